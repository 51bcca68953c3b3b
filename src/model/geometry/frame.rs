//! Frames: the local pose of an element, exactly as MuJoCo's compiler resolves it.
//!
//! Sources: MuJoCo's XMLreference (compiler `angle` and `eulerseq`, geom and site
//! `fromto`), modeling.rst "Frame orientations", and the compiler's `ResolveOrientation`,
//! `mjuu_z2quat` and `mjuu_frame2quat`, whose arithmetic is followed step by step so that
//! quaternions agree with the compiled `body_quat`/`geom_quat`/`site_quat` to rounding
//! (sign included: MuJoCo keeps a written `quat` with negative `w` as it is).

use super::{err_at, exact, geometry_error};
use crate::document::Document;
use crate::document::tree::Node;
use crate::error::Error;

/// MuJoCo's `mjEPS`: below this a vector counts as zero.
const EPS: f64 = 1e-14;

/// How a model writes angles: `<compiler angle>` (MuJoCo's default for MJCF is degrees!)
/// and `<compiler eulerseq>`.
///
/// ```
/// let doc = mjcf_forge::Document::from_str(
///     r#"<mujoco><compiler angle="radian"/><compiler eulerseq="ZYX"/></mujoco>"#, ".")?;
/// let angles = mjcf_forge::geometry::Angles::of(&doc)?;
/// assert!(!angles.degrees);
/// assert_eq!(&angles.seq, b"ZYX");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Angles {
    /// Whether `axisangle` and `euler` angles are in degrees (else radians).
    pub degrees: bool,
    /// The Euler axis sequence: letters from `xyzXYZ`; lower case rotates about the moving
    /// (intrinsic) axes, upper case about the fixed (extrinsic) parent axes.
    pub seq: [u8; 3],
}

impl Default for Angles {
    /// MuJoCo's defaults for MJCF: degrees, `xyz`.
    fn default() -> Angles {
        Angles {
            degrees: true,
            seq: *b"xyz",
        }
    }
}

impl Angles {
    /// Angle settings from explicit values; `seq` must be 3 letters from `xyzXYZ`.
    ///
    /// ```
    /// use mjcf_forge::geometry::Angles;
    /// assert_eq!(Angles::new(false, "XYZ")?.seq, *b"XYZ");
    /// let wrong = Angles::new(true, "xyw").unwrap_err();
    /// assert!(matches!(wrong.kind, mjcf_forge::ErrorKind::Geometry(_)));
    /// assert_eq!(wrong.to_string(), "eulerseq 'xyw' can only contain x, y, z, X, Y, Z");
    /// # Ok::<(), mjcf_forge::Error>(())
    /// ```
    pub fn new(degrees: bool, seq: &str) -> Result<Angles, Error> {
        let bytes: [u8; 3] = seq.as_bytes().try_into().map_err(|_| {
            let seq = crate::document::read::clip(seq, 40);
            geometry_error(format!("eulerseq '{seq}' must have exactly 3 letters"))
        })?;
        if !bytes.iter().all(|c| b"xyzXYZ".contains(c)) {
            return Err(geometry_error(format!(
                "eulerseq '{seq}' can only contain x, y, z, X, Y, Z"
            )));
        }
        Ok(Angles {
            degrees,
            seq: bytes,
        })
    }

