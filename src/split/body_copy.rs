//! A body model's compile copied into the body of a model of the whole structure: what
//! MuJoCo derives from the body's geoms (each geom's size, frame, bounding radius and box,
//! the body's mass, inertia and inertial frame, its bounding volumes), after checking that
//! the body model has the body's layout. The model caches of both faces call this with
//! their own MuJoCo's arrays, found by name ([`ModelArrays`]): the C face through
//! `patch.c` (`compiled/linked.rs`), the Python face over the user's `MjModel` in
//! place (`python/src/split/`).

use super::patch_error;
use crate::error::Error;

/// A compiled model's arrays by their `mjModel` names.
pub trait ModelArrays {
    /// An array of `mjtNum`; an error names an array this model does not have.
    fn floats(&self, name: &str) -> Result<&[f64], Error>;
    /// An array of `int`.
    fn ints(&self, name: &str) -> Result<&[i32], Error>;
    /// An array of `mjtByte`.
    fn bytes(&self, name: &str) -> Result<&[u8], Error>;
}

/// A compiled model's arrays, to write.
pub trait ModelArraysMut: ModelArrays {
    /// An array of `mjtNum`, to write.
    fn floats_mut(&mut self, name: &str) -> Result<&mut [f64], Error>;
    /// An array of `mjtByte`, to write.
    fn bytes_mut(&mut self, name: &str) -> Result<&mut [u8], Error>;
    /// An array of `int`, to write.
    fn ints_mut(&mut self, name: &str) -> Result<&mut [i32], Error>;
}

/// The arrays copied from a body model, each with its width: per geom of the body, per
/// body, per bounding-volume node.
const GEOM_FIELDS: [(&str, usize); 5] = [
    ("geom_size", 3),
    ("geom_rbound", 1),
    ("geom_aabb", 6),
    ("geom_pos", 3),
    ("geom_quat", 4),
];
const BODY_FIELDS: [(&str, usize); 4] = [
    ("body_mass", 1),
    ("body_inertia", 3),
    ("body_ipos", 3),
    ("body_iquat", 4),
];
const BVH_FIELDS: [(&str, usize); 1] = [("bvh_aabb", 6)];

/// Every array a body model's copy ([`copy_body_model`]) writes, with the same-frame flags
/// a patch of frames sets again ([`FRAME_FLAGS`](super::FRAME_FLAGS)): what a world's
/// patch writes besides the arrays its entries name.
///
/// ```
/// assert!(mjcf_forge::split::body_model_writes().contains(&"geom_aabb"));
/// ```
pub fn body_model_writes() -> Vec<&'static str> {
    GEOM_FIELDS
        .iter()
        .chain(&BODY_FIELDS)
        .chain(&BVH_FIELDS)
        .map(|&(name, _)| name)
        .chain(super::FRAME_FLAGS)
        .collect()
}

/// The inertial frame of a body its geoms give no mass, as the structure compiled it:
/// MuJoCo puts it where it puts a massless body's, which is not a function of the geoms
/// alone (a body model at the origin has another), so it is kept while the body's own
/// frame is.
#[derive(Debug, Clone, PartialEq)]
pub struct MasslessFrame {
    pos: [f64; 3],
    quat: [f64; 4],
    ipos: [f64; 3],
    iquat: [f64; 4],
    sameframe: u8,
}

fn row<const N: usize>(a: &[f64], i: usize) -> Result<[f64; N], Error> {
    a.get(N * i..N * (i + 1))
        .and_then(|r| r.try_into().ok())
        .ok_or_else(|| patch_error(format!("row {i} out of range")))
}

/// The massless bodies of `m` (no mass, no inertia) and their inertial frames, by body.
///
/// ```
/// # use mjcf_forge::Error;
/// # use mjcf_forge::split::{ModelArrays, massless_frames};
/// # struct One;
/// # impl ModelArrays for One {
/// #     fn floats(&self, name: &str) -> Result<&[f64], Error> {
/// #         Ok(match name {
/// #             "body_mass" => &[0.0, 0.0],
/// #             "body_inertia" | "body_pos" | "body_ipos" => &[0.0; 6],
/// #             _ => &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
/// #         })
/// #     }
/// #     fn ints(&self, _: &str) -> Result<&[i32], Error> { Ok(&[]) }
/// #     fn bytes(&self, _: &str) -> Result<&[u8], Error> { Ok(&[1, 1]) }
/// # }
/// // A world and one body without mass: the body's frame is kept (the world has none).
/// assert_eq!(massless_frames(&One)?.iter().map(|(b, _)| *b).collect::<Vec<_>>(), [1]);
/// # Ok::<(), Error>(())
/// ```
pub fn massless_frames(m: &impl ModelArrays) -> Result<Vec<(usize, MasslessFrame)>, Error> {
    let (mass, inertia) = (m.floats("body_mass")?, m.floats("body_inertia")?);
    let mut out = Vec::new();
    for (b, &weight) in mass.iter().enumerate().skip(1) {
        if weight == 0.0 && row::<3>(inertia, b)?.iter().all(|&x| x == 0.0) {
            out.push((
                b,
                MasslessFrame {
                    pos: row(m.floats("body_pos")?, b)?,
                    quat: row(m.floats("body_quat")?, b)?,
                    ipos: row(m.floats("body_ipos")?, b)?,
                    iquat: row(m.floats("body_iquat")?, b)?,
                    sameframe: *m
                        .bytes("body_sameframe")?
                        .get(b)
                        .ok_or_else(|| patch_error("body_sameframe"))?,
                },
            ));
        }
    }
    Ok(out)
}

