//! The statistics MuJoCo's compiler derives from a model at `qpos0` (`stat.center`,
//! `extent`, `meansize`, `meanmass`, `meaninertia`) and the dof lengths, which
//! `mj_setConst` of 3.17 and 4.0 leaves as they were: after a patch, the model caches of
//! both faces compute them here, from the model's arrays and the kinematics at `qpos0`, with
//! the compiler's operations in its order (the same bits). The C face hands over the
//! arrays of the linked MuJoCo (`compiled/linked.rs`), the Python face those of the user's
//! (`python/src/split/statistics.rs`).

/// `mjGEOM_PLANE` and `mjGEOM_HFIELD`: geoms without a bounding radius that still count
/// in the model's bounding box.
const GEOM_PLANE: i32 = 0;
const GEOM_HFIELD: i32 = 1;
/// `mjJNT_FREE`, `mjJNT_BALL` and `mjJNT_HINGE`: the joints whose dofs (a free joint's last
/// three) rotate.
const JNT_FREE: i32 = 0;
const JNT_BALL: i32 = 1;
const JNT_HINGE: i32 = 3;

/// The arrays the statistics read: the model's, and the data's kinematics and joint-space
/// inertia at `qpos0` (after `mj_kinematics`, `mj_comPos` and the mass matrix). Positions
/// are `3 * n` numbers, sizes `3` per geom and `4` per height field.
#[derive(Debug, Clone, Copy)]
pub struct StatArrays<'a> {
    /// `data.xpos`, one row per body (the world's first).
    pub xpos: &'a [f64],
    /// `data.xipos`, each body's centre of mass.
    pub xipos: &'a [f64],
    /// `data.xanchor`, one row per joint.
    pub xanchor: &'a [f64],
    /// `data.site_xpos`.
    pub site_xpos: &'a [f64],
    /// `data.geom_xpos`.
    pub geom_xpos: &'a [f64],
    /// `model.geom_rbound`.
    pub geom_rbound: &'a [f64],
    /// `model.geom_type`.
    pub geom_type: &'a [i32],
    /// `model.geom_size`.
    pub geom_size: &'a [f64],
    /// `model.geom_dataid`.
    pub geom_dataid: &'a [i32],
    /// `model.hfield_size`.
    pub hfield_size: &'a [f64],
    /// `model.body_parentid`.
    pub body_parentid: &'a [i32],
    /// `model.body_geomadr`.
    pub body_geomadr: &'a [i32],
    /// `model.body_geomnum`.
    pub body_geomnum: &'a [i32],
    /// `model.body_mass`.
    pub body_mass: &'a [f64],
    /// `model.jnt_bodyid`.
    pub jnt_bodyid: &'a [i32],
    /// `model.jnt_type`.
    pub jnt_type: &'a [i32],
    /// `model.jnt_dofadr`.
    pub jnt_dofadr: &'a [i32],
    /// `model.dof_jntid`.
    pub dof_jntid: &'a [i32],
    /// `model.dof_bodyid`.
    pub dof_bodyid: &'a [i32],
    /// The joint-space inertia as this MuJoCo stores it (`data.M`, or `data.qM`).
    pub inertia: &'a [f64],
    /// Where each dof's diagonal element sits in `inertia` (`M_rowadr + M_rownnz - 1`, or
    /// `dof_Madr`).
    pub inertia_diagonal: &'a [i32],
}

/// A model's statistics in `mjStatistic`'s order: `meaninertia`, `meanmass`, `meansize`,
/// `extent`, `center[3]`.
pub type Statistics = [f64; 7];

/// Bit `k` of the mask [`fixed_statistics_mask`] returns: value `k` of [`Statistics`]
/// (`center` is bit 4 and fills values 4 to 6).
pub const STATISTIC_NAMES: [&str; 5] = ["meaninertia", "meanmass", "meansize", "extent", "center"];

/// The statistics `doc`'s `<statistic>` sets, named as in [`STATISTIC_NAMES`]: MuJoCo keeps
/// them over what it computes, so a patched model must too.
///
/// ```
/// use mjcf_forge::Document;
/// use mjcf_forge::split::fixed_statistics;
/// let doc = Document::from_str(r#"<mujoco><statistic extent="2"/></mujoco>"#, ".")?;
/// assert_eq!(fixed_statistics(&doc), ["extent"]);
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn fixed_statistics(doc: &crate::document::Document) -> Vec<&'static str> {
    STATISTIC_NAMES
        .into_iter()
        .filter(|a| super::setting(doc, "statistic", a).is_some())
        .collect()
}

