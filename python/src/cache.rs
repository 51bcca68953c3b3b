//! `CacheCore`: the split tier's model cache ([`mjcf_forge::split::CacheCore`], the rules
//! the C face's `ModelCache` runs too) over the user's `mujoco`: its `MjModel`s kept,
//! each patched by its `PatchPlan` (`split/plan.rs`), compiled by the package's
//! `compile_xml` (through `upcalls.rs`), a superset's worlds derived tree by tree
//! (`mjcf_forge::split::Derivations`). The package's `ModelCache` is its face: a variant's
//! path through `ModelCache.model` crosses into Rust once, and calls up only into the
//! user's `mujoco`.

use std::borrow::Cow;
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard, TryLockError};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyList};

use crate::document::patch::patch_entry;
use crate::errors::mjcf_error;
use crate::scene::{PySuperset, PyVariant};
use crate::split::{PyPatchPlan, signature_of};
use crate::{store, upcalls};
use mjcf_forge::split::DiskStore;
use mjcf_forge::split::{
    self, CacheBackend, CacheError, Held, PatchEntry, PatchFailure, Request, STATISTIC_NAMES,
    Signature, Statistics,
};
use mjcf_forge::{Document, ErrorKind};

/// The user's `mujoco` as the cache core runs it: whether a superset's patches derive
/// tree by tree where their layout allows (`mjcf_forge::split::Derivations`), and how many
/// did.
struct UserBackend {
    mujoco: Py<PyAny>,
    by_tree: bool,
    derived: u64,
}

/// A model's plan, kept by the core (the plan holds its model, so its id stays its own).
struct Kept(Py<PyPatchPlan>);

impl Held for Kept {
    fn nbytes(&self) -> usize {
        self.0.get().nbytes()
    }
}

impl CacheBackend for UserBackend {
    type Model = Py<PyAny>;
    type Plan = Kept;
    type Error = PyErr;

    fn id(model: &Py<PyAny>) -> u64 {
        model.as_ptr() as usize as u64
    }

    fn signature(&self, model: &Py<PyAny>) -> Option<Signature> {
        Some(Python::attach(|py| signature_of(model.bind(py))))
    }

    fn stat(&self, model: &Py<PyAny>) -> Statistics {
        Python::attach(|py| statistics_of(model.bind(py)))
    }

    fn plan(
        &mut self,
        model: &Py<PyAny>,
        key: &str,
        fixed: u32,
        values: Statistics,
    ) -> PyResult<Kept> {
        Python::attach(|py| {
            let plan = PyPatchPlan::create(
                py,
                self.mujoco.bind(py).clone(),
                model.bind(py).clone(),
                key.to_string(),
                fixed,
                values,
            )?;
            Ok(Kept(Py::new(py, plan)?))
        })
    }

    fn patch(
        &mut self,
        plan: &mut Kept,
        _model: &mut Py<PyAny>,
        request: &Request<'_>,
        _patches: u64,
    ) -> Result<(), PatchFailure<PyErr>> {
        let derived = plan
            .0
            .get()
            .patch(request.entries, request.parked, self.by_tree)?;
        self.derived += u64::from(derived);
        Ok(())
    }
}

/// `model.stat`'s numbers in `STATISTIC_NAMES`' order (zeros where one cannot be read).
pub(crate) fn statistics_of(model: &Bound<'_, PyAny>) -> Statistics {
    let mut out = [0.0; 7];
    let Ok(stat) = model.getattr("stat") else {
        return out;
    };
    for (k, name) in STATISTIC_NAMES[..4].iter().enumerate() {
        out[k] = stat.getattr(*name).and_then(|v| v.extract()).unwrap_or(0.0);
    }
    let center: Vec<f64> = stat
        .getattr("center")
        .and_then(|c| c.extract())
        .unwrap_or_default();
    if center.len() == 3 {
        out[4..].copy_from_slice(&center);
    }
    out
}

/// The core and its backend, one call at a time.
struct Inner {
    core: split::CacheCore<UserBackend>,
    backend: UserBackend,
}

