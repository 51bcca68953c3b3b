//! Placing a group's objects: a region (a frame, x/y ranges, a surface height), a rotation,
//! and robosuite's no-overlap rule made a little sharper (two objects clash when their
//! horizontal radii overlap *and* their vertical extents do, so an object may stand on
//! another).

use crate::document::Document;
use crate::document::tree::Node;
use crate::model::geometry::{Bounds, Pose};

use super::rng::Rng;

/// Where a group's objects go (angles in radians, lengths in the region's frame).
#[derive(Clone, Debug)]
pub(crate) struct Placement {
    /// The region's frame in the world.
    pub(crate) frame: Pose,
    /// Label of the frame for messages (`on 'table'`, or empty for the world).
    pub(crate) frame_label: String,
    pub(crate) x: [f64; 2],
    pub(crate) y: [f64; 2],
    pub(crate) z: f64,
    pub(crate) gap: f64,
    pub(crate) rotation: Rotation,
    pub(crate) check_overlap: bool,
    pub(crate) max_tries: u32,
}

/// A rotation about a fixed unit axis.
#[derive(Clone, Debug)]
pub(crate) struct Rotation {
    pub(crate) axis: [f64; 3],
    pub(crate) angles: Angles,
}

/// Where a rotation's angle comes from (radians).
#[derive(Clone, Debug)]
pub(crate) enum Angles {
    None,
    Range(f64, f64),
    Values(Vec<f64>),
}

/// An object placed in a variant: its root pose in the world, its vertical extent and
/// horizontal radius there.
#[derive(Clone, Debug)]
pub(crate) struct Placed {
    pub(crate) pose: Pose,
    pub(crate) z_min: f64,
    pub(crate) z_max: f64,
    pub(crate) radius: f64,
}

impl Placement {
    /// Draws a pose for an object of extent `bounds` (in its root frame), clear of
    /// `placed`; on top of one of `support` (indices into `placed`) when given.
    pub(crate) fn sample(
        &self,
        rng: &mut Rng,
        bounds: &Bounds,
        placed: &[Placed],
        support: Option<&[usize]>,
    ) -> Result<Placed, String> {
        if let Some(s) = support
            && s.is_empty()
        {
            return Err("on top of another object: none of that group was placed".into());
        }
        for _ in 0..self.max_tries {
            let angle = match &self.rotation.angles {
                Angles::None => 0.0,
                Angles::Range(lo, hi) => rng.uniform(*lo, *hi),
                Angles::Values(v) => v[rng.int_in(0, v.len() as u64 - 1) as usize],
            };
            let q_rot = axis_angle(self.rotation.axis, angle);
            let (lo, hi, radius) = extent(bounds, q_rot, self.rotation.axis);
            let dx = rng.uniform(self.x[0], self.x[1]);
            let dy = rng.uniform(self.y[0], self.y[1]);
            let pose = match support {
                Some(s) => {
                    let below = &placed[s[rng.int_in(0, s.len() as u64 - 1) as usize]];
                    Pose {
                        pos: [
                            below.pose.pos[0] + dx,
                            below.pose.pos[1] + dy,
                            below.z_max + self.gap - lo,
                        ],
                        quat: q_rot,
                    }
                }
                None => {
                    let local = Pose {
                        pos: [dx, dy, self.z + self.gap - lo],
                        quat: q_rot,
                    };
                    self.frame.compose(&local)
                }
            };
            let candidate = Placed {
                z_min: pose.pos[2] + lo,
                z_max: pose.pos[2] + hi,
                radius,
                pose,
            };
            if !self.check_overlap || placed.iter().all(|p| !clash(p, &candidate)) {
                return Ok(candidate);
            }
        }
        Err(format!(
            "in x [{}, {}], y [{}, {}]{} after {} tries",
            self.x[0], self.x[1], self.y[0], self.y[1], self.frame_label, self.max_tries
        ))
    }
}

/// robosuite's rule (centres closer than the sum of radii), for objects whose vertical
/// extents overlap.
fn clash(a: &Placed, b: &Placed) -> bool {
    let vertical = a.z_min < b.z_max && b.z_min < a.z_max;
    let dx = a.pose.pos[0] - b.pose.pos[0];
    let dy = a.pose.pos[1] - b.pose.pos[1];
    vertical && (dx * dx + dy * dy).sqrt() <= a.radius + b.radius
}

/// The quaternion of a rotation by `angle` about the unit `axis`.
pub(crate) fn axis_angle(axis: [f64; 3], angle: f64) -> [f64; 4] {
    let (s, c) = (angle / 2.0).sin_cos();
    [c, axis[0] * s, axis[1] * s, axis[2] * s]
}

/// Lowest and highest z and horizontal radius of `bounds` turned by `q` about `axis`:
/// exact for turns about z (the radius does not change and neither do the heights); for
/// other axes from the turned corners of the box, which can only overestimate.
fn extent(bounds: &Bounds, q: [f64; 4], axis: [f64; 3]) -> (f64, f64, f64) {
    if axis == [0.0, 0.0, 1.0] || q == [1.0, 0.0, 0.0, 0.0] {
        return (bounds.min[2], bounds.max[2], bounds.horizontal_radius);
    }
    let turn = Pose {
        pos: [0.0; 3],
        quat: q,
    };
    let (mut lo, mut hi, mut r) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    for corner in 0..8 {
        let p = std::array::from_fn(|k| {
            if corner >> k & 1 == 0 {
                bounds.min[k]
            } else {
                bounds.max[k]
            }
        });
        let t = turn.rotate(p);
        lo = lo.min(t[2]);
        hi = hi.max(t[2]);
        r = r.max(t[0].hypot(t[1]));
    }
    (lo, hi, r)
}