/// The mask of the statistics named in `fixed` (those a document's `<statistic>` sets,
/// which MuJoCo keeps over what it computes).
///
/// ```
/// use mjcf_forge::split::fixed_statistics_mask;
/// assert_eq!(fixed_statistics_mask(["extent", "center"]), 8 | 16);
/// ```
pub fn fixed_statistics_mask<'a>(fixed: impl IntoIterator<Item = &'a str>) -> u32 {
    fixed
        .into_iter()
        .filter_map(|f| STATISTIC_NAMES.iter().position(|n| *n == f))
        .fold(0, |mask, k| mask | (1 << k))
}

/// `stat` with the values `fixed` (a [`fixed_statistics_mask`]) takes from `values`.
///
/// ```
/// use mjcf_forge::split::keep_fixed;
/// let mut stat = [1.0; 7];
/// keep_fixed(&mut stat, 16, &[0.0, 0.0, 0.0, 0.0, 5.0, 6.0, 7.0]);
/// assert_eq!(stat, [1.0, 1.0, 1.0, 1.0, 5.0, 6.0, 7.0]);
/// ```
pub fn keep_fixed(stat: &mut Statistics, fixed: u32, values: &Statistics) {
    for k in 0..4 {
        if fixed & (1 << k) != 0 {
            stat[k] = values[k];
        }
    }
    if fixed & 16 != 0 {
        stat[4..].copy_from_slice(&values[4..]);
    }
}

