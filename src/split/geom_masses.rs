//! A body's mass properties from its geoms' densities or masses, at patch cost: what the
//! compiler derives when a body takes its inertia from its geoms (its mass, principal
//! inertia and inertial frame, the same-frame flags and its bounding volumes, which the
//! compiler builds in the inertial frame), computed from each geom's properties at unit
//! density (or unit mass) read off one compile of the body's *unit model* (every geom
//! that counts for inertia alone in a body of its own, `density="1"` or `mass="1"`).
//! Each geom's mass and inertia are linear in its density or mass, so the unit model is
//! compiled once per structure, whatever the draws; meshes are never processed again.
//!
//! The arithmetic follows the compiler's (sums in its order, the same parallel-axis terms,
//! a Jacobi eigen-decomposition for the principal axes), so masses are the compiler's bit
//! for bit and inertias and inertial frames agree within a few units in the last place
//! (relative 1e-12 is the bound the tests hold; docs/compiled.md). Both faces call
//! [`write_geom_masses`] with their own MuJoCo's arrays.

use super::body_copy::{ModelArrays, ModelArraysMut};
use super::patch_error;
use super::volumes::{Volume, bounding_volumes};
use crate::document::rotation::{EPS, eigen, quat_to_mat};
use crate::error::Error;

/// The compiler's tolerance for "the same frame" (flags `mjtSameFrame`).
const FRAME_EPS: f64 = 1e-6;

/// One geom's mass properties in its body's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeomMass {
    /// Its mass.
    pub mass: f64,
    /// Its principal inertia about its centre of mass, in its own frame.
    pub inertia: [f64; 3],
    /// Its frame (for a mesh, the mesh's centre of mass and principal axes).
    pub pos: [f64; 3],
    /// Its orientation.
    pub quat: [f64; 4],
}

/// A body's mass properties: mass, principal inertia, inertial frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyMass {
    /// The body's mass.
    pub mass: f64,
    /// Its principal inertia, in decreasing order.
    pub inertia: [f64; 3],
    /// Its centre of mass, in the body's frame.
    pub ipos: [f64; 3],
    /// Its principal axes.
    pub iquat: [f64; 4],
}

/// A principal inertia in the frame `quat`, as a full inertia `[xx, yy, zz, xy, xz, yz]`
/// of the frame it is given in.
fn global_inertia(local: &[f64; 3], quat: &[f64; 4]) -> [f64; 6] {
    let m = quat_to_mat(quat);
    let t = [
        m[0] * local[0],
        m[3] * local[0],
        m[6] * local[0],
        m[1] * local[1],
        m[4] * local[1],
        m[7] * local[1],
        m[2] * local[2],
        m[5] * local[2],
        m[8] * local[2],
    ];
    [
        m[0] * t[0] + m[1] * t[3] + m[2] * t[6],
        m[3] * t[1] + m[4] * t[4] + m[5] * t[7],
        m[6] * t[2] + m[7] * t[5] + m[8] * t[8],
        m[0] * t[1] + m[1] * t[4] + m[2] * t[7],
        m[0] * t[2] + m[1] * t[5] + m[2] * t[8],
        m[3] * t[2] + m[4] * t[5] + m[5] * t[8],
    ]
}

/// The parallel-axis term of `mass` at `d` from the centre of mass.
fn off_center(mass: f64, d: &[f64; 3]) -> [f64; 6] {
    [
        mass * (d[1] * d[1] + d[2] * d[2]),
        mass * (d[0] * d[0] + d[2] * d[2]),
        mass * (d[0] * d[0] + d[1] * d[1]),
        -mass * d[0] * d[1],
        -mass * d[0] * d[2],
        -mass * d[1] * d[2],
    ]
}