    /// The settings of a document: its `<compiler>` elements read in order, each overriding
    /// what the earlier ones set. An `eulerseq` that is not 3 bytes long is an error; one
    /// with other letters than `xyzXYZ` is kept, and [`element_pose`] refuses `euler`
    /// attributes under it, as MuJoCo does.
    ///
    /// ```
    /// let doc = mjcf_forge::Document::from_str("<mujoco/>", ".")?;
    /// assert_eq!(mjcf_forge::geometry::Angles::of(&doc)?, Default::default());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn of(doc: &Document) -> Result<Angles, Error> {
        let mut angles = Angles::default();
        for c in doc
            .elements(doc.root())
            .filter(|&n| doc.tag(n) == "compiler")
        {
            if let Some(a) = doc.attr(c, "angle") {
                angles.degrees = match a.trim() {
                    "degree" => true,
                    "radian" => false,
                    other => {
                        return Err(err_at(
                            doc,
                            c,
                            format_args!(
                                "angle must be 'degree' or 'radian', not '{}'",
                                crate::document::read::clip(other, 40)
                            ),
                        ));
                    }
                };
            }
            if let Some(s) = doc.attr(c, "eulerseq") {
                // Like MuJoCo: the length is checked here, the letters when an `euler` is
                // read (a model with no `euler` compiles whatever they are).
                angles.seq = s.as_bytes().try_into().map_err(|_| {
                    err_at(
                        doc,
                        c,
                        format_args!(
                            "eulerseq '{}' must have exactly 3 letters",
                            crate::document::read::clip(s, 40)
                        ),
                    )
                })?;
            }
        }
        Ok(angles)
    }

    /// An angle as written, in radians.
    ///
    /// ```
    /// let a = mjcf_forge::geometry::Angles::default();
    /// assert_eq!(a.radians(180.0), std::f64::consts::PI);
    /// ```
    pub fn radians(&self, angle: f64) -> f64 {
        // MuJoCo's own expression (angle / 180 * pi), so results agree to the last bit.
        if self.degrees {
            angle / 180.0 * std::f64::consts::PI
        } else {
            angle
        }
    }
}

/// A rigid transform: position and unit quaternion `(w, x, y, z)`, mapping child
/// coordinates to parent coordinates (`p_parent = pos + R(quat) p_child`).
///
/// ```
/// use mjcf_forge::geometry::Pose;
/// let h = std::f64::consts::FRAC_1_SQRT_2;
/// let turn = Pose { pos: [1.0, 0.0, 0.0], quat: [h, 0.0, 0.0, h] }; // 90 degrees about z
/// let p = turn.transform_point([1.0, 0.0, 0.0]);
/// assert!((p[0] - 1.0).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12);
/// let back = turn.inverse().compose(&turn);
/// assert!(back.pos.iter().all(|v| v.abs() < 1e-12) && (back.quat[0] - 1.0).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Position of the child frame's origin in the parent frame.
    pub pos: [f64; 3],
    /// Orientation of the child frame, `(w, x, y, z)`.
    pub quat: [f64; 4],
}

impl Default for Pose {
    fn default() -> Pose {
        Pose::IDENTITY
    }
}

impl Pose {
    /// No translation, no rotation.
    pub const IDENTITY: Pose = Pose {
        pos: [0.0; 3],
        quat: [1.0, 0.0, 0.0, 0.0],
    };

    /// `self` followed by `child`: the pose of a grandchild frame in `self`'s parent
    /// (MuJoCo's `mjuu_frameaccum`).
    ///
    /// ```
    /// use mjcf_forge::geometry::Pose;
    /// let up = Pose { pos: [0.0, 0.0, 1.0], ..Pose::IDENTITY };
    /// assert_eq!(up.compose(&up).pos, [0.0, 0.0, 2.0]);
    /// ```
    pub fn compose(&self, child: &Pose) -> Pose {
        let r = self.rotate(child.pos);
        Pose {
            pos: [self.pos[0] + r[0], self.pos[1] + r[1], self.pos[2] + r[2]],
            quat: normalized(quat_mul(self.quat, child.quat)),
        }
    }

    /// The inverse transform (parent coordinates to child coordinates).
    ///
    /// ```
    /// use mjcf_forge::geometry::Pose;
    /// let p = Pose { pos: [1.0, 2.0, 3.0], ..Pose::IDENTITY };
    /// assert_eq!(p.inverse().pos, [-1.0, -2.0, -3.0]);
    /// ```
    pub fn inverse(&self) -> Pose {
        let conj = [self.quat[0], -self.quat[1], -self.quat[2], -self.quat[3]];
        let inv = Pose {
            pos: [0.0; 3],
            quat: conj,
        };
        let p = inv.rotate(self.pos);
        Pose {
            pos: [-p[0], -p[1], -p[2]],
            quat: conj,
        }
    }

    /// A point of the child frame in the parent frame.
    ///
    /// ```
    /// use mjcf_forge::geometry::Pose;
    /// let p = Pose { pos: [1.0, 0.0, 0.0], ..Pose::IDENTITY };
    /// assert_eq!(p.transform_point([0.0, 1.0, 0.0]), [1.0, 1.0, 0.0]);
    /// ```
    pub fn transform_point(&self, p: [f64; 3]) -> [f64; 3] {
        let r = self.rotate(p);
        [self.pos[0] + r[0], self.pos[1] + r[1], self.pos[2] + r[2]]
    }

