//! The `mjcf_forge` Python module: thin wrappers around the mjcf-forge library.
//!
//! Each Python type converts its arguments at the edge, does the work in Rust with the GIL
//! released (see `errors::run`), and turns `Errors` and panics into `MjcfError`. The
//! library crate knows nothing of Python.
//!
//! The files mirror the library's tiers: `document/` (the document tier, with elements that
//! behave as `xml.etree` elements), `model.rs`
//! (instances), `split/` (the split tier's tables, and its rules run over the user's
//! `MjModel` arrays in place), `scene/` (the batch tier: scenes, variants, the stream, the
//! superset); `errors.rs` is the edge where Rust errors and panics become `MjcfError`;
//! `upcalls.rs` the one way up into the package's Python code. The compiled tier's face,
//! `ModelCache`, is Python (`mjcf_forge/_cache.py`), over the user's own `mujoco` package.
//!
//! No `unsafe` but in `split/`, which reads and writes NumPy arrays of the user's MuJoCo
//! in place (`split/arrays.rs`).
#![deny(unsafe_code)]

mod document;
mod errors;
mod model;
mod scene;
mod split;
mod upcalls;

use pyo3::prelude::*;

/// mimalloc for everything Rust allocates in the module: a variant made on a worker thread
/// is freed on the Python thread, and glibc's malloc takes the worker's arena lock for
/// each such free (`Scene.variants` made about one futex call per variant for it).
/// Nothing allocated here is freed by Python's allocator or the other way round: Python
/// objects are made by copying.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Panics on purpose inside the edge where every call runs, with the GIL released
/// (`detached=True`) or held: the tests' proof that a panic reaches Python as an
/// `MjcfError`, never as PyO3's `PanicException`. Not part of the API.
#[pyfunction]
#[pyo3(signature = (detached = true))]
fn _panic_for_tests(py: Python<'_>, detached: bool) -> PyResult<()> {
    let work = || -> Result<(), errors::Failure> { panic!("deliberate panic for the tests") };
    if detached {
        errors::run(py, work)
    } else {
        Ok(errors::catch(work)?)
    }
}

/// A random MJCF model, its structure drawn from ``seed`` and its values from ``(seed,
/// variant)`` (``mjcf_forge::fuzzing::random_mjcf``): the differential tests' documents.
/// Not part of the API.
///
/// >>> from mjcf_forge._mjcf_forge import _random_mjcf
/// >>> _random_mjcf(3, 0) == _random_mjcf(3, 0) != _random_mjcf(3, 1)
/// True
#[pyfunction]
fn _random_mjcf(seed: u64, variant: u64) -> String {
    mjcf_forge::fuzzing::random_mjcf(seed, variant)
}

/// ``_random_mjcf`` as files, ``(name, text)``, ``model.xml`` first; for some seeds its
/// first body is in ``part.xml``, which ``model.xml`` includes. Not part of the API.
///
/// >>> from mjcf_forge._mjcf_forge import _random_mjcf_files
/// >>> _random_mjcf_files(3, 0)[0][0]
/// 'model.xml'
#[pyfunction]
fn _random_mjcf_files(seed: u64, variant: u64) -> Vec<(String, String)> {
    mjcf_forge::fuzzing::random_mjcf_files(seed, variant)
}

/// A random scene (``mjcf_forge::fuzzing::random_scene``): its TOML and the model files it
/// names, ``(name, text)``, to be written into one folder. Not part of the API.
///
/// >>> from mjcf_forge._mjcf_forge import _random_scene
/// >>> toml, files = _random_scene(5)
/// >>> "arena.xml" in dict(files)
/// True
#[pyfunction]
fn _random_scene(seed: u64) -> (String, Vec<(String, String)>) {
    let scene = mjcf_forge::fuzzing::random_scene(seed);
    (scene.toml, scene.files)
}

/// MuJoCo MJCF models loaded exactly as MuJoCo reads them, prefixed, merged into scenes,
/// and written back; randomized scene variants generated in Rust threads.
#[pymodule]
fn _mjcf_forge(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MjcfError", m.py().get_type::<errors::MjcfError>())?;
    m.add_class::<document::PyDocument>()?;
    m.add_class::<document::PyElement>()?;
    m.add_class::<document::PyAttrib>()?;
    // `attrib` is a mapping to isinstance() and to code that checks for one.
    m.py()
        .import("collections.abc")?
        .getattr("MutableMapping")?
        .call_method1("register", (m.py().get_type::<document::PyAttrib>(),))?;
    m.add_class::<document::PyMergeReport>()?;
    m.add_class::<document::PyLoadCache>()?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<scene::PyScene>()?;
    m.add_class::<scene::PyVariant>()?;
    m.add_class::<scene::PyVariantIter>()?;
    m.add_class::<scene::PySuperset>()?;
    m.add_function(wrap_pyfunction!(_panic_for_tests, m)?)?;
    m.add_function(wrap_pyfunction!(_random_mjcf, m)?)?;
    m.add_function(wrap_pyfunction!(_random_scene, m)?)?;
    m.add_function(wrap_pyfunction!(_random_mjcf_files, m)?)?;
    split::add(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
