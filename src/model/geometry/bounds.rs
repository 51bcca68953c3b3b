//! The extent of a body's subtree: exact per primitive, with the tree as written.
//!
//! Per geom, in the frame of the measured body (`p` the geom's position, `R` its rotation
//! there, `R_k` row `k`):
//! - sphere `r`: `p ± r`; capsule `r, h`: its segment `p ± h R e_z`, then `± r`;
//! - box `h`: half extent along `k` is `sum_i |R_ki| h_i`; corners for the radius;
//! - cylinder `r, h`: `|R_k2| h + r sqrt(1 - R_k2^2)`, the root taken as the length of the
//!   axis's other two components (no cancellation for an axis nearly along `k`);
//! - ellipsoid `a`: `sqrt(sum_i (R_ki a_i)^2)`;
//! - mesh: its vertices ([`super::mesh_vertices`]) placed with the geom's written pose.
//!
//! The horizontal radius (largest `sqrt(x^2 + y^2)`) is exact for spheres, capsules,
//! boxes and meshes (a convex function peaks at an extreme point: endpoints, corners,
//! vertices). Cylinders peak on a rim circle and ellipsoids on their outline, both seen
//! from above as an ellipse; [`max_norm_on_ellipse`] finds the farthest point of an ellipse
//! from the origin by bisection on a function proven monotone, to rounding.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use super::frame::{Angles, Pose, element_pose, fromto};
use super::mesh::{find_mesh, mesh_vertices};
use super::{err_at, up_to};
use crate::document::Document;
use crate::document::tree::Node;
use crate::error::Error;

/// An axis-aligned box and a horizontal radius, in the frame of the measured body.
///
/// ```
/// let b = mjcf_forge::geometry::Bounds { min: [-1.0; 3], max: [1.0, 1.0, 2.0], horizontal_radius: 1.5 };
/// assert_eq!(b.center(), [0.0, 0.0, 0.5]);
/// assert_eq!(b.size(), [2.0, 2.0, 3.0]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Smallest `x`, `y`, `z` of any geometry.
    pub min: [f64; 3],
    /// Largest `x`, `y`, `z` of any geometry.
    pub max: [f64; 3],
    /// Largest distance of any geometry from the body's `z` axis, `sqrt(x^2 + y^2)`.
    pub horizontal_radius: f64,
}

impl Bounds {
    /// The middle of the box.
    pub fn center(&self) -> [f64; 3] {
        std::array::from_fn(|k| (self.min[k] + self.max[k]) / 2.0)
    }

    /// The side lengths of the box.
    pub fn size(&self) -> [f64; 3] {
        std::array::from_fn(|k| self.max[k] - self.min[k])
    }

    fn include(&mut self, other: &Bounds) {
        for k in 0..3 {
            self.min[k] = self.min[k].min(other.min[k]);
            self.max[k] = self.max[k].max(other.max[k]);
        }
        self.horizontal_radius = self.horizontal_radius.max(other.horizontal_radius);
    }
}

/// The bounds of every geom in the subtree of `body` (a `<body>`, or `<worldbody>` for the
/// whole scene) for which `filter(doc, geom)` is true: the body's own geoms and those of
/// all its descendants, through `<frame>`s, in the body's frame, with every joint at its
/// reference position (MuJoCo's `qpos0`: the tree as written).
///
/// Planes, height fields and SDF geoms have no extent of their own here and are skipped.
/// Errors: a subtree with no measurable geom, a primitive geom fitted to a mesh (its size
/// comes from the mesh's inertia), `<replicate>`, `<attach>`, `<composite>` and
/// `<flexcomp>` (whose geoms only exist after MuJoCo expands them), and malformed
/// attributes, each with its source position.
///
/// ```
/// use mjcf_forge::{Document, Section};
/// use mjcf_forge::geometry::subtree_bounds;
/// let doc = Document::from_str(
///     r#"<mujoco><worldbody><body name="arm">
///          <geom type="capsule" fromto="0 0 0 1 0 0" size="0.1"/>
///          <body pos="1 0 0"><joint/><geom type="sphere" size="0.2" group="3"/></body>
///        </body></worldbody></mujoco>"#,
///     ".",
/// )?;
/// let arm = doc.descendants(doc.root()).find(|&n| doc.attr(n, "name") == Some("arm")).unwrap();
/// let all = subtree_bounds(&doc, arm, |_, _| true)?;
/// assert!((all.max[0] - 1.2).abs() < 1e-12 && (all.horizontal_radius - 1.2).abs() < 1e-12);
/// let visible = subtree_bounds(&doc, arm, |d, g| d.attr(g, "group") != Some("3"))?;
/// assert!((visible.max[0] - 1.1).abs() < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn subtree_bounds(
    doc: &Document,
    body: Node,
    filter: impl Fn(&Document, Node) -> bool,
) -> Result<Bounds, Error> {
    let tag = doc.tag(body);
    if tag != "body" && tag != "worldbody" {
        return Err(err_at(
            doc,
            body,
            "bounds are measured for a <body> or <worldbody>",
        ));
    }
    let mut walk = Walk {
        doc,
        angles: Angles::of(doc)?,
        filter,
        meshes: HashMap::new(),
        acc: None,
    };
    walk.subtree(body, &Pose::IDENTITY)?;
    walk.acc
        .ok_or_else(|| err_at(doc, body, "no geom with a finite extent in this subtree"))
}

