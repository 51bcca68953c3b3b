//! The batch tier's face: `Scene`, its variants, the variant stream and the superset.
//!
//! A `Scene` is an `Arc` of the library's `Scene` (`Send + Sync`), so Python threads share
//! one and every call releases the GIL. The files mirror the library's `scene` module:
//! `variant.rs` (one variant and what a worker makes for it), `stream.rs` (many variants
//! made on Rust threads, handed over in order) and `superset.rs` (one model for every
//! variant); patches as Python tuples are the document module's (`document/patch.rs`).

mod stream;
mod superset;
mod variant;

pub(crate) use stream::PyVariantIter;
pub(crate) use superset::PySuperset;
pub(crate) use variant::PyVariant;

use std::path::PathBuf;
use std::sync::Arc;

use crate::upcalls;
use mjcf_forge::Document;
use mjcf_forge::scene::Scene;
use pyo3::exceptions::{PyIndexError, PyOverflowError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::document::{PyDocument, python_inertia};
use crate::errors::run;
use variant::{Origin, make};

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
    /// Seconds spent in Rust making `indices` one at a time on this thread, making no
    /// Python object (`_testing.rust_seconds`).
    pub(crate) fn rust_seconds(&self, py: Python<'_>, indices: &[u64]) -> PyResult<f64> {
        run(py, || {
            let start = std::time::Instant::now();
            for &i in indices {
                // Dropped at once, as a Python caller drops a variant it has read.
                std::hint::black_box(make(&self.scene, i)?);
            }
            Ok(start.elapsed().as_secs_f64())
        })
    }

    fn new(scene: Scene, source: Source) -> PyScene {
        PyScene {
            scene: Arc::new(scene),
            source,
        }
    }
}