/// A pose as the root body's `pos` and `quat` texts.
pub(crate) fn pose_text(pose: &Pose) -> (String, String) {
    (join(&pose.pos), join(&pose.quat))
}

/// Drops the orientation attributes that a written `quat` replaces.
pub(crate) fn clear_orientation(doc: &mut Document, root: Node) {
    for attr in ["euler", "axisangle", "xyaxes", "zaxis"] {
        doc.remove_attr(root, attr);
    }
}

/// Writes `pose` as the root body's `pos` and `quat` (any other orientation attribute
/// dropped) and returns both as written.
pub(crate) fn write_pose(doc: &mut Document, root: Node, pose: &Pose) -> (String, String) {
    let (pos, quat) = pose_text(pose);
    clear_orientation(doc, root);
    doc.set_attr(root, "pos", &pos);
    doc.set_attr(root, "quat", &quat);
    (pos, quat)
}

/// Numbers as MJCF text: each the shortest text that reads back as the same `f64` (ryu,
/// without a trailing `.0`), space separated. Every variant writes several of these per
/// object, and the standard formatter costs several times more.
pub(crate) fn join(values: &[f64]) -> String {
    let mut out = String::with_capacity(values.len() * 12);
    let mut buf = ryu::Buffer::new();
    for (i, &v) in values.iter().enumerate() {
        if i > 0 {
            out.push(' ');
        }
        // -0 reads back as 0 in MuJoCo; write it as 0 so equal poses give equal bytes.
        if v == 0.0 || !v.is_finite() {
            out.push_str(if v.is_nan() {
                "nan"
            } else if v == 0.0 {
                "0"
            } else if v > 0.0 {
                "inf"
            } else {
                "-inf"
            });
            continue;
        }
        let text = buf.format_finite(v);
        out.push_str(text.strip_suffix(".0").unwrap_or(text));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(h: f64) -> Bounds {
        Bounds {
            min: [-h; 3],
            max: [h; 3],
            horizontal_radius: h * 2f64.sqrt(),
        }
    }

    fn region(tries: u32) -> Placement {
        Placement {
            frame: Pose {
                pos: [0.0, 0.0, 0.8],
                ..Pose::IDENTITY
            },
            frame_label: " on 'table'".into(),
            x: [-0.1, 0.1],
            y: [-0.1, 0.1],
            z: 0.0,
            gap: 0.0,
            rotation: Rotation {
                axis: [0.0, 0.0, 1.0],
                angles: Angles::Range(0.0, 6.0),
            },
            check_overlap: true,
            max_tries: tries,
        }
    }

    #[test]
    fn objects_rest_on_the_surface_and_keep_apart() {
        let mut rng = Rng::new(1, 2, 3);
        let r = region(1000);
        let mut placed = Vec::new();
        for _ in 0..3 {
            let p = r.sample(&mut rng, &cube(0.02), &placed, None).unwrap();
            assert!((p.z_min - 0.8).abs() < 1e-12, "{p:?}");
            for q in &placed {
                assert!(!clash(q, &p));
            }
            placed.push(p);
        }
        let stacked = r
            .sample(&mut rng, &cube(0.01), &placed, Some(&[0]))
            .unwrap();
        assert!((stacked.z_min - placed[0].z_max).abs() < 1e-12);
    }

    #[test]
    fn numbers_read_back_exactly() {
        let values = [
            0.1,
            -0.0,
            1.0,
            100.0,
            0.8250000000000001,
            1e-7,
            -2.5e21,
            1.0 / 3.0,
        ];
        let text = join(&values);
        assert_eq!(text.split(' ').next(), Some("0.1"));
        assert!(text.contains(" 0 1 100 "), "{text}");
        let back: Vec<f64> = text.split(' ').map(|t| t.parse().unwrap()).collect();
        assert_eq!(back, values.map(|v| if v == 0.0 { 0.0 } else { v }));
    }

    #[test]
    fn a_full_region_says_where_and_how_often() {
        let mut rng = Rng::new(1, 2, 3);
        let r = region(5);
        let big = cube(0.3);
        let first = r.sample(&mut rng, &big, &[], None).unwrap();
        let err = r.sample(&mut rng, &big, &[first], None).unwrap_err();
        assert_eq!(
            err,
            "in x [-0.1, 0.1], y [-0.1, 0.1] on 'table' after 5 tries"
        );
    }

    #[test]
    fn turned_about_x_the_box_stands_on_its_corner_bound() {
        let b = Bounds {
            min: [-0.1, -0.2, -0.3],
            max: [0.1, 0.2, 0.3],
            horizontal_radius: 0.2236,
        };
        let q = axis_angle([1.0, 0.0, 0.0], std::f64::consts::FRAC_PI_2);
        let (lo, hi, _) = extent(&b, q, [1.0, 0.0, 0.0]);
        assert!((lo + 0.2).abs() < 1e-12 && (hi - 0.2).abs() < 1e-12);
    }
}
