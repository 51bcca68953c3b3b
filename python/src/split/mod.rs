//! The split tier's face in Python: its tables (`tables.rs`, the one copy of each the
//! package's caches read) and the rules the caches run over the user's `MjModel` in place
//! (`plan.rs`, the split tier's patch plan over the user's `mujoco`, and `snapshot.rs`,
//! what the document cache writes back before a patch, and `rows.rs`, a superset's
//! per-world rows; with `patch.rs`, `statistics.rs`,
//! `body_models.rs`, through `arrays.rs`).

// NumPy's memory read in place: the bindings' only unsafe code.
#[allow(unsafe_code)]
mod arrays;
#[allow(unsafe_code)]
mod body_models;
#[allow(unsafe_code)]
mod patch;
#[allow(unsafe_code)]
mod plan;
mod rows;
mod signature;
#[allow(unsafe_code)]
mod snapshot;
#[allow(unsafe_code)]
mod statistics;
mod tables;
#[allow(unsafe_code)]
mod user_model;

use pyo3::prelude::*;

pub(crate) use plan::PyPatchPlan;
pub(crate) use signature::signature_of;
pub(crate) use snapshot::{Snapshot, Views, references};

/// A refusal of this face's model to the split tier's rules, in words (the kind of the
/// rules' own, `ErrorKind::Patch`).
fn patch_error(message: impl Into<String>) -> mjcf_forge::Error {
    mjcf_forge::Error {
        location: None,
        kind: mjcf_forge::ErrorKind::Patch(message.into()),
    }
}

/// Adds the tier's tables, functions and classes to the module.
pub(crate) fn add(m: &Bound<'_, PyModule>) -> PyResult<()> {
    tables::add(m)?;
    m.add_class::<statistics::PyStatistics>()?;
    m.add_class::<body_models::PyModelArrays>()?;
    m.add_class::<plan::PyPatchPlan>()?;
    m.add_class::<rows::PyWorldRows>()?;
    m.add_function(wrap_pyfunction!(rows::patchable_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(signature::structure_signature, m)?)?;
    Ok(())
}
