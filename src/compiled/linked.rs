//! The linked MuJoCo behind the split tier's patch plan ([`crate::split::PatchPlan`], the
//! one implementation both faces' caches run): a [`CompiledModel`] as a
//! [`PatchModel`], its arrays found by name through `patch.c` ([`Arrays`]), its scratch
//! data, body models compiled by the FFI, and `mj_setConst` and the kinematics called
//! through `patch.c`; and as a [`TreeModel`], what a superset's tree-by-tree derivation
//! needs besides (skeletons compiled, MuJoCo's constants, `mj_camlight`, the frames).

use std::ffi::CString;
use std::path::Path;
use std::ptr::NonNull;

use super::arrays::{Arrays, array_mut};
use super::statistics::with_arrays;
use super::sys::{
    RawData, mjf_patch_delete_data, mjf_patch_get_stat, mjf_patch_id2name, mjf_patch_kinematics,
    mjf_patch_make_data, mjf_patch_make_m, mjf_patch_name2id, mjf_patch_nbytes, mjf_patch_option,
    mjf_patch_set_const, mjf_patch_set_stat, mjf_patch_size, mjf_patch_size_name,
    mjf_tree_camlight, mjf_tree_constant, mjf_tree_data,
};
use crate::error::Error;
use crate::mujoco::{CompiledModel, compile_str};
use crate::split::{
    ArrayMut, ModelArrays, ModelArraysMut, ModelLayout, PatchModel, StatArrays, Statistics,
    TreeModel, patch_error,
};

/// Scratch mjData for `mj_setConst` (which overwrites the qpos of the data it is given).
pub struct Scratch(NonNull<RawData>);

// SAFETY: exclusively owned heap data without thread affinity.
unsafe impl Send for Scratch {}

impl Drop for Scratch {
    fn drop(&mut self) {
        // SAFETY: made by mj_makeData, owned here alone.
        unsafe { mjf_patch_delete_data(self.0.as_ptr()) }
    }
}

/// An array found once: its start, element size and count.
pub struct Target {
    ptr: *mut u8,
    elem: usize,
    count: usize,
    int: bool,
}

// SAFETY: the pointer points into the model the plan belongs to, which is only written
// through `&mut` of that model.
unsafe impl Send for Target {}

/// The model's arrays (the model is live while borrowed; writes go through `&mut`).
fn arrays(model: &CompiledModel) -> Arrays {
    Arrays(std::ptr::from_ref(model.raw()).cast_mut())
}

impl ModelArrays for CompiledModel {
    fn floats(&self, name: &str) -> Result<&[f64], Error> {
        let (p, n) = arrays(self).typed::<f64>(name)?;
        // SAFETY: `n` elements of this live model, read while `self` is borrowed.
        Ok(unsafe { crate::mujoco::slice_or_empty(p.cast_const(), n) })
    }
    fn ints(&self, name: &str) -> Result<&[i32], Error> {
        let (p, n) = arrays(self).typed::<i32>(name)?;
        // SAFETY: as above.
        Ok(unsafe { crate::mujoco::slice_or_empty(p.cast_const(), n) })
    }
    fn bytes(&self, name: &str) -> Result<&[u8], Error> {
        let (p, n) = arrays(self).typed::<u8>(name)?;
        // SAFETY: as above.
        Ok(unsafe { crate::mujoco::slice_or_empty(p.cast_const(), n) })
    }
}

/// `name`'s `n` elements of `T`, to write.
fn whole_mut<'a, T>(model: &'a mut CompiledModel, name: &str) -> Result<&'a mut [T], Error> {
    let (p, n) = Arrays(model.as_mut_ptr()).typed::<T>(name)?;
    // SAFETY: `n` elements of this live model, written through its `&mut` borrow only.
    Ok(unsafe { super::arrays::whole(p.cast(), n) })
}

impl ModelArraysMut for CompiledModel {
    fn floats_mut(&mut self, name: &str) -> Result<&mut [f64], Error> {
        whole_mut(self, name)
    }
    fn bytes_mut(&mut self, name: &str) -> Result<&mut [u8], Error> {
        whole_mut(self, name)
    }
    fn ints_mut(&mut self, name: &str) -> Result<&mut [i32], Error> {
        whole_mut(self, name)
    }
}

