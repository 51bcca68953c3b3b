//! Every call this module makes up into the package's Python code, in one place: each
//! target is a name in `mjcf_forge._upcalls`, looked up once per process.
//!
//! ```text
//! compile_inertia(xml, model_dir)   the user's mujoco compiling a part alone
//! preview(scene, indices, path, **options)
//! progress_of(progress, total, unit)
//! fromstring(xml)                   an Element rebuilt (pickling)
//! MjcfFileNotFoundError             the error of missing files
//! mujoco_version()                  the user's mujoco's version (the URDF importer)
//! compile_xml(mujoco, xml)          a PatchPlan's body model compiled by the user's mujoco
//! inertia_diagonal(model, data)     where that version keeps the joint-space inertia
//! make_inertia(mujoco, model, data) that version's mj_makeM (or mj_crb)
//! snapshot_fields(mujoco, model)    what DocumentCache writes back before a patch
//! model_bytes(mujoco, model)        a model as MuJoCo's binary format (the model store)
//! model_from_bytes(mujoco, data, signature)  and read back
//! signature_offset(mujoco)          where mjModel.signature sits (None: no model store)
//! ```
//!
//! Every other import the extension makes (the standard library's `json`, `errno`,
//! `operator`, `xml.etree.ElementPath`, `collections.abc`, NumPy, the user's `mujoco`) goes
//! through [`python`] and [`python_module`].
//!
//! The package's modules never import the compiled module's internals the other way
//! round: what Python needs of Rust is the public `_mjcf_forge` types.

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyModule;

/// The Python side of every upcall.
const MODULE: &str = "mjcf_forge._upcalls";

/// `mjcf_forge._upcalls`, imported on first use.
fn module(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    static UPCALLS: PyOnceLock<Py<PyModule>> = PyOnceLock::new();
    UPCALLS
        .get_or_try_init(py, || py.import(MODULE).map(Bound::unbind))
        .map(|m| m.bind(py))
}

/// `module.name` of another Python module (the standard library, NumPy, the user's
/// `mujoco`): every import the extension makes is here, this one or [`module`]'s.
pub fn python<'py>(py: Python<'py>, module: &str, name: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import(module)?.getattr(name)
}

/// The Python module `name` (imported on each call; Python's module cache makes a second
/// import a lookup).
pub fn python_module<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyModule>> {
    py.import(name)
}

/// The upcall `name` (a function or class of `mjcf_forge._upcalls`).
pub fn get<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    module(py)?.getattr(name)
}
