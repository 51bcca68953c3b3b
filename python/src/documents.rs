//! `DocumentCore`: the split tier's document cache ([`mjcf_forge::split::DocumentCore`],
//! the rules the C face's `DocumentCache` runs too) over the user's `mujoco`: its
//! `MjModel`s given out per thread, each patched by its `PatchPlan` after the structure's
//! snapshot is written back (`split/snapshot.rs`), held while anyone but the cache holds
//! it (CPython's reference count), compiled by the package's `compile_xml` outside the
//! cache's lock (two threads compile two structures at once; a second asker for one
//! structure waits for the first). The package's `DocumentCache` is its face: a
//! document's path through `DocumentCache.model` crosses into Rust once.

use std::sync::{Condvar, Mutex, MutexGuard};

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::sync::MutexExt;
use pyo3::types::{PyList, PyTuple};

use crate::cache::statistics_of;
use crate::document::PyDocument;
use crate::errors::{mjcf_error, run};
use crate::split::{PyPatchPlan, Snapshot, Views, references};
use crate::{store, upcalls};
use mjcf_forge::split::{
    self, CacheError, Compiled, DiskStore, DocumentBackend, Held, PatchEntry, PatchFailure,
    Request, SplitOptions, Step, split_document_with,
};

/// The user's `mujoco` as the document core runs it.
struct UserDocs {
    mujoco: Py<PyAny>,
}

/// One model the cache gave out: its plan, its views of what the snapshot writes back,
/// and the references the cache itself holds to it (counted once it was made).
struct Working {
    model: Py<PyAny>,
    plan: Py<PyPatchPlan>,
    views: Views,
    own: isize,
}

impl Held for Working {
    fn nbytes(&self) -> usize {
        self.plan.get().nbytes()
    }
}

impl DocumentBackend for UserDocs {
    type Model = Py<PyAny>;
    type Working = Working;
    type Snapshot = Snapshot;
    type Error = PyErr;

    fn id(model: &Py<PyAny>) -> u64 {
        model.as_ptr() as usize as u64
    }

    fn model(working: &Working) -> &Py<PyAny> {
        &working.model
    }

    fn snapshot(&mut self, model: &Py<PyAny>) -> PyResult<Snapshot> {
        Python::attach(|py| {
            let model = model.bind(py);
            Snapshot::of(self.mujoco.bind(py), model, statistics_of(model))
        })
    }

    fn working(
        &mut self,
        model: Py<PyAny>,
        snapshot: &Snapshot,
        request: &Request<'_>,
    ) -> Result<Working, (Py<PyAny>, PatchFailure<PyErr>)> {
        Python::attach(|py| {
            let made = (|| {
                let bound = model.bind(py);
                let views = snapshot.views(bound)?;
                // The plan reads the model as compiled (a copy of another model may hold
                // its patch).
                views.restore(py, snapshot)?;
                let plan = PyPatchPlan::create(
                    py,
                    self.mujoco.bind(py).clone(),
                    bound.clone(),
                    request.key.to_string(),
                    request.fixed,
                    snapshot.stat,
                )?;
                Ok::<_, PyErr>((views, Py::new(py, plan)?))
            })();
            let (views, plan) = match made {
                Ok(made) => made,
                Err(e) => return Err((model, PatchFailure::Backend(e))),
            };
            if let Err(e) = plan.get().resolve_entries(request.entries) {
                return Err((model, e));
            }
            // Every reference the cache holds is made: the model, its plan's, its views'.
            let own = references(&model);
            Ok(Working {
                model,
                plan,
                views,
                own,
            })
        })
    }

    fn held(&self, working: &Working) -> bool {
        Python::attach(|_| references(&working.model) > working.own)
    }

    fn copy(&mut self, working: &Working) -> PyResult<Py<PyAny>> {
        Python::attach(|py| {
            let copied = upcalls::python(py, "copy", "copy")?.call1((working.model.bind(py),))?;
            Ok(copied.unbind())
        })
    }

    fn patch(
        &mut self,
        working: &mut Working,
        snapshot: &Snapshot,
        request: &Request<'_>,
    ) -> Result<(), PatchFailure<PyErr>> {
        Python::attach(|py| working.views.restore(py, snapshot)).map_err(PatchFailure::Backend)?;
        working.plan.get().patch(request.entries, None, false)?;
        Ok(())
    }
}

