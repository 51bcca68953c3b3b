//! `Element.attrib`: a live mapping over an element's attributes.
//!
//! ElementTree's `attrib` is the element's own `dict`, so code edits it in place
//! (`el.attrib["pos"] = ...`, `el.attrib.pop("material", None)`, `el.attrib.update(...)`).
//! Here the attributes live in the document, so `attrib` is a view: every read and write
//! goes to the document (as lxml's `_Attrib`). It is registered as a
//! `collections.abc.MutableMapping` and has `dict`'s methods; `dict(el.attrib)` is a copy.

use pyo3::exceptions::{PyKeyError, PyTypeError};
use pyo3::prelude::*;
use pyo3::pyclass::CompareOp;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};

use super::element::PyElement;
use super::values::{attr_pairs, checked_attr};

/// The attributes of an :class:`Element` as a live mapping: reads and writes go to the
/// document (``el.attrib["pos"] = "0 0 1"``, ``del el.attrib["name"]``,
/// ``el.attrib.update(...)``). ``dict(el.attrib)`` is a copy; ``==`` compares with any
/// mapping.
#[pyclass(name = "Attrib", module = "mjcf_forge", frozen, mapping)]
pub(crate) struct PyAttrib {
    element: Py<PyElement>,
}

impl PyAttrib {
    pub(crate) fn new(element: Py<PyElement>) -> PyAttrib {
        PyAttrib { element }
    }

    fn pairs(&self, py: Python<'_>) -> Vec<(String, String)> {
        self.element.get().read(py, |d, n| {
            d.attrs(n)
                .map(|(k, v)| (k.to_owned(), v.to_owned()))
                .collect()
        })
    }

    fn value(&self, py: Python<'_>, key: &Bound<'_, PyAny>) -> PyResult<Option<String>> {
        let Ok(key) = key.cast::<PyString>() else {
            return Ok(None);
        };
        let key = key.to_cow()?;
        Ok(self
            .element
            .get()
            .read(py, |d, n| d.attr(n, &key).map(str::to_owned)))
    }

    fn remove(&self, py: Python<'_>, key: &Bound<'_, PyAny>) -> PyResult<bool> {
        let Ok(key) = key.cast::<PyString>() else {
            return Ok(false);
        };
        let key = key.to_cow()?;
        self.element
            .get()
            .write(py, |d, n| Ok(d.remove_attr(n, &key)))
    }

    fn set(
        &self,
        py: Python<'_>,
        key: &Bound<'_, PyAny>,
        value: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let key = key
            .cast::<PyString>()
            .map_err(|_| PyTypeError::new_err("attribute names are str"))?
            .to_cow()?;
        let (key, text) = checked_attr(&key, value)?;
        self.element.get().write(py, |d, n| {
            d.set_attr(n, &key, &text);
            Ok(())
        })
    }

    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (k, v) in self.pairs(py) {
            dict.set_item(k, v)?;
        }
        Ok(dict)
    }
}

#[pymethods]
impl PyAttrib {
    /// Unhashable, as a ``dict``.
    #[classattr]
    const __hash__: Option<Py<PyAny>> = None;

    fn __getitem__(&self, py: Python<'_>, key: &Bound<'_, PyAny>) -> PyResult<String> {
        self.value(py, key)?
            .ok_or_else(|| PyKeyError::new_err(key.clone().unbind()))
    }

    fn __setitem__(
        &self,
        py: Python<'_>,
        key: &Bound<'_, PyAny>,
        value: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        self.set(py, key, value)
    }

    fn __delitem__(&self, py: Python<'_>, key: &Bound<'_, PyAny>) -> PyResult<()> {
        if self.remove(py, key)? {
            Ok(())
        } else {
            Err(PyKeyError::new_err(key.clone().unbind()))
        }
    }

    fn __contains__(&self, py: Python<'_>, key: &Bound<'_, PyAny>) -> PyResult<bool> {
        Ok(self.value(py, key)?.is_some())
    }

    fn __len__(&self, py: Python<'_>) -> usize {
        self.element.get().read(py, |d, n| d.attrs(n).count())
    }