/// The mass properties of a body whose inertia comes from `geoms` (those that count for
/// inertia, in the body's order), as the compiler combines them: one geom's are the
/// body's; several add up about their common centre of mass, then turn to principal axes.
///
/// ```
/// use mjcf_forge::split::{GeomMass, body_mass};
/// let unit = GeomMass { mass: 1.0, inertia: [0.1; 3], pos: [0.0; 3], quat: [1.0, 0.0, 0.0, 0.0] };
/// let two = [unit, GeomMass { pos: [1.0, 0.0, 0.0], ..unit }];
/// let body = body_mass(&two)?;
/// assert_eq!((body.mass, body.ipos), (2.0, [0.5, 0.0, 0.0]));
/// # Ok::<(), mjcf_forge::Error>(())
/// ```
pub fn body_mass(geoms: &[GeomMass]) -> Result<BodyMass, Error> {
    match geoms {
        [] => Err(patch_error("no geom counts for its inertia")),
        [one] => Ok(BodyMass {
            mass: one.mass,
            inertia: one.inertia,
            ipos: one.pos,
            iquat: one.quat,
        }),
        _ => {
            let mut mass = 0.0;
            let mut com = [0.0; 3];
            for g in geoms {
                mass += g.mass;
                for (c, p) in com.iter_mut().zip(g.pos) {
                    *c += g.mass * p;
                }
            }
            if mass < EPS {
                return Err(patch_error("its mass is too small for a centre of mass"));
            }
            let ipos = [com[0] / mass, com[1] / mass, com[2] / mass];
            let mut total = [0.0; 6];
            for g in geoms {
                let d = [g.pos[0] - ipos[0], g.pos[1] - ipos[1], g.pos[2] - ipos[2]];
                let own = global_inertia(&g.inertia, &g.quat);
                let shift = off_center(g.mass, &d);
                for ((t, o), s) in total.iter_mut().zip(own).zip(shift) {
                    *t = *t + o + s;
                }
            }
            let full = [
                total[0], total[3], total[4], total[3], total[1], total[5], total[4], total[5],
                total[2],
            ];
            let (inertia, iquat) = eigen(&full);
            if inertia[2] < EPS {
                return Err(patch_error(
                    "its inertia has an eigenvalue that is not positive",
                ));
            }
            Ok(BodyMass {
                mass,
                inertia,
                ipos,
                iquat,
            })
        }
    }
}

fn null3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| x.abs() < FRAME_EPS)
}

fn same3(a: &[f64; 3], b: &[f64; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < FRAME_EPS)
}

fn same_quat(a: &[f64; 4], b: &[f64; 4]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < FRAME_EPS)
        || a.iter().zip(b).all(|(x, y)| (x + y).abs() < FRAME_EPS)
}

const UNIT: [f64; 4] = [1.0, 0.0, 0.0, 0.0];

/// A body's same-frame flag (`mjtSameFrame`) from its inertial frame: its own frame (1),
/// its own orientation (3), or neither (0).
pub fn body_frame_flag(ipos: &[f64; 3], iquat: &[f64; 4]) -> u8 {
    match (same_quat(iquat, &UNIT), null3(ipos)) {
        (true, true) => 1,
        (true, false) => 3,
        _ => 0,
    }
}

/// A geom's or site's same-frame flag from its frame and its body's inertial frame: the
/// body's frame (1), the body's orientation (3), the inertial frame (2), its orientation
/// (4), or none (0).
pub fn frame_flag(pos: &[f64; 3], quat: &[f64; 4], ipos: &[f64; 3], iquat: &[f64; 4]) -> u8 {
    let null_quat = same_quat(quat, &UNIT);
    if null3(pos) && null_quat {
        1
    } else if null_quat {
        3
    } else if same3(pos, ipos) && same_quat(quat, iquat) {
        2
    } else if same_quat(quat, iquat) {
        4
    } else {
        0
    }
}

/// The same-frame flags [`write_frame_flags`] sets: of bodies, geoms and sites.
pub const FRAME_FLAGS: [&str; 3] = ["body_sameframe", "geom_sameframe", "site_sameframe"];

