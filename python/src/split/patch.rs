//! An array of a user's `MjModel` that a patch run writes (`Run::write`), by the type it
//! holds: the patch plan's target over the user's `mujoco` (`plan.rs`).

use pyo3::prelude::*;

use super::arrays::Array;
use mjcf_forge::split::ArrayMut;

/// An array a run writes, by its element type.
pub(super) enum Whole {
    F64(Array<f64>),
    F32(Array<f32>),
    I32(Array<i32>),
}

impl Whole {
    /// `array` of `model` as the type it holds (NumPy's type string).
    pub(super) fn of(model: &Bound<'_, PyAny>, array: &str) -> PyResult<Whole> {
        let obj = model.getattr(array)?;
        let typestr: String = obj
            .getattr("__array_interface__")?
            .get_item("typestr")?
            .extract()?;
        Ok(match typestr.as_str() {
            "<f4" => Whole::F32(Array::of(&obj, array, true)?),
            "<i4" => Whole::I32(Array::of(&obj, array, true)?),
            _ => Whole::F64(Array::of(&obj, array, true)?),
        })
    }

    /// The array, to write.
    ///
    /// # Safety
    /// As for [`Array::slice_mut`].
    pub(super) unsafe fn slice_mut(&self) -> ArrayMut<'_> {
        // SAFETY: as the caller promises.
        unsafe {
            match self {
                Whole::F64(a) => ArrayMut::F64(a.slice_mut()),
                Whole::F32(a) => ArrayMut::F32(a.slice_mut()),
                Whole::I32(a) => ArrayMut::I32(a.slice_mut()),
            }
        }
    }
}