/// The core and its backend, under the cache's lock.
struct Inner {
    core: split::DocumentCore<UserDocs>,
    backend: UserDocs,
}

/// The document cache's rules over the user's ``mujoco``
/// (``mjcf_forge::split::DocumentCore``): per structure the models given out, per thread,
/// each patched per document after the structure's values as compiled are written back;
/// bounded (``max_models`` structures, ``max_bytes``), least recently used out. The
/// package's :class:`mjcf_forge.DocumentCache` is its face.
///
/// >>> import mujoco, mjcf_forge
/// >>> from mjcf_forge._mjcf_forge import DocumentCore
/// >>> core = DocumentCore(mujoco, 4, None, False)  # no store across processes
/// >>> xml = "<mujoco><worldbody><geom name='g' size='.1' rgba='{}'/></worldbody></mujoco>"
/// >>> red = core.model(mjcf_forge.Document.from_string(xml.format("1 0 0 1")))
/// >>> del red
/// >>> blue = core.model(mjcf_forge.Document.from_string(xml.format("0 0 1 1")))
/// >>> blue.geom("g").rgba.tolist(), core.compiles, core.patches
/// ([0.0, 0.0, 1.0, 1.0], 1, 1)
#[pyclass(name = "DocumentCore", module = "mjcf_forge._mjcf_forge", frozen)]
pub(crate) struct PyDocumentCore {
    inner: Mutex<Inner>,
    /// Where compiled structures are kept across processes, if anywhere.
    store: Option<DiskStore>,
    /// Signalled when a compile ends (its waiters ask again).
    compiled: Condvar,
}