/// The installed ``mujoco``, as the package calls it, for the inertials an object group
/// writes out (``write_inertials = true``): called only when a group asks.
fn python_mujoco(py: Python<'_>) -> PyResult<Py<PyAny>> {
    Ok(upcalls::get(py, "compile_inertia")?.unbind())
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
        let mujoco = python_mujoco(py)?;
        follow_installed_mujoco(py)?;
        let scene = run(py, || {
            Ok(match &path {
                Some(path) => Scene::load_with(path, &mut |d| python_inertia(&mujoco, d))?,
                None => Scene::demo()?,
            })
        })?;
        crate::errors::raise_warnings(py, scene.warnings())?;
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
        let mujoco = python_mujoco(py)?;
        follow_installed_mujoco(py)?;
        let scene = run(py, || {
            let mut compile = |d: &Document| python_inertia(&mujoco, d);
            Ok(Scene::from_toml_str_with(&text, &base_dir, &mut compile)?)
        })?;
        crate::errors::raise_warnings(py, scene.warnings())?;
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
        let json: String = upcalls::python(py, "json", "dumps")?
            .call1((description,))
            .map_err(|e| {
                PyValueError::new_err(format!("the scene description is not JSON data: {e}"))
            })?
            .extract()?;
        let mujoco = python_mujoco(py)?;
        follow_installed_mujoco(py)?;
        let scene = run(py, || {
            let mut compile = |d: &Document| python_inertia(&mujoco, d);
            Ok(Scene::from_json_str_with(&json, &base_dir, &mut compile)?)
        })?;
        crate::errors::raise_warnings(py, scene.warnings())?;
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
    fn superset(&self, py: Python<'_>) -> PyResult<PySuperset> {
        let scene = Arc::clone(&self.scene);
        let (superset, xml) = run(py, move || {
            let s = scene.superset()?;
            let xml = s.document.to_xml_string();
            Ok((s, xml))
        })?;
        Ok(PySuperset {
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

    /// A contact sheet of variants ``indices`` (an iterable of ints, or ``n`` for
    /// ``range(n)``; an index may come twice): each variant compiled with your ``mujoco``
    /// and drawn by ``mujoco.Renderer`` at its initial pose into one ``cell`` (width,
    /// height) of a grid of ``columns`` (default: the smallest whose square holds every
    /// cell), 2 pixels apart, labelled with its index unless ``labels=False``. Returns the
    /// sheet as a ``uint8`` array (height, width, 3) and writes it as PNG to ``path`` when
    /// given (atomically; no Pillow needed).
    ///
    /// ``camera``: a camera of the scene by its full name; without it every cell shares
    /// the free camera of the first variant that ``mjcf-forge preview`` uses (docs/cli.md).
    /// ``geoms``: ``"default"`` (groups 0-2, as MuJoCo draws), ``"visual"``,
    /// ``"collision"`` or ``"all"``. With ``segmentation=True`` the result is instead an
    /// ``int32`` array (height, width) of the geom id drawn at each pixel (ids of that
    /// cell's variant's model; -1 for none and between cells), and nothing is written.
    ///
    /// Rendering is ``mujoco``'s: ``MUJOCO_GL`` picks the OpenGL platform; unset (and
    /// ``mujoco`` not imported yet) it is set to ``egl``, or ``osmesa`` without EGL.
    ///
    /// Example::
    ///
    ///     sheet = scene.preview(16, "sheet.png")     # variants 0..15, 4 x 4 cells
    ///     sheet.shape                                # (966, 1286, 3)
    #[pyo3(signature = (indices, path = None, **options))]
    fn preview<'py>(
        slf: &Bound<'py, Self>,
        indices: &Bound<'py, PyAny>,
        path: Option<&Bound<'py, PyAny>>,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        // Drawn with the user's mujoco, in Python (mjcf_forge/_preview.py): this module
        // links no MuJoCo.
        upcalls::get(slf.py(), "preview")?.call((slf, indices, path), options)
    }

    /// Variant ``index`` (made with the GIL released): an ``int`` from 0 to 2**64 - 1
    /// (``IndexError`` outside, ``TypeError`` for another type). Raises
    /// :class:`MjcfError` when it cannot be made, e.g. a group whose objects find no place
    /// (the message names the group, the region and the index).
    fn variant(&self, py: Python<'_>, index: &Bound<'_, PyAny>) -> PyResult<PyVariant> {
        let index = variant_index(index)?;
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
    ///
    /// ``progress``: ``True`` for a ``tqdm`` bar (a line on standard error every second
    /// without ``tqdm``), or your own object with ``update(n)`` (a ``tqdm`` bar) or a
    /// callable ``f(n)``, told of the variants handed over once per batch; ``None``
    /// (default) or ``False`` for none.
    #[pyo3(signature = (indices, threads = None, window = None, progress = None))]
    fn variants(
        &self,
        py: Python<'_>,
        indices: &Bound<'_, PyAny>,
        threads: Option<usize>,
        window: Option<usize>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyVariantIter> {
        let indices: Vec<u64> = indices
            .try_iter()?
            .map(|i| i.and_then(|i| variant_index(&i)))
            .collect::<PyResult<_>>()?;
        if threads == Some(0) || window == Some(0) {
            return Err(PyValueError::new_err(
                "threads and window must be at least 1",
            ));
        }
        let progress = match progress {
            Some(p) if !p.is_none() => {
                let made =
                    upcalls::get(py, "progress_of")?.call1((p, indices.len(), "variants"))?;
                (!made.is_none()).then(|| made.unbind())
            }
            _ => None,
        };
        Ok(PyVariantIter::start(
            self.scene.clone(),
            indices,
            threads,
            window,
            progress,
        )?)
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
                let dict = upcalls::python(py, "json", "loads")?.call1((json,))?;
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

/// A variant index from Python: an integer from 0 to 2**64 - 1 (anything with
/// ``__index__``). Outside that range an ``IndexError`` (a negative index does not count
/// from an end: a scene's variants have none); another type a ``TypeError``.
pub(crate) fn variant_index(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    match value.extract::<u64>() {
        Ok(i) => Ok(i),
        Err(e) if e.is_instance_of::<PyOverflowError>(value.py()) => {
            Err(PyIndexError::new_err(format!(
                "variant index {} is out of range: indices run from 0 to 2**64 - 1",
                value.repr()?
            )))
        }
        Err(_) => Err(PyTypeError::new_err(format!(
            "a variant index is an int, not {}",
            value.get_type().name()?
        ))),
    }
}

/// A path made absolute for the pickled form, so that a copy loaded in another process
/// (another current folder) finds the same files. Messages keep the path as given.
fn absolute(path: PathBuf) -> PathBuf {
    std::path::absolute(&path).unwrap_or(path)
}

/// A scene's URDF models are read as the installed `mujoco`'s importer reads them (the
/// scene compiles with it): made the process's default before the scene loads.
fn follow_installed_mujoco(py: Python<'_>) -> PyResult<()> {
    let importer = crate::document::urdf::installed_importer(py)?;
    mjcf_forge::UrdfImporter::set_default(Some(importer));
    Ok(())
}