    /// A direction of the child frame in the parent frame (rotation only).
    ///
    /// ```
    /// use mjcf_forge::geometry::Pose;
    /// let flip = Pose { pos: [5.0, 0.0, 0.0], quat: [0.0, 1.0, 0.0, 0.0] }; // 180 about x
    /// assert_eq!(flip.rotate([0.0, 0.0, 1.0]), [0.0, 0.0, -1.0]);
    /// ```
    pub fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        let m = self.rotation_matrix();
        [
            m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
        ]
    }

    /// The rotation matrix, `m[row][col]`; column `k` is the child's axis `k` in the parent.
    ///
    /// ```
    /// use mjcf_forge::geometry::Pose;
    /// assert_eq!(Pose::IDENTITY.rotation_matrix()[1], [0.0, 1.0, 0.0]);
    /// ```
    pub fn rotation_matrix(&self) -> [[f64; 3]; 3] {
        quat_to_mat(self.quat)
    }
}

/// Hamilton product `a * b` (MuJoCo's `mjuu_mulquat` without its normalization).
pub(crate) fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// Rotation matrix of a unit quaternion, `m[row][col]` (MuJoCo's `mjuu_quat2mat`).
pub(crate) fn quat_to_mat(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q;
    let (ww, xx, yy, zz) = (w * w, x * x, y * y, z * z);
    [
        [
            ww + xx - yy - zz,
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            ww - xx + yy - zz,
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            ww - xx - yy + zz,
        ],
    ]
}