struct Walk<'a, F> {
    doc: &'a Document,
    angles: Angles,
    filter: F,
    /// Vertices per mesh asset: meshes are shared by many geoms.
    meshes: HashMap<Node, Vec<[f64; 3]>>,
    acc: Option<Bounds>,
}

impl<F: Fn(&Document, Node) -> bool> Walk<'_, F> {
    /// Measures every geom below `node`, in document order, from an explicit stack (bodies
    /// nest without bound; this may run on a worker thread with a small stack).
    fn subtree(&mut self, node: Node, pose: &Pose) -> Result<(), Error> {
        let doc = self.doc;
        let mut stack: Vec<(Node, Pose)> = Vec::new();
        let push_kids = |stack: &mut Vec<(Node, Pose)>, node: Node, pose: &Pose| {
            let at = stack.len();
            stack.extend(doc.elements(node).map(|k| (k, *pose)));
            stack[at..].reverse();
        };
        push_kids(&mut stack, node, pose);
        while let Some((child, pose)) = stack.pop() {
            let pose = &pose;
            match doc.tag(child) {
                "body" | "frame" => {
                    let inner = pose.compose(&element_pose(doc, child, &self.angles)?);
                    push_kids(&mut stack, child, &inner);
                }
                "geom" if (self.filter)(doc, child) => {
                    if let Some(b) = self.geom(child, pose)? {
                        match &mut self.acc {
                            Some(acc) => acc.include(&b),
                            None => self.acc = Some(b),
                        }
                    }
                }
                t @ ("replicate" | "attach" | "composite" | "flexcomp") => {
                    return Err(err_at(
                        doc,
                        child,
                        format_args!("<{t}> is not expanded here: its geoms cannot be measured"),
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// The bounds of one geom whose parent frame is `parent` (in the measured body's frame).
    fn geom(&mut self, geom: Node, parent: &Pose) -> Result<Option<Bounds>, Error> {
        let doc = self.doc;
        let ty = doc.attr(geom, "type").unwrap_or("sphere").trim();
        if matches!(ty, "plane" | "hfield" | "sdf") {
            return Ok(None);
        }
        if ty == "mesh" {
            let name = doc
                .attr(geom, "mesh")
                .ok_or_else(|| err_at(doc, geom, "mesh geom without 'mesh'"))?;
            let mesh = find_mesh(doc, name)
                .ok_or_else(|| err_at(doc, geom, format_args!("no mesh named '{name}'")))?;
            if let Entry::Vacant(slot) = self.meshes.entry(mesh) {
                slot.insert(mesh_vertices(doc, mesh)?);
            }
            let pose = parent.compose(&element_pose(doc, geom, &self.angles)?);
            return Ok(Some(mesh_bounds(&self.meshes[&mesh], &pose)));
        }
        if doc.attr(geom, "mesh").is_some() {
            return Err(err_at(
                doc,
                geom,
                format_args!(
                    "a {ty} fitted to a mesh is not supported (its size comes from the mesh's inertia)"
                ),
            ));
        }
        let (required, kind) = match ty {
            "sphere" => (1, Kind::Sphere),
            "capsule" => (2, Kind::Capsule),
            "ellipsoid" => (3, Kind::Ellipsoid),
            "cylinder" => (2, Kind::Cylinder),
            "box" => (3, Kind::Box),
            other => {
                return Err(err_at(
                    doc,
                    geom,
                    format_args!("unknown geom type '{other}'"),
                ));
            }
        };
        let mut size = up_to::<3>(doc, geom, "size", [0.0; 3])?;
        let local = match fromto(doc, geom)? {
            Some((pose, half)) => {
                // MuJoCo: the length goes to size[1] (capsule, cylinder) or size[2] with
                // size[1] = size[0] (box, ellipsoid).
                if matches!(kind, Kind::Box | Kind::Ellipsoid) {
                    size = [size[0], size[0], half];
                } else {
                    size[1] = half;
                }
                pose
            }
            None => element_pose(doc, geom, &self.angles)?,
        };
        if let Some(i) = (0..required).find(|&i| size[i].is_nan() || size[i] <= 0.0) {
            return Err(err_at(
                doc,
                geom,
                format_args!("size[{i}] of a {ty} must be positive"),
            ));
        }
        let pose = parent.compose(&local);
        Ok(Some(primitive(kind, size, &pose)))
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Sphere,
    Capsule,
    Ellipsoid,
    Cylinder,
    Box,
}

/// The bounds of a set of points.
fn points(pts: impl Iterator<Item = [f64; 3]>) -> Bounds {
    let mut b = Bounds {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
        horizontal_radius: 0.0,
    };
    for p in pts {
        b.include(&Bounds {
            min: p,
            max: p,
            horizontal_radius: p[0].hypot(p[1]),
        });
    }
    b
}

/// The bounds of mesh vertices placed at `pose`. A plain loop: meshes run to millions of
/// vertices and this also runs unoptimized in tests.
fn mesh_bounds(verts: &[[f64; 3]], pose: &Pose) -> Bounds {
    let (p, m) = (pose.pos, pose.rotation_matrix());
    let (mut lo, mut hi, mut r2) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3], 0.0f64);
    for v in verts {
        let x = p[0] + m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2];
        let y = p[1] + m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2];
        let z = p[2] + m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2];
        lo = [lo[0].min(x), lo[1].min(y), lo[2].min(z)];
        hi = [hi[0].max(x), hi[1].max(y), hi[2].max(z)];
        r2 = r2.max(x * x + y * y);
    }
    Bounds {
        min: lo,
        max: hi,
        horizontal_radius: r2.sqrt(),
    }
}

/// Exact bounds of a primitive with `size` at `pose`.
fn primitive(kind: Kind, size: [f64; 3], pose: &Pose) -> Bounds {
    let p = pose.pos;
    let m = pose.rotation_matrix();
    let around = |half: [f64; 3], horizontal_radius: f64| Bounds {
        min: std::array::from_fn(|k| p[k] - half[k]),
        max: std::array::from_fn(|k| p[k] + half[k]),
        horizontal_radius,
    };
    match kind {
        Kind::Sphere => around([size[0]; 3], p[0].hypot(p[1]) + size[0]),
        Kind::Capsule => {
            let (r, h) = (size[0], size[1]);
            let axis = [m[0][2] * h, m[1][2] * h, m[2][2] * h];
            let mut b = points(
                [-1.0, 1.0]
                    .into_iter()
                    .map(|s| std::array::from_fn(|k| p[k] + s * axis[k])),
            );
            for k in 0..3 {
                b.min[k] -= r;
                b.max[k] += r;
            }
            b.horizontal_radius += r;
            b
        }
        Kind::Box => {
            let corners = (0..8).map(|c: u32| {
                let s: [f64; 3] =
                    std::array::from_fn(|i| if c >> i & 1 == 1 { size[i] } else { -size[i] });
                std::array::from_fn(|k| p[k] + m[k][0] * s[0] + m[k][1] * s[1] + m[k][2] * s[2])
            });
            let rad = points(corners).horizontal_radius;
            let half = std::array::from_fn(|k| (0..3).map(|i| m[k][i].abs() * size[i]).sum());
            around(half, rad)
        }
        Kind::Cylinder => {
            let (r, h) = (size[0], size[1]);
            let a = [m[0][2], m[1][2], m[2][2]];
            // sqrt(1 - a_k^2) written as the length of a's other two components: the same
            // for a unit axis, but without cancellation when a is nearly along k.
            let half =
                std::array::from_fn(|k| a[k].abs() * h + r * a[(k + 1) % 3].hypot(a[(k + 2) % 3]));
            // A rim circle seen from above: radius r across a's horizontal direction,
            // r |a_z| along it.
            let n = a[0].hypot(a[1]);
            let rad = [-1.0, 1.0]
                .into_iter()
                .map(|s| {
                    let c = [p[0] + s * h * a[0], p[1] + s * h * a[1]];
                    if n == 0.0 {
                        c[0].hypot(c[1]) + r
                    } else {
                        max_norm_on_ellipse(c, [-a[1] / n, a[0] / n], r, r * a[2].abs().min(1.0))
                    }
                })
                .fold(0.0, f64::max);
            around(half, rad)
        }
        Kind::Ellipsoid => {
            let half = std::array::from_fn(|k| {
                (0..3)
                    .map(|i| (m[k][i] * size[i]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            });
            // Outline from above: the image of the unit sphere under rows 0-1 of R diag(a),
            // the ellipse whose shape matrix is S = M M^T.
            let s00: f64 = (0..3).map(|i| (m[0][i] * size[i]).powi(2)).sum();
            let s11: f64 = (0..3).map(|i| (m[1][i] * size[i]).powi(2)).sum();
            let s01: f64 = (0..3).map(|i| m[0][i] * m[1][i] * size[i] * size[i]).sum();
            let mean = (s00 + s11) / 2.0;
            let d = ((s00 - s11) / 2.0).hypot(s01);
            let (l1, l2) = (mean + d, (mean - d).max(0.0));
            let rad = if d == 0.0 {
                p[0].hypot(p[1]) + l1.sqrt()
            } else {
                // Eigenvector of l1: whichever of the two equivalent forms is longer.
                let (u, v) = ([s01, l1 - s00], [l1 - s11, s01]);
                let e = if u[0].hypot(u[1]) >= v[0].hypot(v[1]) {
                    u
                } else {
                    v
                };
                let n = e[0].hypot(e[1]);
                max_norm_on_ellipse([p[0], p[1]], [e[0] / n, e[1] / n], l1.sqrt(), l2.sqrt())
            };
            around(half, rad)
        }
    }
}

/// The largest `|c + y|` over the ellipse `y = s1 cos(t) e1 + s2 sin(t) e2`, with `e1` a
/// unit vector, `e2` perpendicular to it, and `s1 >= s2 >= 0`.
///
/// With `p1 = |c.e1|`, `p2 = |c.e2|` the maximum is that of
/// `f(t) = (p1 + s1 cos t)^2 + (p2 + s2 sin t)^2` on `[0, pi/2]` (taking `|cos|` and `|sin|`
/// never lowers either term). There `f'(t) / (2 cos t) = s2 p2 - s1 p1 tan t
/// - (s1^2 - s2^2) sin t` is non-increasing, so `f'` changes sign once, from `+` to `-`:
/// bisection on its sign finds the maximiser to the last bit, and `f` is flat there.
fn max_norm_on_ellipse(c: [f64; 2], e1: [f64; 2], s1: f64, s2: f64) -> f64 {
    let p1 = (c[0] * e1[0] + c[1] * e1[1]).abs();
    let p2 = (-c[0] * e1[1] + c[1] * e1[0]).abs();
    if s1 == s2 {
        return p1.hypot(p2) + s1;
    }
    let value = |t: f64| (p1 + s1 * t.cos()).hypot(p2 + s2 * t.sin());
    let slope = |t: f64| {
        let (sin, cos) = t.sin_cos();
        s2 * p2 * cos - s1 * p1 * sin - (s1 * s1 - s2 * s2) * sin * cos
    };
    let (mut lo, mut hi) = (0.0f64, std::f64::consts::FRAC_PI_2);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if slope(mid) > 0.0 { lo = mid } else { hi = mid }
    }
    value(lo).max(value(hi))
}

#[cfg(test)]
mod tests {
    use super::super::words;
    use super::*;

    /// A brute-force reference: dense sampling, then golden-section refinement.
    fn brute(c: [f64; 2], u: [f64; 2], v: [f64; 2]) -> f64 {
        let f = |t: f64| {
            (c[0] + t.cos() * u[0] + t.sin() * v[0]).hypot(c[1] + t.cos() * u[1] + t.sin() * v[1])
        };
        let n = 20_000;
        let step = std::f64::consts::TAU / n as f64;
        let best = (0..n)
            .map(|i| i as f64 * step)
            .max_by(|a, b| f(*a).total_cmp(&f(*b)))
            .unwrap();
        let (mut a, mut b) = (best - step, best + step);
        let g = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..100 {
            let (x, y) = (b - g * (b - a), a + g * (b - a));
            if f(x) > f(y) { b = y } else { a = x }
        }
        f(a).max(f(b)).max(f(best))
    }

    #[test]
    fn ellipse_maximum_matches_brute_force() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for i in 0..500 {
            let c = if i % 7 == 0 {
                [0.0, 0.0]
            } else {
                [rnd() * 3.0, rnd() * 3.0]
            };
            let ang = rnd() * 4.0;
            let e1 = [ang.cos(), ang.sin()];
            let s1 = rnd().abs() * 2.0 + 1e-3;
            let s2 = if i % 5 == 0 { 0.0 } else { s1 * rnd().abs() };
            let got = max_norm_on_ellipse(c, e1, s1, s2);
            let want = brute(c, [e1[0] * s1, e1[1] * s1], [-e1[1] * s2, e1[0] * s2]);
            assert!(
                (got - want).abs() <= 1e-12 * want.max(1.0),
                "{c:?} {e1:?} {s1} {s2}: {got} vs {want}"
            );
        }
    }

    fn bounds_of(xml: &str) -> Result<Bounds, Error> {
        let doc = Document::from_str(xml, ".").unwrap();
        let body = doc
            .descendants(doc.root())
            .find(|&n| doc.tag(n) == "body")
            .unwrap();
        subtree_bounds(&doc, body, |_, _| true)
    }

    #[test]
    fn rotated_cylinder_and_ellipsoid_extents() {
        // Cylinder lying along x: half extents (h, r, r); radius of the far rim point.
        let b = bounds_of(r#"<mujoco><worldbody><body><geom type="cylinder" size="1 2" euler="0 90 0"/></body></worldbody></mujoco>"#).unwrap();
        assert!(
            b.max
                .iter()
                .zip([2.0, 1.0, 1.0])
                .all(|(a, e)| (a - e).abs() < 1e-12),
            "{b:?}"
        );
        assert!((b.horizontal_radius - 5f64.sqrt()).abs() < 1e-12);
        let b = bounds_of(r#"<mujoco><worldbody><body><geom type="ellipsoid" size="1 2 3" pos="1 0 0"/></body></worldbody></mujoco>"#).unwrap();
        assert_eq!(b.max, [2.0, 2.0, 3.0]);
        // Farthest point of the ellipse x^2 + y^2/4 = 1 from (-1, 0): at x = -1/3.
        let want = ((1.0 + 1.0 / 3.0f64).powi(2) + 4.0 * (1.0 - 1.0 / 9.0)).sqrt();
        assert!(
            (b.horizontal_radius - want).abs() < 1e-12,
            "{} vs {want}",
            b.horizontal_radius
        );
    }

    #[test]
    fn fromto_box_takes_size0_across_and_half_length_along() {
        let b = bounds_of(r#"<mujoco><worldbody><body><geom type="box" size="0.1" fromto="0 0 0 0 0 1"/></body></worldbody></mujoco>"#).unwrap();
        assert!(
            (b.min[0] + 0.1).abs() < 1e-12
                && (b.max[2] - 1.0).abs() < 1e-12
                && b.min[2].abs() < 1e-12,
            "{b:?}"
        );
    }

    #[test]
    fn planes_are_skipped_and_empty_subtrees_are_errors() {
        let e = words(bounds_of(r#"<mujoco><worldbody><body><geom type="plane" size="1 1 1"/></body></worldbody></mujoco>"#).unwrap_err());
        assert!(e.contains("no geom with a finite extent"), "{e}");
        let e = words(
            bounds_of(
                r#"<mujoco><worldbody><body><geom type="sphere"/></body></worldbody></mujoco>"#,
            )
            .unwrap_err(),
        );
        assert!(e.contains("size[0] of a sphere must be positive"), "{e}");
    }
}