/// The model cache's rules over the user's ``mujoco`` (``mjcf_forge::split::CacheCore``):
/// one compiled ``MjModel`` per structure, patched per variant by its ``PatchPlan``,
/// bounded (``max_models``, ``max_bytes``), least recently used out. ``fixed``: the
/// statistics the scene's ``<statistic>`` fixes; ``superset``: every variant a patch of
/// it, each world's derived values found tree by tree where its layout allows
/// (:attr:`derive_by_tree`). The package's :class:`mjcf_forge.ModelCache` is its face.
///
/// >>> import mujoco, mjcf_forge
/// >>> from mjcf_forge._mjcf_forge import CacheCore
/// >>> scene = mjcf_forge.Scene.demo()
/// >>> core = CacheCore(mujoco, 2, None, list(scene.fixed_statistics))
/// >>> model = core.model(scene.variant(0))
/// >>> core.model(scene.variant(0)) is model, core.compiles, core.patches
/// (True, 1, 1)
#[pyclass(name = "CacheCore", module = "mjcf_forge._mjcf_forge", frozen)]
pub(crate) struct PyCacheCore {
    inner: Mutex<Inner>,
    superset: Option<Py<PySuperset>>,
    fixed: u32,
    /// Where structures are kept across processes (never for a superset: its one model
    /// is the superset's own compile).
    store: Option<DiskStore>,
    /// Of the misses, the models loaded from the store.
    loads: AtomicU64,
}

impl PyCacheCore {
    fn inner(&self) -> PyResult<MutexGuard<'_, Inner>> {
        match self.inner.try_lock() {
            Ok(guard) => Ok(guard),
            Err(TryLockError::Poisoned(p)) => Ok(p.into_inner()),
            Err(TryLockError::WouldBlock) => Err(PyRuntimeError::new_err(
                "this model cache is in use by another call",
            )),
        }
    }

    /// What `variant` asks: its index, patch and (superset) parked roots, and the XML of
    /// its structure's compile.
    fn asked<'a>(&'a self, py: Python<'_>, variant: &'a Bound<'_, PyAny>) -> PyResult<Asked<'a>> {
        if let Some(sup) = &self.superset {
            let sup = sup.get();
            let index: u64 = variant.getattr("index")?.extract()?;
            let (patch, parked) = py
                .detach(|| {
                    let patch = sup.scene.superset_patch(&sup.superset, index)?;
                    let parked = sup.scene.superset_parked(&sup.superset, index)?;
                    Ok::<_, mjcf_forge::Errors>((patch, parked))
                })
                .map_err(|e| mjcf_error(e.0.iter().map(ToString::to_string).collect()))?;
            return Ok(Asked {
                index,
                key: Cow::Owned(patch.structure_key),
                entries: Cow::Owned(patch.entries),
                parked: Some(parked),
                xml: Cow::Borrowed(&sup.xml),
            });
        }
        if let Ok(v) = variant.cast::<PyVariant>() {
            let v = v.get();
            let patch = v.drawn(py)?;
            return Ok(Asked {
                index: v.index(),
                key: Cow::Borrowed(&patch.structure_key),
                entries: Cow::Borrowed(&patch.entries),
                parked: None,
                xml: Cow::Borrowed(v.text()),
            });
        }
        // Code that stands for a variant: its key, patch tuples and XML.
        let mut entries = Vec::new();
        for e in variant.getattr("patch")?.try_iter()? {
            let (object, name, field, value): (String, Bound<'_, PyAny>, String, Bound<'_, PyAny>) =
                e?.extract()?;
            entries.push(patch_entry(object, &name, field, &value)?);
        }
        Ok(Asked {
            index: variant.getattr("index")?.extract()?,
            key: Cow::Owned(variant.getattr("structure_key")?.extract()?),
            entries: Cow::Owned(entries),
            parked: None,
            xml: Cow::Owned(variant.getattr("xml")?.extract()?),
        })
    }
}

impl PyCacheCore {
    /// The superset plan of `model`, made on first sight, under the lock held (`inner`).
    fn plan_in(
        &self,
        py: Python<'_>,
        inner: &mut Inner,
        model: &Py<PyAny>,
    ) -> PyResult<Py<PyPatchPlan>> {
        let Some(sup) = &self.superset else {
            return Err(mjcf_error(vec![ErrorKind::NeedsSuperset.to_string()]));
        };
        let sup = sup.get();
        let asked = Asked {
            index: 0,
            key: Cow::Borrowed(&sup.superset.structure_key),
            entries: Cow::Borrowed(&[]),
            parked: None,
            xml: Cow::Borrowed(&sup.xml),
        };
        let Inner { core, backend } = inner;
        let mujoco = backend.mujoco.clone_ref(py);
        let request = asked.request(self.fixed);
        let loaded = Cell::new(false);
        match core.plan_for(
            backend,
            &request,
            model,
            asked.compile(&mujoco, None, &loaded),
        ) {
            Ok(plan) => Ok(plan.0.clone_ref(py)),
            Err(e) => Err(asked.error(e)),
        }
    }
}

