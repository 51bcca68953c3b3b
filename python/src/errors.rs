//! The one exception type, and the edge where Rust errors and panics become it.
//!
//! Every call into the library goes through [`run`] (GIL released) or [`catch`] (GIL held):
//! both turn a panic into an `MjcfError` instead of letting PyO3 raise its
//! `PanicException`, which derives from `BaseException` and so escapes `except Exception`.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::{RwLock, RwLockReadGuard, RwLockWriteGuard};

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
pub(crate) struct Failure(pub(crate) Vec<String>);

impl From<mjcf_forge::Errors> for Failure {
    fn from(errors: mjcf_forge::Errors) -> Failure {
        Failure(errors.0.iter().map(ToString::to_string).collect())
    }
}

impl From<mjcf_forge::Error> for Failure {
    fn from(error: mjcf_forge::Error) -> Failure {
        Failure(vec![error.to_string()])
    }
}

impl From<String> for Failure {
    fn from(message: String) -> Failure {
        Failure(vec![message])
    }
}

impl From<Failure> for PyErr {
    fn from(failure: Failure) -> PyErr {
        mjcf_error(failure.0)
    }
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
            Err(Failure(vec![format!(
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