impl PyDocumentCore {
    fn inner(&self, py: Python<'_>) -> MutexGuard<'_, Inner> {
        self.inner
            .lock_py_attached(py)
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// `doc` compiled by the user's `mujoco` (as `to_xml(pretty=True)` writes it); MuJoCo's
    /// refusal at the element it names in the document's sources.
    fn compile(&self, py: Python<'_>, doc: &PyDocument, mujoco: &Py<PyAny>) -> PyResult<Py<PyAny>> {
        let xml = run(py, || Ok(doc.doc.read_detached().to_pretty_string()))?;
        match upcalls::get(py, "compile_xml")?.call1((mujoco.bind(py), &xml)) {
            Ok(model) => Ok(model.unbind()),
            Err(e) if e.is_instance_of::<PyValueError>(py) => {
                let message = e.value(py).str()?.to_cow()?.into_owned();
                let at = doc.doc.read(py).mujoco_error(&xml, &message).to_string();
                Err(mjcf_error(vec![at]))
            }
            Err(e) => Err(e),
        }
    }
}

/// The core's error as Python's.
fn error(e: CacheError<PyErr>) -> PyErr {
    match e {
        CacheError::Backend(e) => e,
        CacheError::OtherStructure { .. } => {
            mjcf_error(vec!["a model of another structure".into()])
        }
        CacheError::NotThisStructure(m) => mjcf_error(vec![m]),
    }
}

/// The ids of the models `into` names (one, or a list or tuple of them).
fn ids(into: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<u64>> {
    let Some(into) = into.filter(|i| !i.is_none()) else {
        return Ok(Vec::new());
    };
    if into.is_instance_of::<PyList>() || into.is_instance_of::<PyTuple>() {
        return into
            .try_iter()?
            .map(|m| Ok(UserDocs::id(&m?.unbind())))
            .collect();
    }
    Ok(vec![UserDocs::id(&into.clone().unbind())])
}

#[pymethods]
impl PyDocumentCore {
    #[new]
    #[pyo3(signature = (mujoco, max_models, max_bytes, store=None))]
    fn new(
        py: Python<'_>,
        mujoco: Py<PyAny>,
        max_models: usize,
        max_bytes: Option<usize>,
        store: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let store = store::open(py, store, &mujoco)?;
        Ok(PyDocumentCore {
            inner: Mutex::new(Inner {
                core: split::DocumentCore::new(max_models, max_bytes),
                backend: UserDocs { mujoco },
            }),
            store,
            compiled: Condvar::new(),
        })
    }

    /// The folder compiled structures are kept in across processes, or ``None``.
    #[getter]
    fn store(&self) -> Option<std::path::PathBuf> {
        self.store.as_ref().map(|s| s.dir().to_path_buf())
    }

    /// Of the misses, the models loaded from the store.
    #[getter]
    fn loads(&self, py: Python<'_>) -> u64 {
        self.inner(py).core.loads()
    }

    /// The model MuJoCo compiles from ``doc`` (see ``DocumentCache.model``); ``into``: a
    /// model, or a list of models, handed back to be patched itself.
    #[pyo3(signature = (doc, into=None))]
    fn model(
        &self,
        py: Python<'_>,
        doc: &Bound<'_, PyDocument>,
        into: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Py<PyAny>> {
        let doc = doc.get();
        let split = run(py, || {
            Ok(split_document_with(
                &doc.doc.read_detached(),
                SplitOptions { body_models: true },
            ))
        })?;
        let entries: &[PatchEntry] = &split.entries;
        let request = Request {
            key: &split.structure_key,
            entries,
            parked: None,
            fixed: split::fixed_statistics_mask(split.fixed_statistics.iter().copied()),
        };
        let into = ids(into)?;
        let mut use_store = true;
        loop {
            let (step, mujoco) = {
                let mut inner = self.inner(py);
                let Inner { core, backend } = &mut *inner;
                match core.model(backend, &request, &into).map_err(error)? {
                    Step::Ready => {
                        let given = core.given().map(|m| m.clone_ref(py));
                        return given.ok_or_else(|| mjcf_error(vec!["no model given".into()]));
                    }
                    step => (step, backend.mujoco.clone_ref(py)),
                }
            };
            let replace = match step {
                Step::Compile { replace } => replace,
                _ => {
                    // Another thread compiles the structure: wait for it, then ask again
                    // (its model, copied, is ours).
                    py.detach(|| {
                        let inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
                        let _done = self
                            .compiled
                            .wait_while(inner, |i| i.core.compiling(request.key))
                            .unwrap_or_else(|p| p.into_inner());
                    });
                    continue;
                }
            };
            // A failed patch compiles the document itself: the store's model is what failed.
            let store = self.store.as_ref().filter(|_| use_store && !replace);
            let (compiled, stored) = match store {
                Some(store) => {
                    let key = {
                        let read = doc.doc.read(py);
                        store::key(py, &read, request.key, &mujoco)?
                    };
                    match store::load_or(py, store, &key, &mujoco, || {
                        self.compile(py, doc, &mujoco)
                    }) {
                        Ok((m, stored)) => (Ok(m), stored),
                        Err(e) => (Err(e), false),
                    }
                }
                None => (self.compile(py, doc, &mujoco), false),
            };
            let mut inner = self.inner(py);
            let Inner { core, backend } = &mut *inner;
            let kept = core.compiled(backend, &request, compiled, replace, stored);
            let given = core.given().map(|m| m.clone_ref(py));
            drop(inner);
            if !replace {
                self.compiled.notify_all();
            }
            match kept.map_err(error)? {
                Compiled::Alone(alone) => return Ok(alone),
                Compiled::Kept => {
                    return given.ok_or_else(|| mjcf_error(vec!["no model given".into()]));
                }
                Compiled::Stored => {}
                Compiled::Refused => use_store = false,
            }
        }
    }

    /// How many models the calling thread's pool of ``doc``'s structure holds.
    fn pool_len(&self, py: Python<'_>, doc: &Bound<'_, PyDocument>) -> PyResult<usize> {
        let doc = doc.get();
        let key = run(py, || {
            Ok(
                split_document_with(&doc.doc.read_detached(), SplitOptions { body_models: true })
                    .structure_key,
            )
        })?;
        Ok(self.inner(py).core.pool_len(&key))
    }

    /// Models compiled so far (misses).
    #[getter]
    fn compiles(&self, py: Python<'_>) -> u64 {
        self.inner(py).core.compiles()
    }

    /// Patches applied so far (hits).
    #[getter]
    fn patches(&self, py: Python<'_>) -> u64 {
        self.inner(py).core.patches()
    }

    /// Bytes held: every model, its scratch ``MjData`` and its structure's snapshot.
    #[getter]
    fn nbytes(&self, py: Python<'_>) -> usize {
        self.inner(py).core.nbytes()
    }

    fn __len__(&self, py: Python<'_>) -> usize {
        self.inner(py).core.len()
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let inner = self.inner(py);
        format!(
            "DocumentCore({} structures, {} compiles, {} patches)",
            inner.core.len(),
            inner.core.compiles(),
            inner.core.patches()
        )
    }
}
