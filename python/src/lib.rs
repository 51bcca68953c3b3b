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
//! `upcalls.rs` the one way up into the package's Python code; `testing.rs` the tests' and
//! benches' entry points, in a submodule of their own. `cache.rs` is the compiled tier's
//! face: the split tier's model cache over the user's own `mujoco` package
//! (`mjcf_forge/_cache.py`'s `ModelCache` is its Python face), and `documents.rs` the
//! split tier's document cache over it (under `_doc_cache.py`'s `DocumentCache`). `sheet.rs` is
//! the contact sheet's rules (`mjcf_forge::sheet`) for `mjcf_forge/_preview.py`.
//!
//! No `unsafe` but in `split/`, which reads and writes NumPy arrays of the user's MuJoCo
//! in place (`split/arrays.rs`).
#![deny(unsafe_code)]

mod cache;
mod document;
mod documents;
mod errors;
mod model;
mod scene;
mod sheet;
mod split;
mod store;
mod testing;
mod upcalls;

use pyo3::prelude::*;

/// mimalloc for everything Rust allocates in the module: a variant made on a worker thread
/// is freed on the Python thread, and glibc's malloc takes the worker's arena lock for
/// each such free (`Scene.variants` made about one futex call per variant for it).
/// Nothing allocated here is freed by Python's allocator or the other way round: Python
/// objects are made by copying.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// MuJoCo MJCF models loaded exactly as MuJoCo reads them, prefixed, merged into scenes,
/// and written back; randomized scene variants generated in Rust threads.
#[pymodule]
fn _mjcf_forge(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MjcfError", m.py().get_type::<errors::MjcfError>())?;
    m.add_class::<document::PyDocument>()?;
    m.add_class::<document::PyElement>()?;
    m.add_class::<document::PyAttrib>()?;
    // `attrib` is a mapping to isinstance() and to code that checks for one.
    upcalls::python(m.py(), "collections.abc", "MutableMapping")?
        .call_method1("register", (m.py().get_type::<document::PyAttrib>(),))?;
    m.add_class::<document::PyMergeReport>()?;
    m.add_class::<document::PyLoadCache>()?;
    m.add_class::<document::PyDocumentSplit>()?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<scene::PyScene>()?;
    m.add_class::<scene::PyVariant>()?;
    m.add_class::<scene::PyVariantIter>()?;
    m.add_class::<scene::PySuperset>()?;
    split::add(m)?;
    m.add_class::<cache::PyCacheCore>()?;
    m.add_class::<documents::PyDocumentCore>()?;
    sheet::add(m)?;
    testing::add(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
