//! `ModelStore`: the split tier's [`mjcf_forge::split::ModelStore`] (models by structure
//! key and plans by model, least recently used out past a count and about a number of
//! bytes: the one rule both faces' caches keep) over Python objects, for the package's
//! `ModelCache` (the user's `MjModel`s and their `PatchPlan`s) and `DocumentCache` (its
//! structures, each counting its own bytes).

use std::sync::Mutex;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyList;

use super::plan::PyPatchPlan;
use mjcf_forge::split::{self, Held};

/// A plan kept for a model: the model (held, so that its id stays its own) and the plan.
struct Kept {
    model: Py<PyAny>,
    plan: Py<PyPatchPlan>,
}

impl Held for Kept {
    fn nbytes(&self) -> usize {
        self.plan.get().nbytes()
    }
}

/// A Python object's id (its address, unique while it is held).
fn id_of(obj: &Py<PyAny>) -> u64 {
    obj.as_ptr() as usize as u64
}

/// Models by structure key and their patch plans by model, least recently used first,
/// bounded (``mjcf_forge::split::ModelStore``): at most ``max_models`` models and as many
/// plans of other models, and about ``max_bytes`` in all (the most recent model always
/// stays). With ``sized``, each model's own ``nbytes`` counts too.
///
/// >>> from mjcf_forge._mjcf_forge import ModelStore
/// >>> store = ModelStore(1, None)
/// >>> store.insert("a", "model a"); store.insert("b", "model b")
/// >>> store.trim()
/// ['a']
/// >>> store.get("b"), store.get("a"), len(store)
/// ('model b', None, 1)
#[pyclass(name = "ModelStore", module = "mjcf_forge._mjcf_forge", frozen)]
pub(crate) struct PyModelStore {
    inner: Mutex<split::ModelStore<Py<PyAny>, Kept>>,
    sized: bool,
}

impl PyModelStore {
    fn inner(&self) -> PyResult<std::sync::MutexGuard<'_, split::ModelStore<Py<PyAny>, Kept>>> {
        self.inner
            .try_lock()
            .map_err(|_| PyRuntimeError::new_err("this ModelStore is in use by another call"))
    }

    /// A model's own bytes (`sized`: its `nbytes`, read with the GIL held).
    fn model_bytes(&self, py: Python<'_>) -> impl Fn(&Py<PyAny>) -> usize {
        let sized = self.sized;
        move |m: &Py<PyAny>| {
            if !sized {
                return 0;
            }
            m.bind(py)
                .getattr("nbytes")
                .and_then(|n| n.extract::<usize>())
                .unwrap_or(0)
        }
    }
}

#[pymethods]
impl PyModelStore {
    #[new]
    #[pyo3(signature = (max_models, max_bytes, sized=false))]
    fn new(max_models: usize, max_bytes: Option<usize>, sized: bool) -> Self {
        PyModelStore {
            inner: Mutex::new(split::ModelStore::new(max_models, max_bytes)),
            sized,
        }
    }

    fn __len__(&self) -> PyResult<usize> {
        Ok(self.inner()?.len())
    }

    /// The model of structure ``key`` (which becomes the most recent), or ``None``.
    fn get(&self, py: Python<'_>, key: &str) -> PyResult<Option<Py<PyAny>>> {
        Ok(self.inner()?.touch(key).map(|m| m.clone_ref(py)))
    }

    /// Keeps ``model`` as the most recent, of structure ``key``.
    fn insert(&self, key: &str, model: Py<PyAny>) -> PyResult<()> {
        self.inner()?.insert(key, model);
        Ok(())
    }

    /// Takes the model of structure ``key`` out, with its plan; returns it, or ``None``.
    fn remove(&self, key: &str) -> PyResult<Option<Py<PyAny>>> {
        Ok(self.inner()?.remove(key, id_of))
    }

    /// The models, least recently used first.
    fn models(&self, py: Python<'_>) -> PyResult<Py<PyList>> {
        let inner = self.inner()?;
        let models = PyList::new(py, inner.models().map(|(_, m)| m.clone_ref(py)))?;
        Ok(models.unbind())
    }

    /// The plan of ``model`` (which becomes the most recent plan), or ``None``.
    fn plan(&self, py: Python<'_>, model: Py<PyAny>) -> PyResult<Option<Py<PyPatchPlan>>> {
        let mut inner = self.inner()?;
        Ok(inner
            .plan(id_of(&model))
            .filter(|k| k.model.is(&model))
            .map(|k| k.plan.clone_ref(py)))
    }

    /// Keeps ``plan`` as the most recent plan, of ``model``.
    fn add_plan(&self, model: Py<PyAny>, plan: Py<PyPatchPlan>) -> PyResult<()> {
        self.inner()?.add_plan(id_of(&model), Kept { model, plan });
        Ok(())
    }

    /// Drops the least recently used models (with their plans) and other models' plans
    /// beyond the bounds; returns the keys of the models dropped.
    fn trim(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        let bytes = self.model_bytes(py);
        Ok(self.inner()?.trim(id_of, bytes))
    }

    /// Bytes held: every plan's (its model and scratch data), and with ``sized`` every
    /// model's own ``nbytes``.
    #[getter]
    fn nbytes(&self, py: Python<'_>) -> PyResult<usize> {
        let bytes = self.model_bytes(py);
        Ok(self.inner()?.nbytes(bytes))
    }
}
