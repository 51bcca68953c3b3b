//! A body model (`PatchValue::BodyModel`, see `split::SplitOptions`): the body's
//! geoms compiled alone, whose compile gives what MuJoCo derives from them, copied into the
//! body of a model of the whole structure by [`crate::split::copy_body_model`] (the rule
//! both faces share; this is the C face's side: the linked MuJoCo's arrays by name, and the
//! body models compiled so far).

use std::path::Path;

use super::arrays::Arrays;
use crate::mujoco::{CompiledModel, MjModel, compile_str};
use crate::split::{MasslessFrame, copy_body_model, massless_frames, write_geom_masses};

/// Body models and unit models compiled so far, by their MJCF text, the newest last; the
/// inertial frames of the structure's massless bodies; and the unit model of the patch's
/// last `unit_geoms` entry, whose `geom_factors` entry follows it.
pub(super) struct BodyModels {
    models: Vec<(String, CompiledModel)>,
    massless: Vec<(usize, MasslessFrame)>,
    unit: Option<String>,
}

/// How many body models a plan keeps.
const KEPT: usize = crate::split::BODY_MODELS_KEPT;

impl BodyModels {
    /// The body models of `model`'s plan, none compiled yet; its massless bodies' frames
    /// as it holds them now (made when the model is first patched).
    pub(super) fn of(model: &CompiledModel) -> Result<BodyModels, String> {
        let arrays = Arrays(std::ptr::from_ref(model.raw()).cast_mut());
        Ok(BodyModels {
            models: Vec::new(),
            massless: massless_frames(&arrays)?,
            unit: None,
        })
    }

    /// The index of the compile of `xml`, compiled on first sight (and kept).
    fn compiled(&mut self, xml: &str) -> Result<usize, String> {
        Ok(match self.models.iter().position(|(x, _)| x == xml) {
            Some(at) => at,
            None => {
                let part = compile_str(xml, Path::new(".")).map_err(|e| e.to_string())?;
                if self.models.len() >= KEPT {
                    self.models.remove(0);
                }
                self.models.push((xml.to_string(), part));
                self.models.len() - 1
            }
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
        let at = self.compiled(xml)?;
        let part = Arrays(self.models[at].1.as_mut_ptr());
        let kept = self
            .massless
            .iter()
            .find(|(b, _)| *b == body)
            .map(|(_, k)| k);
        copy_body_model(&mut Arrays(model), body, &body.to_string(), kept, &part)
    }

    /// Makes the unit model `xml` (compiled once, kept) the one the next
    /// [`BodyModels::write_masses`] reads.
    pub(super) fn unit(&mut self, xml: &str) -> Result<(), String> {
        self.compiled(xml)?;
        self.unit = Some(xml.to_string());
        Ok(())
    }

    /// Writes into body `body` (named `name`) of `model` its mass properties for its unit
    /// model's geoms at densities or masses `factors`.
    pub(super) fn write_masses(
        &mut self,
        model: *mut MjModel,
        body: usize,
        name: &str,
        factors: &[f64],
    ) -> Result<(), String> {
        let xml = self
            .unit
            .as_deref()
            .ok_or_else(|| format!("body '{name}': geom factors without a unit model"))?;
        let at = self
            .models
            .iter()
            .position(|(x, _)| x == xml)
            .ok_or_else(|| format!("body '{name}': its unit model is gone"))?;
        let unit = Arrays(self.models[at].1.as_mut_ptr());
        write_geom_masses(&mut Arrays(model), body, name, &unit, factors)
    }
}