/// What a variant asks of the cache (see `PyCacheCore::asked`).
struct Asked<'a> {
    index: u64,
    key: Cow<'a, str>,
    entries: Cow<'a, [PatchEntry]>,
    parked: Option<Vec<String>>,
    xml: Cow<'a, str>,
}

impl Asked<'_> {
    fn request(&self, fixed: u32) -> Request<'_> {
        Request {
            key: &self.key,
            entries: &self.entries,
            parked: self.parked.as_deref(),
            fixed,
        }
    }

    /// The compile of the variant's structure with the user's `mujoco`; with a `store`,
    /// its first call loads the structure's model from there when another process
    /// stored it (`loaded` says so: that model is another variant's compile, to be
    /// patched), and stores what it compiles.
    fn compile<'a>(
        &'a self,
        mujoco: &'a Py<PyAny>,
        mut store: Option<&'a DiskStore>,
        loaded: &'a Cell<bool>,
    ) -> impl FnMut() -> PyResult<Py<PyAny>> + 'a {
        move || {
            Python::attach(|py| {
                let compile = || {
                    let model =
                        upcalls::get(py, "compile_xml")?.call1((mujoco.bind(py), &*self.xml))?;
                    Ok(model.unbind())
                };
                // Relative file names resolve as MuJoCo resolves them in a string's model.
                let doc = store
                    .take()
                    .zip(std::env::current_dir().ok())
                    .and_then(|(s, dir)| Some((s, Document::from_str(&self.xml, &dir).ok()?)));
                let Some((store, doc)) = doc else {
                    return compile();
                };
                let key = store::key(py, &doc, &self.key, mujoco)?;
                let (model, stored) = store::load_or(py, store, &key, mujoco, compile)?;
                loaded.set(stored);
                Ok(model)
            })
        }
    }

    /// The core's error as Python's.
    fn error(&self, e: CacheError<PyErr>) -> PyErr {
        match e {
            CacheError::Backend(e) => e,
            CacheError::OtherStructure { found } => mjcf_error(vec![
                ErrorKind::OtherStructure {
                    variant: self.index,
                    key: self.key.to_string(),
                    found,
                }
                .to_string(),
            ]),
            CacheError::NotThisStructure(m) => mjcf_error(vec![m]),
        }
    }
}

#[pymethods]
impl PyCacheCore {
    #[new]
    #[pyo3(signature = (mujoco, max_models, max_bytes, fixed, superset=None, store=None))]
    fn new(
        py: Python<'_>,
        mujoco: Py<PyAny>,
        max_models: usize,
        max_bytes: Option<usize>,
        fixed: Vec<String>,
        superset: Option<Py<PySuperset>>,
        store: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let core = split::CacheCore::new(max_models, max_bytes, superset.is_some());
        let store = match &superset {
            Some(_) => None,
            None => store::open(py, store, &mujoco)?,
        };
        Ok(PyCacheCore {
            inner: Mutex::new(Inner {
                core,
                backend: UserBackend {
                    mujoco,
                    by_tree: true,
                    derived: 0,
                },
            }),
            superset,
            fixed: split::fixed_statistics_mask(fixed.iter().map(String::as_str)),
            store,
            loads: AtomicU64::new(0),
        })
    }

    /// The model of ``variant`` (see ``ModelCache.model``).
    fn model(&self, py: Python<'_>, variant: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        let asked = self.asked(py, variant)?;
        let mut inner = self.inner()?;
        let Inner { core, backend } = &mut *inner;
        let mujoco = backend.mujoco.clone_ref(py);
        let request = asked.request(self.fixed);
        let loaded = Cell::new(false);
        let compile = asked.compile(&mujoco, self.store.as_ref(), &loaded);
        let model = match core.model(backend, &request, compile) {
            Ok(model) => model.clone_ref(py),
            Err(e) => return Err(asked.error(e)),
        };
        if !loaded.get() {
            return Ok(model);
        }
        // Another variant's compile, from the store: now a hit, patched into this one.
        self.loads.fetch_add(1, Ordering::Relaxed);
        match core.model(backend, &request, asked.compile(&mujoco, None, &loaded)) {
            Ok(model) => Ok(model.clone_ref(py)),
            Err(e) => Err(asked.error(e)),
        }
    }