/// `count` rows of `width` from `first`, checked.
fn rows<T>(a: &[T], first: usize, count: usize, width: usize) -> Result<&[T], Error> {
    a.get(width * first..width * (first + count))
        .ok_or_else(|| patch_error(format!("rows {first}..{} out of range", first + count)))
}

fn index(a: &[i32], i: usize, name: &str) -> Result<usize, Error> {
    a.get(i)
        .map(|&v| v.max(0) as usize)
        .ok_or_else(|| patch_error(format!("{name}[{i}] out of range")))
}

/// Body `b`'s first geom, geom count, first bounding-volume node and node count.
fn span(m: &(impl ModelArrays + ?Sized), b: usize) -> Result<(usize, usize, usize, usize), Error> {
    Ok((
        index(m.ints("body_geomadr")?, b, "body_geomadr")?,
        index(m.ints("body_geomnum")?, b, "body_geomnum")?,
        index(m.ints("body_bvhadr")?, b, "body_bvhadr")?,
        index(m.ints("body_bvhnum")?, b, "body_bvhnum")?,
    ))
}

/// Writes into body `body` (named `name` in errors) of `model` what MuJoCo derives from its
/// geoms, read off `part`, the compile of the body's body model (the world and one body).
/// `kept`: the body's [`MasslessFrame`], when the structure compiled it without mass.
/// Refused, with nothing written, when the body model's layout is not the body's (its
/// geoms' types or frames, its bounding-volume tree, whether its inertial frame is its
/// own), or when a massless body's own frame moved: the document is then compiled.
pub fn copy_body_model(
    model: &mut impl ModelArraysMut,
    body: usize,
    name: &str,
    kept: Option<&MasslessFrame>,
    part: &impl ModelArrays,
) -> Result<(), Error> {
    let not_a_patch = || {
        format!(
            "body '{name}': its geoms compile to another layout than this structure's (sizes, \
             frames or densities that move or turn its inertial frame off its own, or another \
             bounding-volume tree): not a patch of it"
        )
    };
    if part.floats("body_mass")?.len() != 2 {
        return Err(patch_error(not_a_patch()));
    }
    // It has a mass now: its geoms place its inertial frame.
    let massive = part.floats("body_mass")?[1] != 0.0
        || row::<3>(part.floats("body_inertia")?, 1)?
            .iter()
            .any(|&x| x != 0.0);
    let kept = kept.filter(|_| !massive);
    if let Some(k) = kept
        && (row::<3>(model.floats("body_pos")?, body)? != k.pos
            || row::<4>(model.floats("body_quat")?, body)? != k.quat)
    {
        return Err(patch_error(format!(
            "body '{name}' has no mass and another frame: not a patch of it"
        )));
    }
    let (g, n, v, nv) = span(&*model, body)?;
    let (pg, pn, pv, pnv) = span(part, 1)?;
    let sameframe = |m: &[u8], b: usize| {
        m.get(b)
            .copied()
            .ok_or_else(|| patch_error("body_sameframe"))
    };
    let same_ints = |field: &str, width: usize, (a, b): ((usize, usize), (usize, usize))| {
        Ok::<_, Error>(
            rows(model.ints(field)?, a.0, a.1, width)? == rows(part.ints(field)?, b.0, b.1, width)?,
        )
    };
    // Leaves name geoms by id: the body model's start at its first geom.
    let shifted: Vec<i32> = rows(part.ints("bvh_nodeid")?, pv, pnv, 1)?
        .iter()
        .map(|&id| {
            if id >= 0 {
                id - pg as i32 + g as i32
            } else {
                id
            }
        })
        .collect();
    let layout = pn == n
        && pnv == nv
        && (kept.is_some()
            || sameframe(part.bytes("body_sameframe")?, 1)?
                == sameframe(model.bytes("body_sameframe")?, body)?)
        && same_ints("geom_type", 1, ((g, n), (pg, pn)))?
        && rows(model.bytes("geom_sameframe")?, g, n, 1)?
            == rows(part.bytes("geom_sameframe")?, pg, pn, 1)?
        && same_ints("bvh_child", 2, ((v, nv), (pv, pnv)))?
        && same_ints("bvh_depth", 1, ((v, nv), (pv, pnv)))?
        && shifted == rows(model.ints("bvh_nodeid")?, v, nv, 1)?;
    if !layout {
        return Err(patch_error(not_a_patch()));
    }
    let copies = GEOM_FIELDS
        .iter()
        .map(|&(f, w)| (f, w, g, pg, n))
        .chain(BODY_FIELDS.iter().map(|&(f, w)| (f, w, body, 1, 1)))
        .chain(BVH_FIELDS.iter().map(|&(f, w)| (f, w, v, pv, nv)));
    for (field, width, to, from, count) in copies {
        let source = rows(part.floats(field)?, from, count, width)?;
        let target = model.floats_mut(field)?;
        target
            .get_mut(width * to..width * (to + count))
            .ok_or_else(|| patch_error(format!("{field}: rows out of range")))?
            .copy_from_slice(source);
    }
    if let Some(k) = kept {
        model.floats_mut("body_ipos")?[3 * body..3 * body + 3].copy_from_slice(&k.ipos);
        model.floats_mut("body_iquat")?[4 * body..4 * body + 4].copy_from_slice(&k.iquat);
        model.bytes_mut("body_sameframe")?[body] = k.sameframe;
    }
    Ok(())
}
