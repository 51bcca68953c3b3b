//! The tests' and benches' entry points (`mjcf_forge._mjcf_forge._testing`): not part of
//! the API, kept out of the module's own namespace so that no user meets them there.

use pyo3::prelude::*;

use crate::errors;
use crate::scene::PyScene;

/// Panics on purpose inside the edge where every call runs, with the GIL released
/// (`detached=True`) or held: the tests' proof that a panic reaches Python as an
/// `MjcfError`, never as PyO3's `PanicException`.
#[pyfunction]
#[pyo3(signature = (detached = true))]
fn panic(py: Python<'_>, detached: bool) -> PyResult<()> {
    let work = || -> Result<(), errors::Failure> { panic!("deliberate panic for the tests") };
    if detached {
        errors::run(py, work)
    } else {
        Ok(errors::catch(work)?)
    }
}

/// A random MJCF model, its structure drawn from ``seed`` and its values from ``(seed,
/// variant)`` (``mjcf_forge::fuzzing::random_mjcf``): the differential tests' documents.
///
/// >>> from mjcf_forge._mjcf_forge import _testing
/// >>> _testing.random_mjcf(3, 0) == _testing.random_mjcf(3, 0) != _testing.random_mjcf(3, 1)
/// True
#[pyfunction]
fn random_mjcf(seed: u64, variant: u64) -> String {
    mjcf_forge::fuzzing::random_mjcf(seed, variant)
}

/// ``random_mjcf`` as files, ``(name, text)``, ``model.xml`` first; for some seeds its
/// first body is in ``part.xml``, which ``model.xml`` includes.
///
/// >>> from mjcf_forge._mjcf_forge import _testing
/// >>> _testing.random_mjcf_files(3, 0)[0][0]
/// 'model.xml'
#[pyfunction]
fn random_mjcf_files(seed: u64, variant: u64) -> Vec<(String, String)> {
    mjcf_forge::fuzzing::random_mjcf_files(seed, variant)
}

/// A random scene (``mjcf_forge::fuzzing::random_scene``): its TOML and the model files it
/// names, ``(name, text)``, to be written into one folder.
///
/// >>> from mjcf_forge._mjcf_forge import _testing
/// >>> toml, files = _testing.random_scene(5)
/// >>> "arena.xml" in dict(files)
/// True
#[pyfunction]
fn random_scene(seed: u64) -> (String, Vec<(String, String)>) {
    let scene = mjcf_forge::fuzzing::random_scene(seed);
    (scene.toml, scene.files)
}

/// Seconds spent in Rust making ``indices`` of ``scene`` one at a time on this thread
/// (variant, XML and parameters, exactly what ``Scene.variant`` makes) without making any
/// Python object: the baseline against which the benchmarks measure the cost of crossing
/// into Python per variant.
#[pyfunction]
fn rust_seconds(py: Python<'_>, scene: &PyScene, indices: Vec<u64>) -> PyResult<f64> {
    scene.rust_seconds(py, &indices)
}

/// The submodule `_testing`, added to the extension module `m`.
pub(crate) fn add(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let testing = PyModule::new(m.py(), "_testing")?;
    testing.add_function(wrap_pyfunction!(panic, &testing)?)?;
    testing.add_function(wrap_pyfunction!(random_mjcf, &testing)?)?;
    testing.add_function(wrap_pyfunction!(random_mjcf_files, &testing)?)?;
    testing.add_function(wrap_pyfunction!(random_scene, &testing)?)?;
    testing.add_function(wrap_pyfunction!(rust_seconds, &testing)?)?;
    m.add_submodule(&testing)
}
