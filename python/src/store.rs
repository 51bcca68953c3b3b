//! The model store across processes ([`mjcf_forge::split::DiskStore`]) over the user's
//! `mujoco`, for both caches of the Python face (`DocumentCore`, `CacheCore`): which store
//! a cache gets from its `store=` argument, a stored model read back and written out
//! through the package's `model_from_bytes` and `model_bytes` (`upcalls.rs`), and the
//! store's failures as `RuntimeWarning`s (the cache then compiles).

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyByteArray, PyBytes};

use crate::upcalls;
use mjcf_forge::Document;
use mjcf_forge::split::{self, DiskStore, StoreKey, load_or_compile};

/// The store a cache's `store=` names: `None` or `True` the environment's
/// (`MJCF_FORGE_STORE`, else the user cache folder), `False` none, else a folder. A
/// folder that cannot be opened, or a `mujoco` whose `mjModel` layout cannot be checked
/// (a loaded model could not get its signature back), is a warning and no store.
pub(crate) fn open(
    py: Python<'_>,
    store: Option<Bound<'_, PyAny>>,
    mujoco: &Py<PyAny>,
) -> PyResult<Option<DiskStore>> {
    let store = match store {
        None => DiskStore::from_env(),
        Some(s) if s.is_instance_of::<PyBool>() => {
            if s.extract::<bool>()? {
                DiskStore::from_env()
            } else {
                None
            }
        }
        Some(s) => {
            let dir: std::path::PathBuf = s.extract()?;
            Some(DiskStore::open(dir, split::DEFAULT_STORE_BYTES))
        }
    };
    let store = match store.transpose() {
        Ok(store) => store,
        Err(e) => {
            warn(py, &e.to_string());
            None
        }
    };
    // A stored model must get its signature back (MuJoCo's binary format drops it).
    if store.is_some()
        && upcalls::get(py, "signature_offset")?
            .call1((mujoco.bind(py),))?
            .is_none()
    {
        warn(
            py,
            "model store: this mujoco's mjModel layout is not known, so a stored model \
             could not carry its signature: no store",
        );
        return Ok(None);
    }
    Ok(store)
}

/// `message` as a Python `RuntimeWarning` (the store's failures: the cache compiles).
pub(crate) fn warn(py: Python<'_>, message: &str) {
    let warned = upcalls::python(py, "warnings", "warn")
        .and_then(|w| w.call1((message, py.get_type::<pyo3::exceptions::PyRuntimeWarning>())));
    if let Err(e) = warned {
        // A filter that turns warnings into errors: the store's failure is not the call's.
        e.print(py);
    }
}

/// The store key of structure `key` of `doc` compiled by the user's `mujoco`: its version
/// and every file the document reads (hashed with the GIL released).
pub(crate) fn key(
    py: Python<'_>,
    doc: &Document,
    key: &str,
    mujoco: &Py<PyAny>,
) -> PyResult<String> {
    let version: String = mujoco.bind(py).getattr("__version__")?.extract()?;
    Ok(py.detach(|| StoreKey::of_document(key, &version, doc)))
}

/// The model stored under `key` in `store`, read back by the user's `mujoco`, or else
/// `compile`'s model, then stored; with whether it was read back.
pub(crate) fn load_or(
    py: Python<'_>,
    store: &DiskStore,
    key: &str,
    mujoco: &Py<PyAny>,
    compile: impl FnOnce() -> PyResult<Py<PyAny>>,
) -> PyResult<(Py<PyAny>, bool)> {
    load_or_compile(
        Some((store, key)),
        |bytes| {
            // The signature apart: the model's bytes copied once, not twice.
            let (signature, mjb) = bytes.split_at_checked(8)?;
            let signature = u64::from_le_bytes(signature.try_into().ok()?);
            upcalls::get(py, "model_from_bytes")
                .and_then(|f| f.call1((mujoco.bind(py), PyBytes::new(py, mjb), signature)))
                .ok()
                .filter(|m| !m.is_none())
                .map(Bound::unbind)
        },
        |model: &Py<PyAny>| {
            upcalls::get(py, "model_bytes")
                .and_then(|f| f.call1((mujoco.bind(py), model.bind(py))))
                .ok()
                .and_then(|b| match b.cast::<PyByteArray>() {
                    Ok(a) => Some(a.to_vec()),
                    Err(_) => Some(b.cast::<PyBytes>().ok()?.as_bytes().to_vec()),
                })
        },
        compile,
        &mut |w| warn(py, &w),
    )
}