impl ModelLayout for CompiledModel {
    fn int(&self, name: &str, i: usize) -> Result<i64, Error> {
        arrays(self).int(name, i)
    }
    fn len(&self, name: &str) -> Result<usize, Error> {
        arrays(self).len(name)
    }
}

impl PatchModel for CompiledModel {
    type Target = Target;
    type Part = CompiledModel;
    type Data = Scratch;

    fn target(&mut self, name: &str, int: bool) -> Result<Target, Error> {
        let (ptr, elem, count) = Arrays(self.as_mut_ptr()).find(name)?;
        Ok(Target {
            ptr,
            elem,
            count,
            int,
        })
    }

    fn target_mut<'a>(&'a mut self, t: &'a Target) -> ArrayMut<'a> {
        // SAFETY: the target is this live model's array (found by `target`), written only
        // through the `&mut` borrow of the model the slice lives in.
        unsafe { array_mut(t.ptr, t.elem, t.count, t.int) }
    }

    fn size(&self, name: &str) -> Option<usize> {
        for i in 0.. {
            // SAFETY: a static NUL-terminated name, or null past the last size.
            let n = unsafe { mjf_patch_size_name(i) };
            if n.is_null() {
                return None;
            }
            // SAFETY: as above.
            if unsafe { std::ffi::CStr::from_ptr(n) }.to_bytes() == name.as_bytes() {
                // SAFETY: the model is live; `i` names one of its sizes.
                return usize::try_from(unsafe { mjf_patch_size(self.raw(), i) }).ok();
            }
        }
        None
    }

    fn id(&self, object: &str, name: &str) -> Option<usize> {
        let kind = CString::new(object).ok()?;
        let name = CString::new(name).ok()?;
        // SAFETY: the model is live; both strings are NUL-terminated.
        usize::try_from(unsafe { mjf_patch_name2id(self.raw(), kind.as_ptr(), name.as_ptr()) }).ok()
    }

    fn has_option(&self, field: &str, n: usize) -> bool {
        let Ok(c) = CString::new(field) else {
            return false;
        };
        let (mut elem, mut count) = (0usize, 0usize);
        let raw = std::ptr::from_ref(self.raw()).cast_mut();
        // SAFETY: the model is live; `c` is NUL-terminated; nothing is written.
        let p = unsafe { mjf_patch_option(raw, c.as_ptr(), &mut elem, &mut count) };
        !p.is_null() && elem == std::mem::size_of::<f64>() && count == n
    }

    fn write_option(&mut self, field: &str, values: &[f64]) -> Result<(), Error> {
        let c = CString::new(field).map_err(|x| patch_error(x.to_string()))?;
        let (mut elem, mut count) = (0usize, 0usize);
        // SAFETY: the model is live; `c` is NUL-terminated.
        let p = unsafe { mjf_patch_option(self.as_mut_ptr(), c.as_ptr(), &mut elem, &mut count) };
        if p.is_null() || elem != std::mem::size_of::<f64>() || count != values.len() {
            return Err(patch_error(format!(
                "this MuJoCo's mjOption has no field {field} of {}",
                values.len()
            )));
        }
        // SAFETY: `count` doubles of the live model's mjOption, written through `&mut`.
        unsafe { std::slice::from_raw_parts_mut(p.cast::<f64>(), count) }.copy_from_slice(values);
        Ok(())
    }

    fn body_name(&self, body: usize) -> String {
        let name = i32::try_from(body).ok().and_then(|id| {
            // SAFETY: the model is live; "body" is NUL-terminated; MuJoCo checks the id.
            let p = unsafe { mjf_patch_id2name(self.raw(), c"body".as_ptr(), id) };
            // SAFETY: a NUL-terminated name in the model's names buffer.
            (!p.is_null()).then(|| unsafe { std::ffi::CStr::from_ptr(p) }.to_string_lossy())
        });
        name.map_or_else(|| body.to_string(), |n| n.into_owned())
    }

    fn compile_part(&self, xml: &str) -> Result<CompiledModel, Error> {
        compile_str(xml, Path::new(".")).map_err(|e| patch_error(e.to_string()))
    }