/// Sets the same-frame flags of `bodies`, `geoms` and `sites` from their frames and their
/// bodies' inertial frames ([`body_frame_flag`], [`frame_flag`]): what MuJoCo 4.0's
/// `mj_setConst` sets again (3.17.0's keeps the compiler's), for a superset world derived
/// tree by tree ([`super::TreeDerivation`]).
pub fn write_frame_flags(
    model: &mut impl ModelArraysMut,
    bodies: &[usize],
    geoms: &[usize],
    sites: &[usize],
) -> Result<(), Error> {
    let (ipos, iquat) = (model.floats("body_ipos")?, model.floats("body_iquat")?);
    let mut body_flags = Vec::with_capacity(bodies.len());
    for &b in bodies {
        body_flags.push((b, body_frame_flag(&row(ipos, b)?, &row(iquat, b)?)));
    }
    let element_flags = |kind: &str, list: &[usize]| -> Result<Vec<(usize, u8)>, Error> {
        let (pos, quat) = (
            model.floats(&format!("{kind}_pos"))?,
            model.floats(&format!("{kind}_quat"))?,
        );
        let owner = model.ints(&format!("{kind}_bodyid"))?;
        list.iter()
            .map(|&i| {
                let b = at(owner, i, "bodyid")?;
                let flag = frame_flag(
                    &row(pos, i)?,
                    &row(quat, i)?,
                    &row(ipos, b)?,
                    &row(iquat, b)?,
                );
                Ok((i, flag))
            })
            .collect()
    };
    let geom_flags = element_flags("geom", geoms)?;
    let site_flags = element_flags("site", sites)?;
    for (name, flags) in FRAME_FLAGS
        .into_iter()
        .zip([body_flags, geom_flags, site_flags])
    {
        if flags.is_empty() {
            continue;
        }
        let out = model.bytes_mut(name)?;
        for (i, flag) in flags {
            *out.get_mut(i)
                .ok_or_else(|| patch_error(format!("{name}[{i}] out of range")))? = flag;
        }
    }
    Ok(())
}

fn row<const N: usize>(a: &[f64], i: usize) -> Result<[f64; N], Error> {
    a.get(N * i..N * (i + 1))
        .and_then(|r| r.try_into().ok())
        .ok_or_else(|| patch_error(format!("row {i} out of range")))
}

fn at(a: &[i32], i: usize, what: &str) -> Result<usize, Error> {
    a.get(i)
        .and_then(|&v| usize::try_from(v).ok())
        .ok_or_else(|| patch_error(format!("{what}[{i}] out of range")))
}

