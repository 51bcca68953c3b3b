//! A body's bounding-volume tree as the compiler builds it, in the body's inertial frame:
//! boxes of its colliding geoms' boxes, split at the median along the longest edge
//! (`geom_masses.rs` builds it again when a body's inertial frame moves).

use crate::document::rotation::{EPS, rotate};

/// One geom as its body's bounding volumes see it.
#[derive(Clone, Copy, Debug)]
pub struct Volume {
    /// The geom's id (what a leaf names).
    pub id: i32,
    /// Whether it collides (`contype` or `conaffinity`): the others are left out.
    pub collides: bool,
    /// Its frame in the body's.
    pub pos: [f64; 3],
    /// Its orientation in the body's frame.
    pub quat: [f64; 4],
    /// Its box (`geom_aabb`: centre and half sizes, in its own frame).
    pub aabb: [f64; 6],
}

/// A node of a body's bounding-volume tree, as `mjModel` holds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeNode {
    /// Its box in the body's inertial frame: centre and half sizes.
    pub aabb: [f64; 6],
    /// Its children (-1: none).
    pub child: [i32; 2],
    /// The geom of a leaf (-1 for an inner node).
    pub nodeid: i32,
    /// Its depth.
    pub depth: i32,
}

/// The bounding-volume tree of a body's geoms in its inertial frame `(ipos, iquat)`: the
/// compiler's construction (boxes of the geoms' boxes' corners, split at the median along
/// the longest edge), nodes in its order.
pub fn bounding_volumes(volumes: &[Volume], ipos: &[f64; 3], iquat: &[f64; 4]) -> Vec<VolumeNode> {
    let inverse = [iquat[0], -iquat[1], -iquat[2], -iquat[3]];
    let mut elements: Vec<(usize, [f64; 3])> = volumes
        .iter()
        .enumerate()
        .filter(|(_, v)| v.collides)
        .map(|(i, v)| {
            let d = [v.pos[0] - ipos[0], v.pos[1] - ipos[1], v.pos[2] - ipos[2]];
            (i, rotate(&d, &inverse))
        })
        .collect();
    let mut nodes = Vec::new();
    build(volumes, &mut elements, ipos, &inverse, 0, &mut nodes);
    nodes
}

fn build(
    volumes: &[Volume],
    elements: &mut [(usize, [f64; 3])],
    ipos: &[f64; 3],
    inverse: &[f64; 4],
    depth: i32,
    nodes: &mut Vec<VolumeNode>,
) -> i32 {
    if elements.is_empty() {
        return -1;
    }
    let mut lo = [f64::MAX; 3];
    let mut hi = [-f64::MAX; 3];
    for &(i, _) in elements.iter() {
        let v = &volumes[i];
        let a = &v.aabb;
        let (min, max) = (
            [a[0] - a[3], a[1] - a[4], a[2] - a[5]],
            [a[0] + a[3], a[1] + a[4], a[2] + a[5]],
        );
        for corner in 0..8 {
            let c = [
                if corner & 1 != 0 { max[0] } else { min[0] },
                if corner & 2 != 0 { max[1] } else { min[1] },
                if corner & 4 != 0 { max[2] } else { min[2] },
            ];
            let mut b = rotate(&c, &v.quat);
            for k in 0..3 {
                b[k] += v.pos[k] - ipos[k];
            }
            let p = rotate(&b, inverse);
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    for k in 0..3 {
        if (lo[k] - hi[k]).abs() < EPS {
            lo[k] -= EPS;
            hi[k] += EPS;
        }
    }
    let index = nodes.len();
    nodes.push(VolumeNode {
        aabb: [
            (hi[0] + lo[0]) / 2.0,
            (hi[1] + lo[1]) / 2.0,
            (hi[2] + lo[2]) / 2.0,
            (hi[0] - lo[0]) / 2.0,
            (hi[1] - lo[1]) / 2.0,
            (hi[2] - lo[2]) / 2.0,
        ],
        child: [-1, -1],
        nodeid: -1,
        depth,
    });
    if elements.len() == 1 {
        nodes[index].nodeid = volumes[elements[0].0].id;
        return index as i32;
    }
    let edges = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let mut axis = 0;
    if edges[1] >= edges[0] + EPS {
        axis = 1;
    }
    if edges[2] >= edges[axis] + EPS {
        axis = 2;
    }
    // The median along the axis (ties within mjEPS in the geoms' order).
    elements.sort_by(|a, b| {
        if (a.1[axis] - b.1[axis]).abs() > EPS {
            a.1[axis].total_cmp(&b.1[axis])
        } else {
            a.0.cmp(&b.0)
        }
    });
    let m = elements.len() / 2;
    let (left, right) = elements.split_at_mut(m);
    if m > 0 {
        nodes[index].child[0] = build(volumes, left, ipos, inverse, depth + 1, nodes);
    }
    nodes[index].child[1] = build(volumes, right, ipos, inverse, depth + 1, nodes);
    index as i32
}