fn maxd(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

fn row(a: &[f64], i: usize) -> &[f64] {
    &a[3 * i..3 * i + 3]
}

/// `mju_dist3`'s operations in its order.
fn dist3(a: &[f64], b: &[f64]) -> f64 {
    let (d0, d1, d2) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    (d0 * d0 + d1 * d1 + d2 * d2).sqrt()
}

/// The bounding box grown by a sphere of radius `r` at `p`.
fn grow(lo: &mut [f64; 3], hi: &mut [f64; 3], p: &[f64], r: f64) {
    for k in 0..3 {
        lo[k] = if lo[k] < p[k] - r { lo[k] } else { p[k] - r };
        hi[k] = if hi[k] > p[k] + r { hi[k] } else { p[k] + r };
    }
}

fn at(a: &[i32], i: usize) -> usize {
    a[i] as usize
}

/// The statistics of the model `a` holds, from `previous` (what MuJoCo keeps where it
/// computes nothing: `extent` of a model without a spread, the means of a model without
/// bodies or dofs), and each dof's length written into `dof_length` when given (a
/// rotational dof's is its body's size, a translational one's 1).
///
/// ```
/// use mjcf_forge::split::{StatArrays, statistics};
/// // One body at z = 1 with a sphere of radius 0.1 and no joint.
/// let xpos = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
/// let a = StatArrays {
///     xpos: &xpos, xipos: &xpos, xanchor: &[], site_xpos: &[],
///     geom_xpos: &xpos[3..], geom_rbound: &[0.1], geom_type: &[2], geom_size: &[0.1, 0.0, 0.0],
///     geom_dataid: &[-1], hfield_size: &[], body_parentid: &[0, 0], body_geomadr: &[-1, 0],
///     body_geomnum: &[0, 1], body_mass: &[0.0, 2.0], jnt_bodyid: &[], jnt_type: &[],
///     jnt_dofadr: &[], dof_jntid: &[], dof_bodyid: &[], inertia: &[], inertia_diagonal: &[],
/// };
/// let stat = statistics(&a, &[0.0; 7], None);
/// assert_eq!(stat[1], 2.0); // meanmass
/// assert_eq!(&stat[4..], &[0.0, 0.0, 1.0]); // center
/// ```
pub fn statistics(
    a: &StatArrays<'_>,
    previous: &Statistics,
    dof_length: Option<&mut [f64]>,
) -> Statistics {
    let mut stat = *previous;
    let nbody = a.xpos.len() / 3;
    let (njnt, nv) = (a.jnt_bodyid.len(), a.dof_jntid.len());
    let mut lo = [1e10; 3];
    let mut hi = [-1e10; 3];
    for i in 1..nbody {
        grow(&mut lo, &mut hi, row(a.xpos, i), 0.0);
        grow(&mut lo, &mut hi, row(a.xipos, i), 0.0);
    }
    for j in 0..njnt {
        grow(&mut lo, &mut hi, row(a.xanchor, j), 0.0);
    }
    for s in 0..a.site_xpos.len() / 3 {
        grow(&mut lo, &mut hi, row(a.site_xpos, s), 0.0);
    }
    for g in 0..a.geom_rbound.len() {
        let mut r = 0.0;
        if a.geom_rbound[g] > 0.0 {
            r = a.geom_rbound[g];
        } else if a.geom_type[g] == GEOM_PLANE {
            let s = row(a.geom_size, g);
            r = if s[0] != 0.0 || s[1] != 0.0 {
                maxd(s[0], s[1]) * 0.1
            } else {
                0.01
            };
        } else if a.geom_type[g] == GEOM_HFIELD {
            let id = at(a.geom_dataid, g);
            let h = &a.hfield_size[4 * id..4 * id + 4];
            r = maxd(h[0], maxd(h[1], maxd(h[2], h[3]))) * 0.1;
        }
        grow(&mut lo, &mut hi, row(a.geom_xpos, g), r);
    }
    for k in 0..3 {
        stat[4 + k] = (lo[k] + hi[k]) * 0.5;
    }
    if hi[0] > lo[0] {
        stat[3] = maxd(
            1e-5,
            maxd(hi[0] - lo[0], maxd(hi[1] - lo[1], hi[2] - lo[2])),
        );
    }

    // Body sizes: the largest com-joint distance (the joint's body and its parent), then
    // geom bounds around the com.
    let mut body = vec![0.0; nbody];
    for j in 0..njnt {
        let anchor = row(a.xanchor, j);
        let id = at(a.jnt_bodyid, j);
        body[id] = maxd(body[id], dist3(row(a.xipos, id), anchor));
        let id = at(a.body_parentid, id);
        body[id] = maxd(body[id], dist3(row(a.xipos, id), anchor));
    }
    if nbody > 0 {
        body[0] = 0.0;
    }
    for (i, size) in body.iter_mut().enumerate().skip(1) {
        let first = at(a.body_geomadr, i);
        for g in first..first + at(a.body_geomnum, i) {
            if a.geom_rbound[g] > 0.0 {
                let far = a.geom_rbound[g] + dist3(row(a.xipos, i), row(a.geom_xpos, g));
                *size = maxd(*size, far);
            }
        }
    }
    if nbody > 1 {
        stat[2] = 0.0;
        for size in &mut body[1..] {
            *size = maxd(*size, 1e-5);
            stat[2] += *size / (nbody - 1) as f64;
        }
    }
    if let Some(lengths) = dof_length {
        for (i, length) in lengths.iter_mut().enumerate().take(nv) {
            let jnt = at(a.dof_jntid, i);
            let kind = a.jnt_type[jnt];
            let offset = i - at(a.jnt_dofadr, jnt);
            let rotational =
                kind == JNT_BALL || kind == JNT_HINGE || (kind == JNT_FREE && offset >= 3);
            *length = if rotational {
                body[at(a.dof_bodyid, i)]
            } else {
                1.0
            };
        }
    }
    stat[3] = maxd(stat[3], 2.0 * stat[2]);
    if nbody > 1 {
        let mut mass = 0.0;
        for m in &a.body_mass[1..nbody] {
            mass += m;
        }
        stat[1] = mass / (nbody - 1) as f64;
    }
    if nv > 0 {
        stat[0] = mean_inertia(a, 0..nv);
    }
    stat
}

/// The mean of the joint-space inertia's diagonal over `dofs` (in their order), as
/// `stat.meaninertia` of a model with those dofs has it (`dofs` not empty). A superset's
/// world takes the dofs of what its variant places.
///
/// ```
/// use mjcf_forge::split::{StatArrays, mean_inertia};
/// let a = StatArrays {
///     xpos: &[], xipos: &[], xanchor: &[], site_xpos: &[], geom_xpos: &[], geom_rbound: &[],
///     geom_type: &[], geom_size: &[], geom_dataid: &[], hfield_size: &[], body_parentid: &[],
///     body_geomadr: &[], body_geomnum: &[], body_mass: &[], jnt_bodyid: &[], jnt_type: &[],
///     jnt_dofadr: &[], dof_jntid: &[], dof_bodyid: &[],
///     inertia: &[2.0, 0.5, 4.0], inertia_diagonal: &[0, 2],
/// };
/// assert_eq!(mean_inertia(&a, [0, 1]), 3.0);
/// ```
pub fn mean_inertia(a: &StatArrays<'_>, dofs: impl IntoIterator<Item = usize>) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for i in dofs {
        sum += a.inertia[at(a.inertia_diagonal, i)];
        n += 1;
    }
    sum / n as f64
}
