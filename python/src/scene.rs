//! `Scene`, `Variant` and the variant stream: the batch tier.
//!
//! A `Scene` is an `Arc` of the library's `Scene` (`Send + Sync`), so Python threads share
//! one and every call releases the GIL. `Scene.variants` runs a producer thread that makes
//! variants on a rayon pool into a ring of `window` slots
//! (`mjcf_forge::output::for_each_ordered`: no worker waits for another) and hands them
//! over in order, in batches of half a window through a channel of one batch, so memory
//! stays bounded however many indices are asked for. Batches, because a hand-over per
//! variant cost a wake-up of the Python thread and a release of the GIL each: two futex
//! calls and about one context switch per variant.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::sync::{Arc, Mutex, OnceLock};

use mjcf_forge::Document;
use mjcf_forge::scene::{PatchEntry, PatchValue, Scene, VariantPatch};
use pyo3::exceptions::{PyImportError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::document::PyDocument;
use crate::errors::{Failure, catch, run};

/// A randomized scene description, loaded once: every model file read once and the part
/// that never changes assembled once. ``scene.variant(i)`` is variant ``i``; all of its
/// randomness comes from ``(seed, i)``, so it is the same bytes in any process, on any
/// thread, in any order.
///
/// Build one with :meth:`Scene.load` (a TOML scene file, or the built-in demo scene) or
/// :meth:`Scene.from_dict` (the same description as a Python ``dict``). Safe to share
/// between threads; every call releases the GIL. A scene pickles as its description (Ray
/// tasks and multiprocessing workers load it again from the same model files).
///
/// Example::
///
///     scene = Scene.load("lift5.toml")
///     v = scene.variant(12)
///     v.xml             # the MJCF text, assets referenced by absolute path
///     v.params          # {'objects': [...], 'randomized': [...]}
///     model = v.compile()   # mujoco.MjModel
///     for v in scene.variants(range(10_000), threads=2):
///         ...
#[pyclass(name = "Scene", module = "mjcf_forge", frozen)]
pub(crate) struct PyScene {
    scene: Arc<Scene>,
    /// Where the scene came from, so that pickling (Ray, multiprocessing) can load it again
    /// on the other side instead of shipping every model.
    source: Source,
}

/// What a scene was loaded from (its pickled form).
#[derive(Clone)]
enum Source {
    Demo,
    File(PathBuf),
    Toml(String, PathBuf),
    Json(String, PathBuf),
}

impl PyScene {
    fn new(scene: Scene, source: Source) -> PyScene {
        PyScene {
            scene: Arc::new(scene),
            source,
        }
    }
}

/// What a worker makes for one index: the variant's text forms, so that the Python side
/// only wraps them. The XML comes from the library's fastest path (`variant_xml`: the
/// template's text with the variant's values spliced in, where the scene allows); the
/// document is only built if Python asks for it.
struct Made {
    index: u64,
    xml: String,
    params_json: String,
    objects: usize,
}

fn make(scene: &Scene, index: u64) -> Result<Made, Failure> {
    catch(|| {
        let (xml, params) = scene.variant_xml(index)?;
        Ok(Made {
            index,
            params_json: params.to_json(index, None),
            objects: params.objects.len(),
            xml,
        })
    })
}

#[pymethods]
impl PyScene {
    /// Loads a TOML scene file (paths in it are relative to it); without ``path``, the
    /// built-in demo scene (our own models, no file needed).
    #[staticmethod]
    #[pyo3(signature = (path = None))]
    fn load(py: Python<'_>, path: Option<PathBuf>) -> PyResult<PyScene> {
        let source = match &path {
            Some(p) => Source::File(absolute(p.clone())),
            None => Source::Demo,
        };
        let scene = run(py, || {
            Ok(match &path {
                Some(path) => Scene::load(path)?,
                None => Scene::demo()?,
            })
        })?;
        Ok(PyScene::new(scene, source))
    }

    /// The built-in demo scene (the same as ``Scene.load()``).
    #[staticmethod]
    fn demo(py: Python<'_>) -> PyResult<PyScene> {
        Self::load(py, None)
    }

    /// A scene from TOML text; model paths are relative to ``base_dir`` (default: the
    /// current folder).
    #[staticmethod]
    #[pyo3(signature = (text, base_dir = None))]
    fn from_toml(py: Python<'_>, text: &str, base_dir: Option<PathBuf>) -> PyResult<PyScene> {
        let text = text.to_owned();
        let base_dir = base_dir.unwrap_or_else(|| PathBuf::from("."));
        let scene = run(py, || Ok(Scene::from_toml_str(&text, &base_dir)?))?;
        Ok(PyScene::new(scene, Source::Toml(text, absolute(base_dir))))
    }

    /// A scene from a ``dict`` with the keys of the TOML scene file (``seed``, ``base``,
    /// ``fixture``, ``objects``, ``randomize``); model paths are relative to ``base_dir``
    /// (default: the current folder). Lets Python code build or tweak a description, e.g. one read with ``tomllib`` and
    /// given another seed or pool.
    #[staticmethod]
    #[pyo3(signature = (description, base_dir = None))]
    fn from_dict(
        py: Python<'_>,
        description: &Bound<'_, PyDict>,
        base_dir: Option<PathBuf>,
    ) -> PyResult<PyScene> {
        let base_dir = base_dir.unwrap_or_else(|| PathBuf::from("."));
        let json: String = py
            .import("json")?
            .getattr("dumps")?
            .call1((description,))
            .map_err(|e| {
                PyValueError::new_err(format!("the scene description is not JSON data: {e}"))
            })?
            .extract()?;
        let scene = run(py, || Ok(Scene::from_json_str(&json, &base_dir)?))?;
        Ok(PyScene::new(scene, Source::Json(json, absolute(base_dir))))
    }

    /// The seed: variant ``i`` draws every random number from ``(seed, i)``.
    #[getter]
    fn seed(&self) -> u64 {
        self.scene.seed()
    }

    /// The scene file this scene was read from (a label for the demo and for text).
    #[getter]
    fn file(&self) -> PathBuf {
        self.scene.file().to_path_buf()
    }

    /// The model files the scene uses, absolute (empty for the built-in demo).
    #[getter]
    fn model_files(&self) -> Vec<PathBuf> {
        self.scene.model_files().to_vec()
    }

    /// The ``<statistic>`` attributes the scene's model sets itself (``extent``,
    /// ``center``...), which MuJoCo keeps over what it computes: a patched model keeps
    /// them too.
    #[getter]
    fn fixed_statistics(&self) -> Vec<&'static str> {
        self.scene.fixed_statistics()
    }

    /// The scene's :class:`Superset`: one model holding every object any slot can hold,
    /// of which every variant is a patch.
    fn superset(&self, py: Python<'_>) -> PyResult<crate::superset::PySuperset> {
        let scene = Arc::clone(&self.scene);
        let (superset, xml) = run(py, move || {
            let s = scene.superset()?;
            let xml = s.document.to_xml_string();
            Ok((s, xml))
        })?;
        Ok(crate::superset::PySuperset {
            scene: Arc::clone(&self.scene),
            superset,
            xml,
        })
    }

    /// A copy of the template every variant starts from: the base with the fixtures.
    #[getter]
    fn template(&self, py: Python<'_>) -> PyResult<PyDocument> {
        run(py, || Ok(self.scene.template().clone())).map(PyDocument::new)
    }

    /// Variant ``index`` (made with the GIL released). Raises :class:`MjcfError` when it
    /// cannot be made, e.g. a group whose objects find no place (the message names the
    /// group, the region and the index).
    fn variant(&self, py: Python<'_>, index: u64) -> PyResult<PyVariant> {
        run(py, || make(&self.scene, index))
            .map(|made| PyVariant::new(made, Origin::Scene(self.scene.clone())))
    }

    /// Variants for ``indices`` (a ``range`` or any iterable of ints), made on
    /// ``threads`` Rust threads (default: one per core) with the GIL released, yielded in
    /// the order of ``indices``. Memory stays bounded: at most ``window`` variants (default
    /// ``8 * threads``, at least 16) are made ahead of the next one handed over, and they
    /// are handed over in batches of half a window, at most about three batches waiting
    /// to be taken. The bytes of each variant do not depend on ``threads`` or ``window``.
    ///
    /// A variant that cannot be made raises :class:`MjcfError` when its turn comes, and
    /// ends the iteration.
    #[pyo3(signature = (indices, threads = None, window = None))]
    fn variants(
        &self,
        indices: &Bound<'_, PyAny>,
        threads: Option<usize>,
        window: Option<usize>,
    ) -> PyResult<PyVariantIter> {
        let indices: Vec<u64> = indices
            .try_iter()?
            .map(|i| i.and_then(|i| i.extract::<u64>()))
            .collect::<PyResult<_>>()?;
        if threads == Some(0) || window == Some(0) {
            return Err(PyValueError::new_err(
                "threads and window must be at least 1",
            ));
        }
        let pool = match threads {
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .thread_name(|i| format!("mjcf-forge-variants-{i}"))
                    .build()
                    .map_err(|e| Failure(vec![format!("cannot start {n} threads: {e}")]))?,
            ),
            None => None,
        };
        let workers = threads.unwrap_or_else(rayon::current_num_threads);
        let window = window.unwrap_or((8 * workers).max(16));
        let batch = (window / 2).max(1);
        let (tx, rx) = sync_channel(1);
        let scene = self.scene.clone();
        std::thread::Builder::new()
            .name("mjcf-forge-variants".into())
            .spawn(move || produce(scene, indices, pool, window, batch, tx))
            .map_err(|e| Failure(vec![format!("cannot start the producer thread: {e}")]))?;
        Ok(PyVariantIter {
            taken: Mutex::new(Taken {
                rx: Some(rx),
                batch: VecDeque::new(),
            }),
            scene: self.scene.clone(),
        })
    }

    /// Seconds spent in Rust making ``indices`` one at a time on this thread (variant, XML
    /// and parameters, exactly what :meth:`variant` makes) without making any Python
    /// object: the baseline against which the benchmarks measure the cost of crossing
    /// into Python per variant. Not part of the API.
    fn _rust_seconds(&self, py: Python<'_>, indices: Vec<u64>) -> PyResult<f64> {
        run(py, || {
            let start = std::time::Instant::now();
            for &i in &indices {
                // Dropped at once, as a Python caller drops a variant it has read.
                std::hint::black_box(make(&self.scene, i)?);
            }
            Ok(start.elapsed().as_secs_f64())
        })
    }

    /// Pickling (Ray, multiprocessing) ships the description, not the models: the copy
    /// loads the same file, text or dict again (so the other side needs the model files
    /// at the same paths, as a cluster with shared storage has them).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let cls = py.get_type::<PyScene>();
        let (make, args) = match &self.source {
            Source::Demo => (cls.getattr("load")?, PyTuple::empty(py)),
            Source::File(path) => (cls.getattr("load")?, (path,).into_pyobject(py)?),
            Source::Toml(text, dir) => (cls.getattr("from_toml")?, (text, dir).into_pyobject(py)?),
            Source::Json(json, dir) => {
                let dict = py.import("json")?.getattr("loads")?.call1((json,))?;
                (cls.getattr("from_dict")?, (dict, dir).into_pyobject(py)?)
            }
        };
        PyTuple::new(py, [make, args.into_any()])
    }

    fn __repr__(&self) -> String {
        format!(
            "<mjcf_forge.Scene file={:?} seed={}>",
            self.scene.file().display().to_string(),
            self.scene.seed()
        )
    }
}