    /// Iterates over the names (those there when the iteration starts).
    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(PyList::new(py, self.keys(py))?.try_iter()?.into_any())
    }

    /// The names, in order.
    fn keys(&self, py: Python<'_>) -> Vec<String> {
        self.pairs(py).into_iter().map(|(k, _)| k).collect()
    }

    /// The values, in order.
    fn values(&self, py: Python<'_>) -> Vec<String> {
        self.pairs(py).into_iter().map(|(_, v)| v).collect()
    }

    /// The (name, value) pairs, in order.
    fn items(&self, py: Python<'_>) -> Vec<(String, String)> {
        self.pairs(py)
    }

    /// The value of ``key``, or ``default``.
    #[pyo3(signature = (key, default = None))]
    fn get<'py>(
        &self,
        py: Python<'py>,
        key: &Bound<'py, PyAny>,
        default: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        Ok(match self.value(py, key)? {
            Some(v) => Some(PyString::new(py, &v).into_any()),
            None => default,
        })
    }

    /// Removes ``key`` and returns its value; ``default`` (or ``KeyError``) when missing.
    #[pyo3(signature = (key, *default))]
    fn pop<'py>(
        &self,
        py: Python<'py>,
        key: &Bound<'py, PyAny>,
        default: &Bound<'py, PyTuple>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if default.len() > 1 {
            return Err(PyTypeError::new_err(format!(
                "pop expected at most 2 arguments, got {}",
                default.len() + 1
            )));
        }
        match self.value(py, key)? {
            Some(v) => {
                self.remove(py, key)?;
                Ok(PyString::new(py, &v).into_any())
            }
            None if default.len() == 1 => default.get_item(0),
            None => Err(PyKeyError::new_err(key.clone().unbind())),
        }
    }

    /// Removes and returns the last (name, value) pair (``KeyError`` when empty).
    fn popitem(&self, py: Python<'_>) -> PyResult<(String, String)> {
        let (k, v) = self
            .pairs(py)
            .pop()
            .ok_or_else(|| PyKeyError::new_err("popitem(): attributes are empty"))?;
        self.element.get().write(py, |d, n| {
            d.remove_attr(n, &k);
            Ok(())
        })?;
        Ok((k, v))
    }

    /// The value of ``key``, first set to ``default`` when missing.
    fn setdefault<'py>(
        &self,
        py: Python<'py>,
        key: &Bound<'py, PyAny>,
        default: &Bound<'py, PyAny>,
    ) -> PyResult<String> {
        if let Some(v) = self.value(py, key)? {
            return Ok(v);
        }
        self.set(py, key, default)?;
        self.__getitem__(py, key)
    }

    /// Sets the attributes of ``other`` (a mapping or pairs) and the keyword arguments.
    #[pyo3(signature = (other = None, **kwargs))]
    fn update(
        &self,
        py: Python<'_>,
        other: Option<&Bound<'_, PyAny>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        let pairs = attr_pairs(other, kwargs)?;
        self.element.get().write(py, |d, n| {
            for (k, v) in &pairs {
                d.set_attr(n, k, v);
            }
            Ok(())
        })
    }

    /// Removes every attribute.
    fn clear(&self, py: Python<'_>) -> PyResult<()> {
        self.element.get().write(py, |d, n| {
            let keys: Vec<String> = d.attrs(n).map(|(k, _)| k.to_owned()).collect();
            for k in keys {
                d.remove_attr(n, &k);
            }
            Ok(())
        })
    }

    /// A ``dict`` of the attributes (a copy).
    fn copy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.to_dict(py)
    }

    fn __richcmp__<'py>(
        &self,
        py: Python<'py>,
        other: &Bound<'py, PyAny>,
        op: CompareOp,
    ) -> PyResult<Bound<'py, PyAny>> {
        match op {
            CompareOp::Eq | CompareOp::Ne => {
                let ours = self.to_dict(py)?;
                // Another live view compares by its contents; a dict (or anything a dict
                // compares with) as a dict does.
                let other = match other.cast::<PyAttrib>() {
                    Ok(a) => a.get().to_dict(py)?.into_any(),
                    Err(_) => other.clone(),
                };
                ours.rich_compare(other, op)
            }
            _ => Ok(py.NotImplemented().into_bound(py)),
        }
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(self.to_dict(py)?.repr()?.to_string())
    }
}