    /// ``model`` patched in place into ``variant``'s (see ``ModelCache.apply``).
    fn apply(
        &self,
        py: Python<'_>,
        variant: &Bound<'_, PyAny>,
        model: Py<PyAny>,
    ) -> PyResult<Py<PyAny>> {
        let asked = self.asked(py, variant)?;
        let mut inner = self.inner()?;
        let Inner { core, backend } = &mut *inner;
        let mujoco = backend.mujoco.clone_ref(py);
        let mut target = model.clone_ref(py);
        // The structure's first sight may load its model from the store: kept, and
        // patched before it is given out, as every cached model is.
        let loaded = Cell::new(false);
        core.apply(
            backend,
            &asked.request(self.fixed),
            &mut target,
            asked.compile(&mujoco, self.store.as_ref(), &loaded),
        )
        .map_err(|e| asked.error(e))?;
        if loaded.get() {
            self.loads.fetch_add(1, Ordering::Relaxed);
        }
        Ok(model)
    }

    /// Superset: the plan of ``model`` (a copy of the superset model, not checked), made
    /// on first sight (:meth:`apply_world` patches through it).
    pub(crate) fn plan_for(&self, py: Python<'_>, model: Py<PyAny>) -> PyResult<Py<PyPatchPlan>> {
        self.plan_in(py, &mut *self.inner()?, &model)
    }

    /// Superset: ``model`` (a copy of the superset model) patched in place for one world
    /// of ``Superset.worlds`` (``world``: its index, numbers, strings and parked roots;
    /// ``patch0``: a patch of its layout), as :meth:`apply` patches a variant.
    fn apply_world(
        &self,
        py: Python<'_>,
        model: Py<PyAny>,
        world: (u64, Bound<'_, PyBytes>, Vec<String>, Vec<String>),
        patch0: Bound<'_, PyAny>,
    ) -> PyResult<Py<PyAny>> {
        let (_index, numbers, strings, parked) = world;
        // One lock for the world: the plan, its patch, the counts.
        let mut inner = self.inner()?;
        let plan = self.plan_in(py, &mut inner, &model)?;
        let by_tree = inner.backend.by_tree;
        let derived =
            plan.get()
                .patch_world(&patch0, numbers.as_bytes(), strings, &parked, by_tree)?;
        inner.core.count_patch();
        inner.backend.derived += u64::from(derived);
        Ok(model)
    }

    /// Superset: whether patches derive what ``mj_setConst`` would tree by tree, where
    /// their layout allows (the same bits; ``False``: ``mj_setConst`` always).
    #[getter]
    fn get_derive_by_tree(&self) -> PyResult<bool> {
        Ok(self.inner()?.backend.by_tree)
    }

    #[setter]
    fn set_derive_by_tree(&self, value: bool) -> PyResult<()> {
        self.inner()?.backend.by_tree = value;
        Ok(())
    }

    /// Superset patches derived tree by tree so far.
    #[getter]
    fn by_tree(&self) -> PyResult<u64> {
        Ok(self.inner()?.backend.derived)
    }

    /// The plan kept for ``model``, or ``None``.
    fn plan(&self, py: Python<'_>, model: Py<PyAny>) -> PyResult<Option<Py<PyPatchPlan>>> {
        let inner = self.inner()?;
        Ok(inner
            .core
            .plan_of(&model)
            .filter(|k| k.0.get().model().is(&model))
            .map(|k| k.0.clone_ref(py)))
    }

    /// The models, least recently used first.
    fn models(&self, py: Python<'_>) -> PyResult<Py<PyList>> {
        let inner = self.inner()?;
        Ok(PyList::new(py, inner.core.models().map(|m| m.clone_ref(py)))?.unbind())
    }

    /// Of the misses, the models loaded from the store (another process compiled them).
    #[getter]
    fn loads(&self) -> u64 {
        self.loads.load(Ordering::Relaxed)
    }

    /// The folder structures are kept in across processes, or ``None``.
    #[getter]
    fn store(&self) -> Option<std::path::PathBuf> {
        self.store.as_ref().map(|s| s.dir().to_path_buf())
    }

    /// Models compiled so far (misses).
    #[getter]
    fn compiles(&self) -> PyResult<u64> {
        Ok(self.inner()?.core.compiles())
    }

    /// Patches applied so far.
    #[getter]
    fn patches(&self) -> PyResult<u64> {
        Ok(self.inner()?.core.patches())
    }

    /// Bytes held: every model and its scratch data.
    #[getter]
    fn nbytes(&self) -> PyResult<usize> {
        Ok(self.inner()?.core.nbytes())
    }

    fn __len__(&self) -> PyResult<usize> {
        Ok(self.inner()?.core.len())
    }

    fn __repr__(&self) -> PyResult<String> {
        let inner = self.inner()?;
        Ok(format!(
            "CacheCore({} models, {} compiles, {} patches)",
            inner.core.len(),
            inner.core.compiles(),
            inner.core.patches()
        ))
    }
}