/// A path made absolute for the pickled form, so that a copy loaded in another process
/// (another current folder) finds the same files. Messages keep the path as given.
fn absolute(path: PathBuf) -> PathBuf {
    std::path::absolute(&path).unwrap_or(path)
}

/// What a batch of the variant stream holds: made variants in order, a failure last.
type Batch = Vec<Result<Made, Failure>>;

/// The producer: variants made in parallel into a ring of `window`, sent in order in
/// batches of `batch` (the last one shorter); stops when the receiver is gone (the Python
/// iterator was dropped) or after the first failure, which ends its batch.
fn produce(
    scene: Arc<Scene>,
    indices: Vec<u64>,
    pool: Option<rayon::ThreadPool>,
    window: usize,
    batch: usize,
    tx: SyncSender<Batch>,
) {
    let run = move || {
        let last = indices.len() as u64;
        let mut pending: Batch = Vec::with_capacity(batch);
        // Err(()) only stops the workers: the receiver is gone or has its failure.
        let _ = mjcf_forge::output::for_each_ordered(
            0..last,
            window,
            |k, _: &mut ()| make(&scene, indices[k as usize]),
            move |k, (), made| {
                let failed = made.is_err();
                pending.push(made);
                if failed || pending.len() >= batch || k + 1 == last {
                    let full = std::mem::replace(&mut pending, Vec::with_capacity(batch));
                    if tx.send(full).is_err() || failed {
                        return Err(());
                    }
                }
                Ok(())
            },
        );
    };
    match &pool {
        Some(pool) => pool.install(run),
        None => run(),
    }
}

