//! A body model (`PatchValue::BodyModel`, see `split::SplitOptions`): the body's
//! geoms compiled alone, whose compile gives what MuJoCo derives from them (each geom's
//! size, frame, bounding radius and box, the body's mass, inertia and inertial frame, its
//! bounding volumes), copied into the body of a model of the whole structure. A body
//! model whose layout is not the body's (another `body_sameframe` or `geom_sameframe`,
//! bounding-volume tree or geom types) is refused: the document is then compiled.

use std::ffi::{CString, c_int};
use std::path::Path;

use super::sys::mjf_patch_array;
use crate::mujoco::{CompiledModel, MjModel, compile_str};

/// Body models compiled so far, by their MJCF text, the newest last.
#[derive(Default)]
pub(super) struct BodyModels {
    models: Vec<(String, CompiledModel)>,
}

/// How many body models a plan keeps.
const KEPT: usize = 64;

/// One array of a live model: its pointer, element size and element count.
struct Array {
    ptr: *mut u8,
    elem: usize,
    count: usize,
}

fn array(m: *mut MjModel, name: &str) -> Result<Array, String> {
    let c = CString::new(name).map_err(|e| e.to_string())?;
    let (mut elem, mut count) = (0usize, 0usize);
    // SAFETY: the model is live; `c` is NUL-terminated.
    let p = unsafe { mjf_patch_array(m, c.as_ptr(), &mut elem, &mut count) };
    if (p.is_null() && count > 0) || elem == 0 {
        return Err(format!("this MuJoCo's mjModel has no array {name}"));
    }
    Ok(Array {
        ptr: p.cast(),
        elem,
        count,
    })
}

/// `name[at]`, an integer (or a byte) of the model.
fn int(m: *mut MjModel, name: &str, at: usize) -> Result<i64, String> {
    let a = array(m, name)?;
    if at >= a.count {
        return Err(format!("{name}[{at}] out of range"));
    }
    // SAFETY: `at` < count elements of `elem` bytes at `ptr`.
    Ok(unsafe {
        match a.elem {
            1 => i64::from(a.ptr.add(at).read()),
            4 => i64::from(a.ptr.cast::<c_int>().add(at).read_unaligned()),
            _ => return Err(format!("{name} is not an integer array")),
        }
    })
}

/// Where rows `first..first + n` of `name` are, each `width` elements wide: their first
/// byte and their length in bytes, checked against the array's length.
fn span(
    m: *mut MjModel,
    name: &str,
    first: usize,
    n: usize,
    width: usize,
) -> Result<(*mut u8, usize), String> {
    let a = array(m, name)?;
    let (start, len) = (first * width, n * width);
    if start + len > a.count {
        return Err(format!("{name}[{start}..{}] out of range", start + len));
    }
    // SAFETY: in bounds of the live array (checked above).
    Ok((unsafe { a.ptr.add(start * a.elem) }, len * a.elem))
}

/// A copy of the bytes of rows `first..first + n` of `name`.
fn read(
    m: *mut MjModel,
    name: &str,
    first: usize,
    n: usize,
    width: usize,
) -> Result<Vec<u8>, String> {
    let (p, len) = span(m, name, first, n, width)?;
    // SAFETY: `len` bytes of the live model at `p` (see `span`).
    Ok(unsafe { std::slice::from_raw_parts(p, len) }.to_vec())
}

/// Copies rows of `name` from `from` (starting at `from_first`) to `to` (at `to_first`).
fn copy(
    name: &str,
    width: usize,
    n: usize,
    from: (*mut MjModel, usize),
    to: (*mut MjModel, usize),
) -> Result<(), String> {
    let (src, len) = span(from.0, name, from.1, n, width)?;
    let (dst, dst_len) = span(to.0, name, to.1, n, width)?;
    debug_assert_eq!(len, dst_len);
    // SAFETY: `len` bytes of two live models (see `span`), distinct allocations.
    unsafe { std::ptr::copy_nonoverlapping(src, dst, len.min(dst_len)) };
    Ok(())
}

impl BodyModels {
    /// Writes into body `body` of `model` what MuJoCo derives from its geoms, read off the
    /// compile of their body model `xml` (compiled once, kept).
    pub(super) fn write(
        &mut self,
        model: *mut MjModel,
        body: usize,
        xml: &str,
    ) -> Result<(), String> {
        let at = match self.models.iter().position(|(x, _)| x == xml) {
            Some(at) => at,
            None => {
                let part = compile_str(xml, Path::new(".")).map_err(|e| e.to_string())?;
                if self.models.len() >= KEPT {
                    self.models.remove(0);
                }
                self.models.push((xml.to_string(), part));
                self.models.len() - 1
            }
        };
        let part = self.models[at].1.as_mut_ptr();
        let geoms = |m, b| -> Result<(usize, usize), String> {
            Ok((
                int(m, "body_geomadr", b)? as usize,
                int(m, "body_geomnum", b)? as usize,
            ))
        };
        let bvh = |m, b| -> Result<(usize, usize), String> {
            Ok((
                int(m, "body_bvhadr", b)?.max(0) as usize,
                int(m, "body_bvhnum", b)? as usize,
            ))
        };
        let (g, n) = geoms(model, body)?;
        let (lg, ln) = geoms(part, 1)?;
        let (v, nv) = bvh(model, body)?;
        let (lv, lnv) = bvh(part, 1)?;
        let same = |name: &str, width: usize, a: (usize, usize), b: (usize, usize)| {
            Ok::<bool, String>(
                read(model, name, a.0, a.1, width)? == read(part, name, b.0, b.1, width)?,
            )
        };
        let nodes = |m, first: usize, count| -> Result<Vec<i64>, String> {
            (first..first + count)
                .map(|k| int(m, "bvh_nodeid", k))
                .collect()
        };
        // Leaves name geoms by id: the body model's start at its first geom.
        let shifted: Vec<i64> = nodes(part, lv, lnv)?
            .into_iter()
            .map(|id| {
                if id >= 0 {
                    id - lg as i64 + g as i64
                } else {
                    id
                }
            })
            .collect();
        if ln != n
            || lnv != nv
            || int(part, "body_sameframe", 1)? != int(model, "body_sameframe", body)?
            || !same("geom_type", 1, (g, n), (lg, ln))?
            || !same("geom_sameframe", 1, (g, n), (lg, ln))?
            || !same("bvh_child", 2, (v, nv), (lv, lnv))?
            || !same("bvh_depth", 1, (v, nv), (lv, lnv))?
            || shifted != nodes(model, v, nv)?
        {
            return Err(format!(
                "body {body}: its geoms compile to another layout than this structure's \
                 (sizes, frames or densities that move or turn its inertial frame off its own, \
                 or another bounding-volume tree): not a patch of it"
            ));
        }
        for (name, width) in [
            ("geom_size", 3),
            ("geom_rbound", 1),
            ("geom_aabb", 6),
            ("geom_pos", 3),
            ("geom_quat", 4),
        ] {
            copy(name, width, n, (part, lg), (model, g))?;
        }
        for (name, width) in [
            ("body_mass", 1),
            ("body_inertia", 3),
            ("body_ipos", 3),
            ("body_iquat", 4),
        ] {
            copy(name, width, 1, (part, 1), (model, body))?;
        }
        copy("bvh_aabb", 6, nv, (part, lv), (model, v))?;
        Ok(())
    }
}
