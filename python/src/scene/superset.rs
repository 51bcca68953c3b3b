//! `Superset`: one model for every variant of a scene (see `mjcf_forge::scene::Superset`).

use std::sync::Arc;

use mjcf_forge::scene::{Scene, Superset};
use mjcf_forge::split::{PatchEntry, PatchValue};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use rayon::prelude::*;

use super::variant_index;
use crate::document::patch::patch_list;
use crate::errors::run;

/// A scene's superset: the template with every object any slot can hold, so that every
/// variant (which objects stand where included) is a patch of one compiled model, as
/// batched simulators need. Made by :meth:`Scene.superset`; ``ModelCache(scene,
/// superset=True)`` compiles and patches it.
#[pyclass(name = "Superset", module = "mjcf_forge", frozen)]
pub(crate) struct PySuperset {
    pub(crate) scene: Arc<Scene>,
    pub(crate) superset: Superset,
    pub(crate) xml: String,
}

#[pymethods]
impl PySuperset {
    /// The superset model as compact MJCF (asset paths absolute).
    #[getter]
    fn xml(&self) -> &str {
        &self.xml
    }

    /// The structure key every variant's superset patch carries.
    #[getter]
    fn structure_key(&self) -> &str {
        &self.superset.structure_key
    }

    /// Variant ``index`` as a patch of the superset model (the same form as
    /// :attr:`Variant.patch`): the placed objects switched on with their values, the others
    /// parked (out of reach in their own cells high above the world, invisible, held
    /// still; collision flags stay as authored). An
    /// :class:`MjcfError` when the variant randomizes a value no patch can carry.
    fn patch<'py>(
        &self,
        py: Python<'py>,
        index: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let index = variant_index(index)?;
        let p = run(py, || {
            Ok(self.scene.superset_patch(&self.superset, index)?)
        })?;
        PyTuple::new(py, patch_list(py, &p.entries)?)
    }

    /// For variant ``index``, each placed object's prefix and the tag its names carry in
    /// the superset: a superset name is tag + the variant's name.
    fn names(&self, py: Python<'_>, index: &Bound<'_, PyAny>) -> PyResult<Vec<(String, String)>> {
        let index = variant_index(index)?;
        run(py, || {
            Ok(self.scene.superset_names(&self.superset, index)?)
        })
    }

    /// For variant ``index``, the superset names of the root bodies of the objects it does
    /// not place (parked).
    fn parked(&self, py: Python<'_>, index: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
        let index = variant_index(index)?;
        run(py, || {
            Ok(self.scene.superset_parked(&self.superset, index)?)
        })
    }

    /// Variants ``indices`` as superset patches at once, made in parallel (what a batch of
    /// worlds needs; the same patches as :meth:`patch`, split apart). Returns ``(layouts,
    /// worlds)``: ``layouts``, the distinct layouts of the patches, each a tuple of
    /// ``(object, name or id, field, width)`` per entry (``width``: how many numbers, -1
    /// for a string value); ``worlds``, per index, ``(layout, numbers, strings, parked)``:
    /// its layout's position in ``layouts``, its numbers end to end (``bytes`` of
    /// native-endian ``float64``, for ``numpy.frombuffer``), its string values in order,
    /// and the root bodies it parks (as :meth:`parked`). An :class:`MjcfError` names a
    /// variant no patch can carry.
    #[allow(clippy::type_complexity)]
    fn worlds<'py>(
        &self,
        py: Python<'py>,
        indices: Vec<u64>,
    ) -> PyResult<(
        Vec<Bound<'py, PyTuple>>,
        Vec<(usize, Bound<'py, PyBytes>, Vec<String>, Vec<String>)>,
    )> {
        let made = run(py, || {
            indices
                .par_iter()
                .map(|&i| {
                    let patch = self.scene.superset_patch(&self.superset, i)?;
                    let parked = self.scene.superset_parked(&self.superset, i)?;
                    Ok((patch.entries, parked))
                })
                .collect::<Result<Vec<_>, mjcf_forge::Errors>>()
                .map_err(Into::into)
        })?;
        let mut layouts: Vec<Vec<(&'static str, Option<usize>, String, &'static str, i64)>> =
            Vec::new();
        let mut worlds = Vec::with_capacity(made.len());
        for (entries, parked) in &made {
            let layout: Vec<_> = entries.iter().map(layout_entry).collect();
            let at = match layouts.iter().position(|l| *l == layout) {
                Some(at) => at,
                None => {
                    layouts.push(layout);
                    layouts.len() - 1
                }
            };
            let mut numbers: Vec<u8> = Vec::new();
            let mut strings = Vec::new();
            for e in entries {
                match &e.value {
                    PatchValue::Numbers(v) => {
                        numbers.extend(v.iter().flat_map(|x| x.to_ne_bytes()));
                    }
                    PatchValue::Id { name, .. } | PatchValue::BodyModel(name) => {
                        strings.push(name.clone());
                    }
                }
            }
            worlds.push((at, PyBytes::new(py, &numbers), strings, parked.clone()));
        }
        let layouts = layouts
            .iter()
            .map(|l| {
                let items = l
                    .iter()
                    .map(|(object, id, name, field, width)| {
                        let name = match id {
                            Some(id) => id.into_pyobject(py)?.into_any(),
                            None => name.as_str().into_pyobject(py)?.into_any(),
                        };
                        (*object, name, *field, *width).into_pyobject(py)
                    })
                    .collect::<PyResult<Vec<_>>>()?;
                PyTuple::new(py, items)
            })
            .collect::<PyResult<Vec<_>>>()?;
        Ok((layouts, worlds))
    }

    fn __repr__(&self) -> String {
        format!(
            "<mjcf_forge.Superset key={} xml_bytes={}>",
            self.superset.structure_key,
            self.xml.len()
        )
    }
}

/// An entry's place in a patch's layout: object, id or name, field, and its width (how
/// many numbers; -1 for a string).
fn layout_entry(e: &PatchEntry) -> (&'static str, Option<usize>, String, &'static str, i64) {
    let width = match &e.value {
        PatchValue::Numbers(v) => v.len() as i64,
        _ => -1,
    };
    (e.object, e.id, e.name.clone(), e.field, width)
}