/// An iterator over variants made on Rust threads (see :meth:`Scene.variants`).
#[pyclass(name = "VariantIterator", module = "mjcf_forge", frozen)]
pub(crate) struct PyVariantIter {
    taken: Mutex<Taken>,
    /// For the variants' documents, made on demand.
    scene: Arc<Scene>,
}

/// The stream's receiving end and the batch being handed out.
struct Taken {
    /// `None` once exhausted or failed.
    rx: Option<Receiver<Batch>>,
    batch: VecDeque<Result<Made, Failure>>,
}

impl Taken {
    /// The next variant of the batch at hand, or of the next batch (waiting for it if
    /// `wait`). `None`: the stream is over, or (without `wait`) nothing is at hand.
    fn next(&mut self, wait: bool) -> Option<Result<Made, Failure>> {
        if self.batch.is_empty() && wait {
            match self.rx.as_ref().and_then(|r| r.recv().ok()) {
                Some(batch) => self.batch.extend(batch),
                None => self.rx = None,
            }
        }
        let got = self.batch.pop_front();
        if matches!(got, Some(Err(_))) {
            // A failure ends the stream: later calls stop at once.
            self.rx = None;
            self.batch.clear();
        }
        got
    }
}

#[pymethods]
impl PyVariantIter {
    fn __iter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    fn __next__(&self, py: Python<'_>) -> PyResult<Option<PyVariant>> {
        // A variant of the batch at hand is taken with the GIL held; waiting for the next
        // batch releases it (the workers never need it). The lock is never waited for
        // with the GIL held: a thread that holds it may be waiting for a batch.
        let at_hand = match self.taken.try_lock() {
            Ok(mut taken) => taken.next(false),
            Err(_) => None,
        };
        let next = match at_hand {
            Some(made) => Some(made),
            None => py.detach(|| {
                let mut taken = self.taken.lock().unwrap_or_else(|p| p.into_inner());
                taken.next(true)
            }),
        };
        match next {
            Some(Ok(made)) => Ok(Some(PyVariant::new(
                made,
                Origin::Scene(self.scene.clone()),
            ))),
            Some(Err(failure)) => Err(failure.into()),
            None => Ok(None),
        }
    }
}

