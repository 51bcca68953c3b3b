//! `Superset`: one model for every variant of a scene (see `mjcf_forge::scene::Superset`).

use std::sync::Arc;

use mjcf_forge::scene::{Scene, Superset};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

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

    fn __repr__(&self) -> String {
        format!(
            "<mjcf_forge.Superset key={} xml_bytes={}>",
            self.superset.structure_key,
            self.xml.len()
        )
    }
}
