//! A live model's arrays by their `mjModel` names, through `patch.c` (MuJoCo's X-macro
//! table): what the split tier's shared rules read and write on the C face
//! (the split tier's patch plan, through `linked.rs`).

use std::ffi::{CString, c_int};

use super::sys::mjf_patch_array;
use crate::error::Error;
use crate::mujoco::MjModel;
use crate::split::{ArrayMut, ModelArrays, ModelArraysMut, ModelLayout, patch_error};

/// A live model's arrays by name (the caller keeps the model alive and writes it through
/// nothing else while this is borrowed).
pub(super) struct Arrays(pub(super) *mut MjModel);

impl Arrays {
    /// `name`'s pointer, element size and element count.
    pub(super) fn find(&self, name: &str) -> Result<(*mut u8, usize, usize), Error> {
        let c = CString::new(name).map_err(|e| patch_error(e.to_string()))?;
        let (mut elem, mut count) = (0usize, 0usize);
        // SAFETY: the model is live; `c` is NUL-terminated.
        let p = unsafe { mjf_patch_array(self.0, c.as_ptr(), &mut elem, &mut count) };
        if elem == 0 || (p.is_null() && count > 0) {
            return Err(patch_error(format!(
                "this MuJoCo's mjModel has no array {name}"
            )));
        }
        Ok((p.cast(), elem, count))
    }

    /// `name`'s pointer and element count, checked to hold elements of `T`'s size.
    pub(super) fn typed<T>(&self, name: &str) -> Result<(*mut T, usize), Error> {
        let (p, elem, count) = self.find(name)?;
        if elem != std::mem::size_of::<T>() {
            return Err(patch_error(format!(
                "this MuJoCo's mjModel has no array {name} of that type"
            )));
        }
        Ok((p.cast(), count))
    }

    fn get<T>(&self, name: &str) -> Result<&[T], Error> {
        let (p, n) = self.typed::<T>(name)?;
        // SAFETY: `n` elements of the live model at `p`, read while `self` is borrowed.
        Ok(unsafe { crate::mujoco::slice_or_empty(p.cast_const(), n) })
    }

    fn get_mut<T>(&mut self, name: &str) -> Result<&mut [T], Error> {
        let (p, n) = self.typed::<T>(name)?;
        // SAFETY: as in `whole`.
        Ok(unsafe { whole(p.cast(), n) })
    }
}

/// `n` elements at `p`, to write (empty when there are none).
///
/// # Safety
/// `p` points at `n` elements of `T` of a live model, and no other view of them lives
/// while the slice does.
pub(super) unsafe fn whole<'a, T>(p: *mut u8, n: usize) -> &'a mut [T] {
    if n == 0 || p.is_null() {
        return &mut [];
    }
    // SAFETY: as the caller promises.
    unsafe { std::slice::from_raw_parts_mut(p.cast(), n) }
}

/// A whole array at `p` of `count` elements of `elem` bytes, as the type the landing
/// expects (`int`: ids or collision bits; else `mjtNum`, or `float` at 4 bytes).
///
/// # Safety
/// As for [`whole`].
pub(super) unsafe fn array_mut<'a>(
    p: *mut u8,
    elem: usize,
    count: usize,
    int: bool,
) -> ArrayMut<'a> {
    // SAFETY: as the caller promises, for each element type by its size.
    unsafe {
        match (elem, int) {
            (4, true) => ArrayMut::I32(whole(p, count)),
            (4, false) => ArrayMut::F32(whole(p, count)),
            _ => ArrayMut::F64(whole(p, count)),
        }
    }
}

impl ModelArrays for Arrays {
    fn floats(&self, name: &str) -> Result<&[f64], Error> {
        self.get(name)
    }
    fn ints(&self, name: &str) -> Result<&[i32], Error> {
        self.get(name)
    }
    fn bytes(&self, name: &str) -> Result<&[u8], Error> {
        self.get(name)
    }
}

impl ModelArraysMut for Arrays {
    fn floats_mut(&mut self, name: &str) -> Result<&mut [f64], Error> {
        self.get_mut(name)
    }
    fn bytes_mut(&mut self, name: &str) -> Result<&mut [u8], Error> {
        self.get_mut(name)
    }
    fn ints_mut(&mut self, name: &str) -> Result<&mut [i32], Error> {
        self.get_mut(name)
    }
}

impl ModelLayout for Arrays {
    fn int(&self, name: &str, i: usize) -> Result<i64, Error> {
        let a: &[c_int] = self.get(name)?;
        a.get(i)
            .map(|&v| i64::from(v))
            .ok_or_else(|| patch_error(format!("{name}[{i}] out of range")))
    }
    fn len(&self, name: &str) -> Result<usize, Error> {
        Ok(self.find(name)?.2)
    }
}