/// One variant of a :class:`Scene`: its ``index``, its MJCF text ``xml`` (assets
/// referenced by absolute path), and ``params``, everything that was drawn for it.
/// Picklable (as its index, XML and parameters). Its :attr:`document` is built only
/// when asked for.
#[pyclass(name = "Variant", module = "mjcf_forge", frozen)]
pub(crate) struct PyVariant {
    index: u64,
    xml: String,
    params_json: String,
    objects: usize,
    /// Where the document comes from when asked for.
    origin: Origin,
    /// The document, built on first use: most callers only want the XML.
    document: OnceLock<Document>,
    /// The `str` made once on first access (the XML of a scene is tens of kilobytes).
    xml_str: OnceLock<Py<pyo3::types::PyString>>,
    /// Structure key and patch, drawn again on first use (or shipped by pickling).
    patch: OnceLock<VariantPatch>,
    /// The patch as the Python tuple made once on first access (a model cache reads it per
    /// patch; a tuple, so that no caller can change what the next one reads).
    patch_list: OnceLock<Py<PyTuple>>,
}

/// How a variant's document is made on demand.
enum Origin {
    /// Made again by the scene (the same document the XML was written from).
    Scene(Arc<Scene>),
    /// Read back from the XML (an unpickled variant); the folder relative paths use.
    Text(PathBuf),
}

impl PyVariant {
    fn new(made: Made, origin: Origin) -> PyVariant {
        PyVariant {
            index: made.index,
            xml: made.xml,
            params_json: made.params_json,
            objects: made.objects,
            origin,
            document: OnceLock::new(),
            xml_str: OnceLock::new(),
            patch: OnceLock::new(),
            patch_list: OnceLock::new(),
        }
    }

    /// The structure key and patch, made on first call (GIL released by the caller).
    fn drawn_patch(&self) -> Result<&VariantPatch, Failure> {
        if let Some(p) = self.patch.get() {
            return Ok(p);
        }
        let p = match &self.origin {
            Origin::Scene(scene) => catch(|| Ok(scene.patch(self.index)?))?,
            Origin::Text(_) => {
                return Err(Failure::from(
                    "this variant was unpickled without its patch".to_string(),
                ));
            }
        };
        Ok(self.patch.get_or_init(|| p))
    }