/// Writes into body `body` (named `name` in errors) of `model` its mass properties for
/// geoms of densities or masses `factors`: `unit` is the compile of the body's unit model
/// (body `k + 1` holds the `k`-th geom that counts for inertia alone, at density or mass
/// 1; see the module). The geoms' same-frame flags and the bounding-volume tree are written
/// in the new inertial frame. Refused, with nothing written, when the result would not be
/// a patch of the structure (the body's own same-frame flag would change, which the
/// compiler's other choices follow).
pub fn write_geom_masses(
    model: &mut impl ModelArraysMut,
    body: usize,
    name: &str,
    unit: &impl ModelArrays,
    factors: &[f64],
) -> Result<(), Error> {
    let (um, ui) = (unit.floats("body_mass")?, unit.floats("body_inertia")?);
    let (up, uq) = (unit.floats("body_ipos")?, unit.floats("body_iquat")?);
    if um.len() != factors.len() + 1 {
        return Err(patch_error(format!(
            "body '{name}': its unit model has {} bodies for {} geoms",
            um.len().saturating_sub(1),
            factors.len()
        )));
    }
    let geoms = factors
        .iter()
        .enumerate()
        .map(|(k, &f)| {
            let i: [f64; 3] = row(ui, k + 1)?;
            Ok(GeomMass {
                mass: f * um[k + 1],
                inertia: [f * i[0], f * i[1], f * i[2]],
                pos: row(up, k + 1)?,
                quat: row(uq, k + 1)?,
            })
        })
        .collect::<Result<Vec<_>, Error>>()?;
    let b = body_mass(&geoms).map_err(|e| patch_error(format!("body '{name}': {e}")))?;
    let not_a_patch = |what: &str| {
        format!(
            "body '{name}': its geoms' densities or masses move its inertial frame so that \
             {what} would change: not a patch of this structure"
        )
    };
    if model.bytes("body_sameframe")?.get(body).copied() != Some(body_frame_flag(&b.ipos, &b.iquat))
    {
        return Err(patch_error(not_a_patch("its same-frame flag")));
    }
    let first = at(model.ints("body_geomadr")?, body, "body_geomadr")?;
    let count = at(model.ints("body_geomnum")?, body, "body_geomnum")?;
    let (pos, quat) = (model.floats("geom_pos")?, model.floats("geom_quat")?);
    let aabb = model.floats("geom_aabb")?;
    let (contype, conaffinity) = (model.ints("geom_contype")?, model.ints("geom_conaffinity")?);
    let mut volumes = Vec::with_capacity(count);
    let mut flags = Vec::with_capacity(count);
    for g in first..first + count {
        let (p, q) = (row(pos, g)?, row(quat, g)?);
        flags.push(frame_flag(&p, &q, &b.ipos, &b.iquat));
        volumes.push(Volume {
            id: i32::try_from(g).map_err(|_| patch_error("too many geoms"))?,
            collides: contype.get(g).copied().unwrap_or(0) != 0
                || conaffinity.get(g).copied().unwrap_or(0) != 0,
            pos: p,
            quat: q,
            aabb: row(aabb, g)?,
        });
    }
    // The tree in the new inertial frame: its boxes, and its shape where the frame's turn
    // reorders the geoms (as many nodes: one per geom that collides, and the inner ones).
    let nodes = if count > 0 {
        bounding_volumes(&volumes, &b.ipos, &b.iquat)
    } else {
        Vec::new()
    };
    let adr = at(model.ints("body_bvhadr")?, body, "body_bvhadr").unwrap_or(0);
    let num = at(model.ints("body_bvhnum")?, body, "body_bvhnum")?;
    if nodes.len() != num {
        return Err(patch_error(not_a_patch("its bounding-volume tree's size")));
    }
    model.floats_mut("body_mass")?[body] = b.mass;
    model.floats_mut("body_inertia")?[3 * body..3 * body + 3].copy_from_slice(&b.inertia);
    model.floats_mut("body_ipos")?[3 * body..3 * body + 3].copy_from_slice(&b.ipos);
    model.floats_mut("body_iquat")?[4 * body..4 * body + 4].copy_from_slice(&b.iquat);
    model.bytes_mut("geom_sameframe")?[first..first + count].copy_from_slice(&flags);
    let boxes = model.floats_mut("bvh_aabb")?;
    for (k, n) in nodes.iter().enumerate() {
        boxes[6 * (adr + k)..6 * (adr + k + 1)].copy_from_slice(&n.aabb);
    }
    let child = model.ints_mut("bvh_child")?;
    for (k, n) in nodes.iter().enumerate() {
        child[2 * (adr + k)..2 * (adr + k + 1)].copy_from_slice(&n.child);
    }
    let nodeid = model.ints_mut("bvh_nodeid")?;
    for (k, n) in nodes.iter().enumerate() {
        nodeid[adr + k] = n.nodeid;
    }
    let depth = model.ints_mut("bvh_depth")?;
    for (k, n) in nodes.iter().enumerate() {
        depth[adr + k] = n.depth;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_geom_is_its_body() {
        let g = GeomMass {
            mass: 2.0,
            inertia: [3.0, 2.0, 1.0],
            pos: [1.0, 2.0, 3.0],
            quat: [0.0, 1.0, 0.0, 0.0],
        };
        let b = body_mass(&[g]).unwrap();
        assert_eq!(
            (b.mass, b.inertia, b.ipos, b.iquat),
            (g.mass, g.inertia, g.pos, g.quat)
        );
    }
}
