//! A body model (`PatchValue::BodyModel`, see `split::SplitOptions`): the body's
//! geoms compiled alone, whose compile gives what MuJoCo derives from them, copied into the
//! body of a model of the whole structure by [`crate::split::copy_body_model`] (the rule
//! both faces share; this is the C face's side: the linked MuJoCo's arrays by name, and the
//! body models compiled so far).

use std::ffi::CString;
use std::path::Path;

use super::sys::mjf_patch_array;
use crate::mujoco::{CompiledModel, MjModel, compile_str};
use crate::split::{MasslessFrame, ModelArrays, ModelArraysMut, copy_body_model, massless_frames};

/// A live model's arrays by name, through `patch.c`.
struct Arrays(*mut MjModel);

impl Arrays {
    /// `name`'s pointer and element count, checked to hold elements of `T`.
    fn find<T>(&self, name: &str) -> Result<(*mut T, usize), String> {
        let c = CString::new(name).map_err(|e| e.to_string())?;
        let (mut elem, mut count) = (0usize, 0usize);
        // SAFETY: the model is live; `c` is NUL-terminated.
        let p = unsafe { mjf_patch_array(self.0, c.as_ptr(), &mut elem, &mut count) };
        if elem != std::mem::size_of::<T>() || (p.is_null() && count > 0) {
            return Err(format!(
                "this MuJoCo's mjModel has no array {name} of that type"
            ));
        }
        Ok((p.cast(), count))
    }

    fn get<T>(&self, name: &str) -> Result<&[T], String> {
        let (p, n) = self.find::<T>(name)?;
        // SAFETY: `n` elements of the live model at `p`, read while `self` is borrowed.
        Ok(unsafe { crate::mujoco::slice_or_empty(p.cast_const(), n) })
    }

    fn get_mut<T>(&mut self, name: &str) -> Result<&mut [T], String> {
        let (p, n) = self.find::<T>(name)?;
        if n == 0 {
            return Ok(&mut []);
        }
        // SAFETY: `n` elements of the live model at `p`, the only view while `self` is
        // borrowed mutably.
        Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

impl ModelArrays for Arrays {
    fn floats(&self, name: &str) -> Result<&[f64], String> {
        self.get(name)
    }
    fn ints(&self, name: &str) -> Result<&[i32], String> {
        self.get(name)
    }
    fn bytes(&self, name: &str) -> Result<&[u8], String> {
        self.get(name)
    }
}

impl ModelArraysMut for Arrays {
    fn floats_mut(&mut self, name: &str) -> Result<&mut [f64], String> {
        self.get_mut(name)
    }
    fn bytes_mut(&mut self, name: &str) -> Result<&mut [u8], String> {
        self.get_mut(name)
    }
}

/// Body models compiled so far, by their MJCF text, the newest last; and the inertial
/// frames of the structure's massless bodies.
pub(super) struct BodyModels {
    models: Vec<(String, CompiledModel)>,
    massless: Vec<(usize, MasslessFrame)>,
}

/// How many body models a plan keeps.
const KEPT: usize = 64;

impl BodyModels {
    /// The body models of `model`'s plan, none compiled yet; its massless bodies' frames
    /// as it holds them now (made when the model is first patched).
    pub(super) fn of(model: &CompiledModel) -> Result<BodyModels, String> {
        let arrays = Arrays(std::ptr::from_ref(model.raw()).cast_mut());
        Ok(BodyModels {
            models: Vec::new(),
            massless: massless_frames(&arrays)?,
        })
    }

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
        let part = Arrays(self.models[at].1.as_mut_ptr());
        let kept = self
            .massless
            .iter()
            .find(|(b, _)| *b == body)
            .map(|(_, k)| k);
        copy_body_model(&mut Arrays(model), body, &body.to_string(), kept, &part)
    }
}