    /// The document, built on first call (GIL released by the caller).
    fn doc(&self) -> Result<&Document, Failure> {
        if let Some(doc) = self.document.get() {
            return Ok(doc);
        }
        let doc = match &self.origin {
            Origin::Scene(scene) => scene.variant(self.index)?.document,
            Origin::Text(dir) => Document::from_str(&self.xml, dir)?,
        };
        // Another thread may have built it meanwhile: either copy is the same document.
        Ok(self.document.get_or_init(|| doc))
    }

    /// The folder the variant's relative paths (if any) are resolved from.
    fn model_dir(&self) -> PathBuf {
        match &self.origin {
            Origin::Scene(scene) => scene.template().model_dir().to_path_buf(),
            Origin::Text(dir) => dir.clone(),
        }
    }
}

#[pymethods]
impl PyVariant {
    /// The variant's index.
    #[getter]
    fn index(&self) -> u64 {
        self.index
    }

    /// The variant as compact MJCF text.
    #[getter]
    fn xml(&self, py: Python<'_>) -> Py<pyo3::types::PyString> {
        self.xml_str
            .get_or_init(|| pyo3::types::PyString::new(py, &self.xml).unbind())
            .clone_ref(py)
    }

    /// What was drawn, as a new ``dict``: ``objects`` (for each placed object its
    /// ``group``, ``slot``, ``model``, ``prefix``, root ``body``, ``pos`` and ``quat`` as
    /// written in the XML) and ``randomized`` (each randomized attribute with its
    /// element's kind, name, part and value); the manifest line of ``mjcf-forge
    /// generate`` without the file name.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?
            .getattr("loads")?
            .call1((self.params_json.as_str(),))
    }

    /// ``params`` as the JSON text it comes from.
    #[getter]
    fn params_json(&self) -> &str {
        &self.params_json
    }

    /// The variant's structure: equal for two variants of a scene exactly when their
    /// compiled models differ only in the values of :attr:`patch` (and what MuJoCo's
    /// ``mj_setConst`` derives from them). 32 hex digits.
    #[getter]
    fn structure_key(&self, py: Python<'_>) -> PyResult<String> {
        run(py, || Ok(self.drawn_patch()?.structure_key.clone()))
    }

    /// The values that turn a compiled model of this variant's structure into its own:
    /// a tuple of ``(object, name, field, value)``, meaning
    /// ``model.<object>(name).<field> = value`` with MuJoCo's named accessors (``name``
    /// is an ``int``, the element's id, for an unnamed element of the scene's template)
    /// (``("geom", "object0_g0_vis", "rgba", (r, g, b, a))``,
    /// ``("joint", "object0_joint0", "qpos0", (x, y, z, qw, qx, qy, qz))``). ``value`` is
    /// a tuple of floats (a ``float`` field's already rounded as MuJoCo rounds it), or
    /// for ``matid`` the material's name. See :class:`ModelCache`.
    #[getter]
    fn patch<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        if let Some(t) = self.patch_list.get() {
            return Ok(t.bind(py).clone());
        }
        let p = run(py, || Ok(self.drawn_patch()?.clone()))?;
        let t = PyTuple::new(py, patch_list(py, &p.entries)?)?;
        Ok(self.patch_list.get_or_init(|| t.unbind()).bind(py).clone())
    }

    /// A copy of the variant's :class:`Document` (to edit before writing or compiling).
    #[getter]
    fn document(&self, py: Python<'_>) -> PyResult<PyDocument> {
        run(py, || Ok(self.doc()?.clone())).map(PyDocument::new)
    }

    /// Writes the indented XML to ``path`` atomically.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        run(py, || Ok(self.doc()?.write_file(&path)?))
    }

    /// Compiles the variant with MuJoCo (``mujoco.MjModel.from_xml_string``); needs the
    /// ``mujoco`` package. Asset files are found by their absolute paths.
    fn compile<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mujoco = py.import("mujoco").map_err(|e| {
            PyImportError::new_err(format!(
                "Variant.compile() needs the mujoco package (pip install mujoco): {e}"
            ))
        })?;
        mujoco
            .getattr("MjModel")?
            .getattr("from_xml_string")?
            .call1((self.xml(py),))
    }

    fn __repr__(&self) -> String {
        format!(
            "<mjcf_forge.Variant index={} objects={} xml_bytes={}>",
            self.index,
            self.objects,
            self.xml.len()
        )
    }

    /// Pickling (Ray, multiprocessing) ships the index, the XML, the parameters and the
    /// patch; the copy reads its document back from the XML (paths in it are absolute).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let restore = py.get_type::<PyVariant>().getattr("_restore")?;
        let patch = run(py, || Ok(self.drawn_patch()?.clone()))?;
        let args = (
            self.index,
            self.xml(py),
            self.params_json.as_str(),
            self.objects,
            self.model_dir(),
            (patch.structure_key.clone(), patch_list(py, &patch.entries)?),
        )
            .into_pyobject(py)?;
        PyTuple::new(py, [restore, args.into_any()])
    }

    /// The inverse of ``__reduce__`` (not part of the API).
    #[staticmethod]
    fn _restore(
        py: Python<'_>,
        index: u64,
        xml: String,
        params_json: String,
        objects: usize,
        model_dir: PathBuf,
        patched: (String, Vec<PatchTuple<'_>>),
    ) -> PyResult<PyVariant> {
        let (structure_key, patch) = patched;
        let made = Made {
            index,
            xml,
            params_json,
            objects,
        };
        let variant = PyVariant::new(made, Origin::Text(model_dir));
        let entries = patch
            .into_iter()
            .map(|(object, name, field, value)| patch_entry(object, &name, field, &value))
            .collect::<PyResult<Vec<_>>>()?;
        let _ = variant.patch.set(VariantPatch {
            index,
            structure_key,
            entries,
        });
        // Read the document now: a pickled variant that does not read back is an error
        // at unpickling, not later.
        run(py, || variant.doc().map(|_| ()))?;
        Ok(variant)
    }
}

