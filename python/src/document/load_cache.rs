//! `LoadCache`: loaded files served again, copied, while unchanged (the library's
//! [`mjcf_forge::LoadCache`]).

use std::path::PathBuf;

use mjcf_forge::{Document, LoadCache};
use pyo3::prelude::*;

use super::{PyDocument, urdf};
use crate::errors::run;

/// Documents loaded from files, kept and served again while their file holds the same
/// bytes: a load of an unchanged file copies the kept document instead of parsing,
/// inlining and resolving paths again. One ``stat`` tells a file is unchanged once its
/// bytes were seen 3 s or more after its last change (any later write moves its change
/// time); until then the file is read and compared at each load. Files with ``<include>`` are read every time.
/// At most ``capacity`` documents are kept, the oldest going first. Safe to share between
/// threads.
///
/// Example::
///
///     files = LoadCache(256)
///     doc = files.load("panda.xml")    # read, inlined, made absolute, kept
///     again = files.load("panda.xml")  # a copy of the kept document
///     assert files.hits == 1
#[pyclass(name = "LoadCache", module = "mjcf_forge", frozen)]
pub(crate) struct PyLoadCache {
    cache: LoadCache,
}

#[pymethods]
impl PyLoadCache {
    #[new]
    #[pyo3(signature = (capacity = 256))]
    fn new(capacity: usize) -> PyLoadCache {
        PyLoadCache {
            cache: LoadCache::new(capacity),
        }
    }

    /// :meth:`Document.load` of ``path``, or a copy of the document kept from an earlier
    /// load of the same path while the file holds the same bytes. A new document every call: edits
    /// to it never reach the kept one.
    ///
    /// A URDF file is read as :meth:`Document.load` reads it, as the installed ``mujoco``
    /// imports it; under a ``mujoco`` 3.x it is read anew at each load (the kept
    /// documents are read as MuJoCo 4.0.0 imports URDF).
    ///
    /// Raises :class:`MjcfError` as :meth:`Document.load` does (errors are not kept).
    fn load(&self, py: Python<'_>, path: PathBuf) -> PyResult<PyDocument> {
        // The library's cache reads URDF with the library's default importer: a file that
        // another importer reads differently is not served from it.
        let urdf = if py.detach(|| urdf::is_urdf_file(&path)) {
            Some(urdf::plain_options(py)?)
                .filter(|o| o.importer != mjcf_forge::UrdfImporter::default())
        } else {
            None
        };
        run(py, || {
            Ok(match urdf {
                Some(options) => Document::load_urdf(&path, &options)?,
                None => self.cache.load(&path)?,
            })
        })
        .and_then(|d| super::loaded(py, d))
    }

    /// How many loads were served from kept documents.
    #[getter]
    fn hits(&self) -> u64 {
        self.cache.hits()
    }

    /// Forgets every kept document.
    fn clear(&self) {
        self.cache.clear()
    }

    /// How many documents are kept.
    fn __len__(&self) -> usize {
        self.cache.len()
    }
}
