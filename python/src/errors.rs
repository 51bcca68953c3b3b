//! The exception types, and the edge where Rust errors and panics become them.
//!
//! Every call into the library goes through [`run`] (GIL released) or [`catch`] (GIL held):
//! both turn a panic into an `MjcfError` instead of letting PyO3 raise its
//! `PanicException`, which derives from `BaseException` and so escapes `except Exception`.
//! A refusal whose every problem is a file that does not exist is an
//! `MjcfFileNotFoundError`: an `MjcfError` and a `FileNotFoundError` at once.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::{OnceLock, RwLock, RwLockReadGuard, RwLockWriteGuard};

use mjcf_forge::ErrorKind;
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyList;

create_exception!(
    mjcf_forge,
    MjcfError,
    PyValueError,
    "A model, scene or operation that mjcf-forge refuses.\n\n\
     ``str(error)`` is one line per problem, each ``file:line:col: message`` (followed by\n\
     ``(included from file:line:col)`` when the problem is inside an included file), exactly\n\
     as the ``mjcf-forge`` command line prints them. ``error.errors`` holds the same lines as\n\
     a list of ``str``, one per problem, all problems of the pass at once."
);

/// What went wrong on the Rust side, as the lines the exception will carry.
#[derive(Debug)]
pub(crate) struct Failure {
    pub(crate) lines: Vec<String>,
    /// When every problem is a file that does not exist: the first such path.
    missing: Option<PathBuf>,
}

impl Failure {
    /// A failure told by `lines` (an `MjcfError`).
    pub(crate) fn new(lines: Vec<String>) -> Failure {
        Failure {
            lines,
            missing: None,
        }
    }
}

/// The path of a file that does not exist, when `error` is about one. The library keeps
/// the operating system's words (`No such file or directory (os error 2)`), not its error
/// kind: they are compared with the words of the "not found" codes.
fn missing_file(error: &mjcf_forge::Error) -> Option<&Path> {
    static NOT_FOUND: OnceLock<Vec<String>> = OnceLock::new();
    let words = NOT_FOUND.get_or_init(|| {
        // ENOENT; Windows also has ERROR_PATH_NOT_FOUND.
        let codes: &[i32] = if cfg!(windows) { &[2, 3] } else { &[2] };
        codes
            .iter()
            .map(|&c| std::io::Error::from_raw_os_error(c).to_string())
            .collect()
    });
    let (path, reason) = match &error.kind {
        ErrorKind::Io { path, reason } => (path, reason),
        ErrorKind::IncludeNotFound {
            beside_main,
            reason,
            ..
        } => (beside_main, reason),
        _ => return None,
    };
    words
        .iter()
        .any(|w| reason.ends_with(w.as_str()))
        .then_some(path.as_path())
}

impl From<mjcf_forge::Errors> for Failure {
    fn from(errors: mjcf_forge::Errors) -> Failure {
        let missing: Option<Vec<&Path>> = errors.0.iter().map(missing_file).collect();
        Failure {
            lines: errors.0.iter().map(ToString::to_string).collect(),
            missing: missing.and_then(|paths| paths.first().map(|p| p.to_path_buf())),
        }
    }
}

impl From<mjcf_forge::Error> for Failure {
    fn from(error: mjcf_forge::Error) -> Failure {
        Failure::from(mjcf_forge::Errors(vec![error]))
    }
}

impl From<String> for Failure {
    fn from(message: String) -> Failure {
        Failure::new(vec![message])
    }
}

impl From<Failure> for PyErr {
    fn from(failure: Failure) -> PyErr {
        match failure.missing {
            Some(path) => {
                Python::attach(|py| file_not_found(py, failure.lines, &path).unwrap_or_else(|e| e))
            }
            None => mjcf_error(failure.lines),
        }
    }
}

/// Raises each of a load's warnings (what MuJoCo's URDF importer warns about, at its
/// place: `file:line:col: message`) as a ``UserWarning``.
pub(crate) fn raise_warnings(py: Python<'_>, warnings: &[mjcf_forge::Warning]) -> PyResult<()> {
    for w in warnings {
        let message = std::ffi::CString::new(w.to_string()).unwrap_or_default();
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &message,
            1,
        )?;
    }
    Ok(())
}

/// An `MjcfError` whose message is `lines` joined by newlines and whose `errors` is `lines`.
pub(crate) fn mjcf_error(lines: Vec<String>) -> PyErr {
    Python::attach(|py| {
        let err = MjcfError::new_err(lines.join("\n"));
        // Setting an attribute on a fresh exception instance cannot fail short of memory
        // exhaustion; the message still carries every line if it does.
        if let Ok(list) = PyList::new(py, &lines) {
            let _ = err.value(py).setattr("errors", list);
        }
        err
    })
}

/// An `MjcfFileNotFoundError` told by `lines`, about `path` (an error making it is
/// returned as the error to raise).
fn file_not_found(py: Python<'_>, lines: Vec<String>, path: &Path) -> Result<PyErr, PyErr> {
    // A Python class (`mjcf_forge/_errors.py`): `create_exception!` makes classes of one
    // base only.
    let class = crate::upcalls::get(py, "MjcfFileNotFoundError")?;
    let value = class.call1((lines.join("\n"),))?;
    value.setattr("errors", PyList::new(py, &lines)?)?;
    value.setattr("errno", crate::upcalls::python(py, "errno", "ENOENT")?)?;
    value.setattr("filename", path.as_os_str())?;
    Ok(PyErr::from_value(value))
}

/// Runs `work` with the GIL released (other Python threads run meanwhile); a panic becomes
/// an `MjcfError`. `work` must not touch Python objects.
pub(crate) fn run<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> Result<T, Failure> + Send,
{
    py.detach(|| catch(work)).map_err(PyErr::from)
}

/// Runs `work` (GIL held, for cheap calls); a panic becomes a [`Failure`].
pub(crate) fn catch<T>(work: impl FnOnce() -> Result<T, Failure>) -> Result<T, Failure> {
    match catch_unwind(AssertUnwindSafe(work)) {
        Ok(result) => result,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            Err(Failure::new(vec![format!(
                "internal error in mjcf-forge (please report it): {what}"
            )]))
        }
    }
}

/// A read lock that survives poisoning: a panic while a lock was held has already been
/// reported as an `MjcfError`, and refusing every later call would add nothing.
pub(crate) fn read<T>(lock: &RwLock<T>) -> RwLockReadGuard<'_, T> {
    lock.read().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The write lock, surviving poisoning as [`read`] does.
pub(crate) fn write<T>(lock: &RwLock<T>) -> RwLockWriteGuard<'_, T> {
    lock.write()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}