/// A patch entry as Python holds it: `(object, name or id, field, value)`.
type PatchTuple<'py> = (String, Bound<'py, PyAny>, String, Bound<'py, PyAny>);

/// A patch as Python tuples (see `Variant.patch`).
pub(crate) fn patch_list<'py>(
    py: Python<'py>,
    entries: &[PatchEntry],
) -> PyResult<Bound<'py, PyList>> {
    let items = entries
        .iter()
        .map(|e| {
            let value = match &e.value {
                PatchValue::Numbers(v) => PyTuple::new(py, v)?.into_any(),
                PatchValue::Id { name, .. } => name.as_str().into_pyobject(py)?.into_any(),
            };
            let name = match e.id {
                Some(id) => id.into_pyobject(py)?.into_any(),
                None => e.name.as_str().into_pyobject(py)?.into_any(),
            };
            (e.object, name, e.field, value).into_pyobject(py)
        })
        .collect::<PyResult<Vec<_>>>()?;
    PyList::new(py, items)
}

/// A patch entry back from its Python tuple (an unpickled variant's): the object and
/// field names are the library's own, matched against its table.
fn patch_entry(
    object: String,
    name: &Bound<'_, PyAny>,
    field: String,
    value: &Bound<'_, PyAny>,
) -> PyResult<PatchEntry> {
    let (name, id) = match name.extract::<usize>() {
        Ok(id) => (String::new(), Some(id)),
        Err(_) => (name.extract::<String>()?, None),
    };
    const OBJECTS: [&str; 7] = [
        "body", "joint", "geom", "site", "camera", "light", "material",
    ];
    let unknown =
        || PyValueError::new_err(format!("not a patch entry: ({object}, {name}, {field})"));
    let object = *OBJECTS.iter().find(|o| **o == object).ok_or_else(unknown)?;
    let field = if field == "matid" {
        "matid"
    } else {
        mjcf_forge::scene::PATCHABLE
            .iter()
            .map(|p| p.2)
            .chain([
                "qpos0",
                "qpos_spring",
                "ipos",
                "iquat",
                "gravcomp",
                "contype",
                "conaffinity",
            ])
            .find(|f| *f == field)
            .ok_or_else(unknown)?
    };
    let value = match value.extract::<String>() {
        Ok(target) => PatchValue::Id {
            object: "material",
            name: target,
        },
        Err(_) => PatchValue::Numbers(value.extract::<Vec<f64>>()?),
    };
    Ok(PatchEntry {
        object,
        name,
        id,
        field,
        value,
    })
}