fn norm<const N: usize>(v: &[f64; N]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Normalizes in place and returns the old length; a vector shorter than `EPS` is left
/// alone (MuJoCo's `mjuu_normvec`).
fn normalize<const N: usize>(v: &mut [f64; N]) -> f64 {
    let n = norm(v);
    if n >= EPS {
        v.iter_mut().for_each(|x| *x /= n);
    }
    n
}

fn normalized<const N: usize>(mut v: [f64; N]) -> [f64; N] {
    normalize(&mut v);
    v
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The minimal rotation taking `+z` to the unit vector `v` (MuJoCo's `mjuu_z2quat`; a
/// vector along `-z` gives the half turn about `x`).
pub(crate) fn z_to_quat(v: [f64; 3]) -> [f64; 4] {
    let mut axis = cross([0.0, 0.0, 1.0], v);
    let s = normalize(&mut axis);
    if s < 1e-10 {
        axis = [1.0, 0.0, 0.0];
    }
    let half = s.atan2(v[2]) / 2.0;
    let (sin, cos) = half.sin_cos();
    [cos, axis[0] * sin, axis[1] * sin, axis[2] * sin]
}

/// The quaternion of the frame whose axes (unit, orthogonal) are `x`, `y`, `z` (MuJoCo's
/// `mjuu_frame2quat`: Shepperd's method, branch on the largest component).
fn frame_to_quat(x: [f64; 3], y: [f64; 3], z: [f64; 3]) -> [f64; 4] {
    let m = [x, y, z]; // m[col][row]
    let q = if m[0][0] + m[1][1] + m[2][2] > 0.0 {
        let w = 0.5 * (1.0 + m[0][0] + m[1][1] + m[2][2]).sqrt();
        [
            w,
            0.25 * (m[1][2] - m[2][1]) / w,
            0.25 * (m[2][0] - m[0][2]) / w,
            0.25 * (m[0][1] - m[1][0]) / w,
        ]
    } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
        let a = 0.5 * (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt();
        [
            0.25 * (m[1][2] - m[2][1]) / a,
            a,
            0.25 * (m[1][0] + m[0][1]) / a,
            0.25 * (m[2][0] + m[0][2]) / a,
        ]
    } else if m[1][1] > m[2][2] {
        let b = 0.5 * (1.0 - m[0][0] + m[1][1] - m[2][2]).sqrt();
        [
            0.25 * (m[2][0] - m[0][2]) / b,
            0.25 * (m[1][0] + m[0][1]) / b,
            b,
            0.25 * (m[2][1] + m[1][2]) / b,
        ]
    } else {
        let c = 0.5 * (1.0 - m[0][0] - m[1][1] + m[2][2]).sqrt();
        [
            0.25 * (m[0][1] - m[1][0]) / c,
            0.25 * (m[2][0] + m[0][2]) / c,
            0.25 * (m[2][1] + m[1][2]) / c,
            c,
        ]
    };
    normalized(q)
}

/// Euler angles (in the units of `angles`) as a unit quaternion, with the axis sequence
/// of `angles`: each lower-case axis rotates about the already rotated frame
/// (post-multiplied), each upper-case one about the fixed parent frame (pre-multiplied).
/// A letter outside `xyzXYZ` (which [`Angles::new`] and [`Angles::of`] refuse) is
/// skipped.
///
/// ```
/// use mjcf_forge::geometry::{euler_to_quat, Angles};
/// let xyz = Angles::default(); // degrees, intrinsic x-y-z
/// let q = euler_to_quat([0.0, 0.0, 90.0], &xyz);
/// let h = std::f64::consts::FRAC_1_SQRT_2;
/// assert!((q[0] - h).abs() < 1e-15 && (q[3] - h).abs() < 1e-15);
/// // Intrinsic x-y-z is extrinsic Z-Y-X with the angles reversed.
/// let a = euler_to_quat([10.0, 20.0, 30.0], &xyz);
/// let b = euler_to_quat([30.0, 20.0, 10.0], &Angles::new(true, "ZYX")?);
/// assert!(a.iter().zip(b).all(|(u, v)| (u - v).abs() < 1e-15));
/// # Ok::<(), mjcf_forge::Error>(())
/// ```
pub fn euler_to_quat(euler: [f64; 3], angles: &Angles) -> [f64; 4] {
    let mut q = [1.0, 0.0, 0.0, 0.0];
    for (i, &axis) in angles.seq.iter().enumerate() {
        let half = angles.radians(euler[i]) / 2.0;
        let (sin, cos) = half.sin_cos();
        let rot = match axis.to_ascii_lowercase() {
            b'x' => [cos, sin, 0.0, 0.0],
            b'y' => [cos, 0.0, sin, 0.0],
            b'z' => [cos, 0.0, 0.0, sin],
            _ => continue,
        };
        q = if axis.is_ascii_lowercase() {
            quat_mul(q, rot)
        } else {
            quat_mul(rot, q)
        };
    }
    normalized(q)
}

/// The five ways to write an orientation; MuJoCo allows at most one per element.
const ORIENTATIONS: [&str; 5] = ["quat", "axisangle", "xyaxes", "zaxis", "euler"];

/// The orientation of an element from its one orientation attribute (identity if none).
fn orientation(doc: &Document, node: Node, angles: &Angles) -> Result<[f64; 4], Error> {
    let given: Vec<&str> = ORIENTATIONS
        .into_iter()
        .filter(|a| doc.attr(node, a).is_some())
        .collect();
    if given.len() > 1 {
        return Err(err_at(
            doc,
            node,
            format_args!(
                "multiple orientation specifiers ({}) are not allowed",
                given.join(", ")
            ),
        ));
    }
    let Some(&which) = given.first() else {
        return Ok([1.0, 0.0, 0.0, 0.0]);
    };
    let too_small = |what: &str| err_at(doc, node, format_args!("{which}: {what} too small"));
    match which {
        "quat" => {
            let mut q = exact::<4>(doc, node, "quat")?.unwrap_or_default();
            if normalize(&mut q) < EPS {
                return Err(too_small("quaternion"));
            }
            Ok(q)
        }
        "axisangle" => {
            let [x, y, z, a] = exact::<4>(doc, node, "axisangle")?.unwrap_or_default();
            let mut axis = [x, y, z];
            if normalize(&mut axis) < EPS {
                return Err(too_small("axis"));
            }
            let (sin, cos) = (angles.radians(a) / 2.0).sin_cos();
            Ok([cos, sin * axis[0], sin * axis[1], sin * axis[2]])
        }
        "xyaxes" => {
            let v = exact::<6>(doc, node, "xyaxes")?.unwrap_or_default();
            let mut x = [v[0], v[1], v[2]];
            if normalize(&mut x) < EPS {
                return Err(too_small("xaxis"));
            }
            // Make y orthogonal to x (x already unit), as MuJoCo does, then z = x cross y.
            let d = x[0] * v[3] + x[1] * v[4] + x[2] * v[5];
            let mut y = [v[3] - x[0] * d, v[4] - x[1] * d, v[5] - x[2] * d];
            if normalize(&mut y) < EPS {
                return Err(too_small("yaxis"));
            }
            let mut z = cross(x, y);
            if normalize(&mut z) < EPS {
                return Err(too_small("cross(xaxis, yaxis)"));
            }
            Ok(frame_to_quat(x, y, z))
        }
        "zaxis" => {
            let mut z = exact::<3>(doc, node, "zaxis")?.unwrap_or_default();
            if normalize(&mut z) < EPS {
                return Err(too_small("zaxis"));
            }
            Ok(z_to_quat(z))
        }
        _ => {
            if !angles.seq.iter().all(|c| b"xyzXYZ".contains(c)) {
                return Err(err_at(
                    doc,
                    node,
                    "euler sequence can only contain x, y, z, X, Y, Z",
                ));
            }
            Ok(euler_to_quat(
                exact::<3>(doc, node, "euler")?.unwrap_or_default(),
                angles,
            ))
        }
    }
}

/// Geom and site types that take `fromto`.
const FROMTO_TYPES: [&str; 4] = ["capsule", "cylinder", "box", "ellipsoid"];

/// The pose and half length that `fromto` gives a geom or site, if it has one. The frame
/// sits midway; its `z` axis is MuJoCo's `mjuu_z2quat(from - to)` (the geom is symmetric,
/// and this is the sign MuJoCo compiles).
pub(super) fn fromto(doc: &Document, node: Node) -> Result<Option<(Pose, f64)>, Error> {
    let tag = doc.tag(node);
    if tag != "geom" && tag != "site" {
        return Ok(None);
    }
    let Some(f) = exact::<6>(doc, node, "fromto")? else {
        return Ok(None);
    };
    let ty = doc.attr(node, "type").unwrap_or("sphere").trim();
    if !FROMTO_TYPES.contains(&ty) {
        return Err(err_at(
            doc,
            node,
            format_args!("fromto requires capsule, cylinder, box or ellipsoid, not {ty}"),
        ));
    }
    if exact::<3>(doc, node, "pos")?.is_some_and(|p| p != [0.0; 3]) {
        return Err(err_at(doc, node, "both pos and fromto defined"));
    }
    let mut v = [f[0] - f[3], f[1] - f[4], f[2] - f[5]];
    let half = normalize(&mut v) / 2.0;
    if half < EPS {
        return Err(err_at(doc, node, "fromto points too close"));
    }
    let pos = [
        (f[0] + f[3]) / 2.0,
        (f[1] + f[4]) / 2.0,
        (f[2] + f[5]) / 2.0,
    ];
    Ok(Some((
        Pose {
            pos,
            quat: z_to_quat(v),
        },
        half,
    )))
}

/// The local pose of an element (body, frame, geom, site, camera, ...) in its parent's
/// frame, from `pos` and its one orientation attribute, or from `fromto` for geoms and
/// sites, as MuJoCo compiles it. Mesh geoms get the pose as written; MuJoCo then moves
/// their frame to the mesh's centre of mass and principal axes and moves the mesh
/// vertices back by the same amount. Lights aim with `dir`, which is not read here.
///
/// ```
/// use mjcf_forge::geometry::{element_pose, Angles};
/// let doc = mjcf_forge::Document::from_str(
///     r#"<mujoco><worldbody><geom type="capsule" size="0.1" fromto="0 0 0 0 0 2"/>
///        </worldbody></mujoco>"#, ".")?;
/// let world = doc.find_section(mjcf_forge::Section::Worldbody).unwrap();
/// let geom = doc.elements(world).next().unwrap();
/// let pose = element_pose(&doc, geom, &Angles::default())?;
/// assert_eq!(pose.pos, [0.0, 0.0, 1.0]);
/// assert!((pose.quat[1] - 1.0).abs() < 1e-15); // z flipped: MuJoCo points it at `from`
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn element_pose(doc: &Document, node: Node, angles: &Angles) -> Result<Pose, Error> {
    if let Some((pose, _)) = fromto(doc, node)? {
        return Ok(pose);
    }
    let pos = exact::<3>(doc, node, "pos")?.unwrap_or_default();
    Ok(Pose {
        pos,
        quat: orientation(doc, node, angles)?,
    })
}

/// The pose of an element in the frame of the body that holds it: the `<frame>` elements
/// in between composed with its own pose (what MuJoCo compiles into `body_pos`/`body_quat`
/// for a body, `geom_pos`/`geom_quat` for a geom, ...). Identity for `<worldbody>`.
///
/// ```
/// use mjcf_forge::geometry::{body_relative_pose, Angles};
/// let doc = mjcf_forge::Document::from_str(
///     r#"<mujoco><worldbody><body><frame pos="1 0 0"><geom pos="0 1 0" size="1"/></frame>
///        </body></worldbody></mujoco>"#, ".")?;
/// let geom = doc.descendants(doc.root()).find(|&n| doc.tag(n) == "geom").unwrap();
/// assert_eq!(body_relative_pose(&doc, geom, &Angles::default())?.pos, [1.0, 1.0, 0.0]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn body_relative_pose(doc: &Document, node: Node, angles: &Angles) -> Result<Pose, Error> {
    if doc.tag(node) == "worldbody" {
        return Ok(Pose::IDENTITY);
    }
    let mut pose = element_pose(doc, node, angles)?;
    let mut up = doc.parent(node);
    while let Some(p) = up.filter(|&p| doc.tag(p) == "frame") {
        pose = element_pose(doc, p, angles)?.compose(&pose);
        up = doc.parent(p);
    }
    Ok(pose)
}

#[cfg(test)]
mod tests {
    use super::super::words;
    use super::*;

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    fn axis_angle(axis: [f64; 3], rad: f64) -> [f64; 4] {
        let (s, c) = (rad / 2.0).sin_cos();
        [c, axis[0] * s, axis[1] * s, axis[2] * s]
    }

    #[test]
    fn intrinsic_sequences_post_multiply_and_extrinsic_pre_multiply() {
        let rad = Angles::new(false, "xyz").unwrap();
        let (a, b, c) = (0.3, -0.7, 1.1);
        let qx = axis_angle([1.0, 0.0, 0.0], a);
        let qy = axis_angle([0.0, 1.0, 0.0], b);
        let qz = axis_angle([0.0, 0.0, 1.0], c);
        let intrinsic = quat_mul(quat_mul(qx, qy), qz);
        assert!(close(&euler_to_quat([a, b, c], &rad), &intrinsic, 1e-15));
        let extrinsic = Angles::new(false, "XYZ").unwrap();
        assert!(close(
            &euler_to_quat([a, b, c], &extrinsic),
            &quat_mul(quat_mul(qz, qy), qx),
            1e-15
        ));
        // Mixed: x intrinsic, Y extrinsic, z intrinsic.
        let mixed = Angles::new(false, "xYz").unwrap();
        assert!(close(
            &euler_to_quat([a, b, c], &mixed),
            &quat_mul(quat_mul(qy, qx), qz),
            1e-15
        ));
    }

    #[test]
    fn frame_to_quat_inverts_quat_to_mat_in_every_branch() {
        for q in [
            [0.9, 0.1, -0.3, 0.2],
            [0.1, 0.9, 0.3, -0.2],
            [0.1, 0.2, -0.9, 0.3],
            [-0.1, 0.2, 0.3, 0.9],
            [0.0, 0.0, 0.0, 1.0],
        ] {
            let q = normalized(q);
            let m = quat_to_mat(q);
            let col = |k: usize| [m[0][k], m[1][k], m[2][k]];
            let back = frame_to_quat(col(0), col(1), col(2));
            let same = close(&back, &q, 1e-14) || close(&back, &q.map(|v| -v), 1e-14);
            assert!(same, "{q:?} -> {back:?}");
        }
    }

    #[test]
    fn z_to_quat_maps_z_onto_the_vector() {
        for v in [
            [1.0, 2.0, 3.0],
            [0.0, 0.0, -1.0],
            [0.0, 0.0, 1.0],
            [-1.0, 0.5, -0.2],
        ] {
            let u = normalized(v);
            let p = Pose {
                pos: [0.0; 3],
                quat: z_to_quat(u),
            };
            assert!(close(&p.rotate([0.0, 0.0, 1.0]), &u, 1e-15), "{v:?}");
        }
        assert_eq!(
            z_to_quat([0.0, 0.0, -1.0]),
            [(std::f64::consts::FRAC_PI_2).cos(), 1.0, 0.0, 0.0]
        );
    }

    #[test]
    fn inverse_and_compose_round_trip() {
        let p = Pose {
            pos: [0.3, -1.0, 2.0],
            quat: normalized([0.4, -0.2, 0.7, 0.1]),
        };
        let q = Pose {
            pos: [1.0, 2.0, 3.0],
            quat: normalized([0.1, 0.9, 0.3, -0.2]),
        };
        let pq = p.compose(&q);
        let x = [0.5, 0.25, -2.0];
        assert!(close(
            &pq.transform_point(x),
            &p.transform_point(q.transform_point(x)),
            1e-14
        ));
        let id = p.inverse().compose(&p);
        assert!(close(&id.pos, &[0.0; 3], 1e-15) && close(&id.quat, &[1.0, 0.0, 0.0, 0.0], 1e-15));
    }

    fn first_geom(xml: &str) -> (Document, Node) {
        let doc = Document::from_str(xml, ".").unwrap();
        let g = doc
            .descendants(doc.root())
            .find(|&n| doc.tag(n) == "geom")
            .unwrap();
        (doc, g)
    }

    #[test]
    fn orientation_errors_name_the_problem_and_the_place() {
        let (doc, g) = first_geom(
            r#"<mujoco><worldbody><geom euler="1 2 3" quat="1 0 0 0"/></worldbody></mujoco>"#,
        );
        let e = words(element_pose(&doc, g, &Angles::default()).unwrap_err());
        assert!(
            e.contains("multiple orientation specifiers (quat, euler)")
                && e.ends_with("<string>:1:20"),
            "{e}"
        );
        let (doc, g) = first_geom(
            r#"<mujoco><worldbody><geom type="sphere" size="1" fromto="0 0 0 1 0 0"/></worldbody></mujoco>"#,
        );
        let e = words(element_pose(&doc, g, &Angles::default()).unwrap_err());
        assert!(
            e.contains("fromto requires capsule, cylinder, box or ellipsoid, not sphere"),
            "{e}"
        );
        let (doc, g) = first_geom(r#"<mujoco><worldbody><geom pos="1 2"/></worldbody></mujoco>"#);
        let e = words(element_pose(&doc, g, &Angles::default()).unwrap_err());
        assert!(
            e.contains("attribute 'pos' needs 3 numbers, found 2"),
            "{e}"
        );
    }

    #[test]
    fn eulerseq_letters_are_checked_where_an_euler_is_read() {
        let xml = r#"<mujoco><compiler eulerseq="xyw"/><worldbody><geom size="1"/><geom euler="1 2 3"/></worldbody></mujoco>"#;
        let doc = Document::from_str(xml, ".").unwrap();
        let angles = Angles::of(&doc).unwrap();
        let geoms: Vec<Node> = doc
            .descendants(doc.root())
            .filter(|&n| doc.tag(n) == "geom")
            .collect();
        assert!(element_pose(&doc, geoms[0], &angles).is_ok());
        let e = words(element_pose(&doc, geoms[1], &angles).unwrap_err());
        assert!(
            e.contains("euler sequence can only contain x, y, z, X, Y, Z"),
            "{e}"
        );
        let doc = Document::from_str(r#"<mujoco><compiler eulerseq="xy"/></mujoco>"#, ".").unwrap();
        assert!(
            words(Angles::of(&doc).unwrap_err())
                .contains("eulerseq 'xy' must have exactly 3 letters")
        );
    }

    #[test]
    fn xyaxes_orthogonalizes_y_like_mujoco() {
        let (doc, g) =
            first_geom(r#"<mujoco><worldbody><geom xyaxes="0 2 0 -1 1 0"/></worldbody></mujoco>"#);
        let q = element_pose(&doc, g, &Angles::default()).unwrap().quat;
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!(close(&q, &[h, 0.0, 0.0, h], 1e-15), "{q:?}");
    }
}