    fn make_data(&self) -> Result<Scratch, Error> {
        // SAFETY: the model is live.
        let d = unsafe { mjf_patch_make_data(self.raw()) };
        NonNull::new(d)
            .map(Scratch)
            .ok_or_else(|| patch_error("MuJoCo could not allocate mjData for the model"))
    }

    fn nbytes(&self, data: &Scratch) -> usize {
        // SAFETY: model and data are live.
        usize::try_from(unsafe { mjf_patch_nbytes(self.raw(), data.0.as_ptr()) }).unwrap_or(0)
    }

    fn set_const(&mut self, data: &mut Scratch) -> Result<(), Error> {
        // SAFETY: the model and its scratch data are live and of one structure.
        unsafe { mjf_patch_set_const(self.as_mut_ptr(), data.0.as_ptr()) };
        Ok(())
    }

    fn kinematics(&mut self, data: &mut Scratch) -> Result<(), Error> {
        // SAFETY: as above.
        unsafe { mjf_patch_kinematics(self.raw(), data.0.as_ptr()) };
        Ok(())
    }

    fn inertia(&mut self, data: &mut Scratch) -> Result<(), Error> {
        // SAFETY: as above.
        unsafe { mjf_patch_make_m(self.raw(), data.0.as_ptr()) };
        Ok(())
    }

    fn with_statistics<R>(
        &mut self,
        data: &Scratch,
        f: impl FnOnce(&StatArrays<'_>, &mut [f64]) -> R,
    ) -> Result<R, Error> {
        // SAFETY: as above; nothing else touches them while `f` runs.
        Ok(unsafe { with_arrays(self.as_mut_ptr(), data.0.as_ptr(), f) })
    }

    fn stat(&self) -> Statistics {
        let mut stat = [0.0; 7];
        // SAFETY: the model is live; `stat` holds 7 values.
        unsafe { mjf_patch_get_stat(self.raw(), stat.as_mut_ptr()) };
        stat
    }

    fn set_stat(&mut self, stat: &Statistics) -> Result<(), Error> {
        // SAFETY: the model is live; `stat` holds 7 values.
        unsafe { mjf_patch_set_stat(self.as_mut_ptr(), stat.as_ptr()) };
        Ok(())
    }
}

/// Whether the linked MuJoCo's `mj_setConst` sets the same-frame flags again.
static RECOMPUTES_SAMEFRAME: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

impl TreeModel for CompiledModel {
    fn compile_model(&self, xml: &str) -> Result<CompiledModel, Error> {
        compile_str(xml, Path::new(".")).map_err(|e| patch_error(e.to_string()))
    }

    fn constant(&self, name: &str) -> Option<i32> {
        let name = CString::new(name).ok()?;
        let mut found = 0;
        // SAFETY: a NUL-terminated name; the C side only reads it.
        let value = unsafe { mjf_tree_constant(name.as_ptr(), &mut found) };
        (found != 0).then_some(value)
    }

    fn recomputes_sameframe(&self) -> Result<bool, Error> {
        if let Some(&known) = RECOMPUTES_SAMEFRAME.get() {
            return Ok(known);
        }
        let probed = self.sameframe_probe()?;
        Ok(*RECOMPUTES_SAMEFRAME.get_or_init(|| probed))
    }

    fn camlight(&mut self, data: &mut Scratch) -> Result<(), Error> {
        // SAFETY: the model and its scratch data are live and of one structure.
        unsafe { mjf_tree_camlight(self.raw(), data.0.as_ptr()) };
        Ok(())
    }

    fn with_data<R>(
        &self,
        data: &Scratch,
        names: &[&str],
        f: impl FnOnce(&[&[f64]]) -> R,
    ) -> Result<R, Error> {
        let mut slices = Vec::with_capacity(names.len());
        for name in names {
            let c = CString::new(*name).map_err(|e| patch_error(e.to_string()))?;
            let mut count = 0usize;
            // SAFETY: live model and data; a NUL-terminated name.
            let p = unsafe { mjf_tree_data(self.raw(), data.0.as_ptr(), c.as_ptr(), &mut count) };
            if p.is_null() && count > 0 {
                return Err(patch_error(format!("no mjData array {name} here")));
            }
            // SAFETY: `count` numbers of the live data, read while it is borrowed.
            slices.push(unsafe { crate::mujoco::slice_or_empty(p, count) });
        }
        Ok(f(&slices))
    }
}
