//! The `mjcf_forge` Python module: thin wrappers around the mjcf-forge library.
//!
//! Each Python type converts its arguments at the edge, does the work in Rust with the GIL
//! released (see `errors::run`), and turns `Errors` and panics into `MjcfError`. The
//! library crate knows nothing of Python.
#![forbid(unsafe_code)]

mod document;
mod errors;
mod model;
mod scene;

use pyo3::prelude::*;

/// MuJoCo MJCF models loaded exactly as MuJoCo reads them, prefixed, merged into scenes,
/// and written back; randomized scene variants generated in Rust threads.
#[pymodule]
fn _mjcf_forge(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MjcfError", m.py().get_type::<errors::MjcfError>())?;
    m.add_class::<document::PyDocument>()?;
    m.add_class::<document::PyElement>()?;
    m.add_class::<document::PyMergeReport>()?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<scene::PyScene>()?;
    m.add_class::<scene::PyVariant>()?;
    m.add_class::<scene::PyVariantIter>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
