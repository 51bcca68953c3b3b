//! `Element`: a proxy to one node of a document that behaves as an
//! `xml.etree.ElementTree.Element` (lxml's design: the tree stays native, the proxy is thin).
//!
//! The methods here are the element's face; the work is in the files beside it:
//! `children.rs` (append, insert, remove, indexing), `path.rs` (ElementPath, `iter`),
//! `attrib.rs` (the live `attrib` mapping), `cell.rs` (the document and the one proxy per
//! node).

use std::sync::{Arc, Mutex};

use mjcf_forge::{Document, Node};
use pyo3::exceptions::{PyDeprecationWarning, PyKeyError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};

use super::attrib::PyAttrib;
use super::cell::{DocCell, next_serial, proxies, proxy};
use super::values::{attr_pairs, check_xml_name, check_xml_text, checked_attr};
use super::{children, path};
use crate::errors::{Failure, catch};

/// Which node a proxy stands for. It changes when the element is copied into another
/// document (see `cell::retarget`).
pub(crate) struct Target {
    pub(crate) cell: Arc<DocCell>,
    pub(crate) node: Node,
}

/// An element of a :class:`Document` (or a new one), with the interface of
/// ``xml.etree.ElementTree.Element``: ``tag``, ``text``, ``tail``, a live ``attrib``
/// mapping, ``get``/``set``/``keys``/``items``, ElementPath ``find``/``findall``/
/// ``iterfind``/``findtext``, ``iter``, ``itertext``, ``append``/``extend``/``insert``/
/// ``remove``, indexing and slicing over the child elements, ``copy.copy`` and
/// ``copy.deepcopy``; ``xml.etree.ElementTree.tostring`` serializes it as it would an
/// element of its own.
///
/// There is one ``Element`` object per element of a document, so ``a is b`` for the same
/// element, and a handle stays valid: edits through it are made in the document. Appending
/// an element of the same document moves it; an element of another document (or a new
/// one, or an ``xml.etree`` element) is copied in, and handles to the copied elements
/// then stand for the copies (so does a merged part's after :meth:`Document.merge`). A
/// removed element is a detached element: it reads and edits as before, outside the
/// document, and can be appended again.
///
/// Attribute values are MJCF text; :meth:`set` also takes numbers, booleans and sequences
/// of numbers (written as MuJoCo reads them: ``[0, 0.5, 1]`` becomes ``"0 0.5 1"``).
/// Beyond ElementTree: ``name``, ``parent``, ``location``, ``el["pos"]`` for an attribute,
/// ``append("site", {...})`` to make a new child, :meth:`find_named`.
#[pyclass(name = "Element", module = "mjcf_forge", frozen, weakref)]
pub(crate) struct PyElement {
    target: Mutex<Target>,
    serial: u64,
}

impl PyElement {
    /// A proxy of `node`; register it through `cell::proxy`, never directly.
    pub(crate) fn at(cell: Arc<DocCell>, node: Node) -> PyElement {
        PyElement {
            target: Mutex::new(Target { cell, node }),
            serial: next_serial(),
        }
    }

    pub(crate) fn serial(&self) -> u64 {
        self.serial
    }

    /// The cell and node this proxy stands for now.
    pub(crate) fn target(&self) -> (Arc<DocCell>, Node) {
        let t = self.target.lock().unwrap_or_else(|p| p.into_inner());
        (t.cell.clone(), t.node)
    }

    pub(crate) fn point_at(&self, cell: Arc<DocCell>, node: Node) {
        let mut t = self.target.lock().unwrap_or_else(|p| p.into_inner());
        let old = std::mem::replace(&mut *t, Target { cell, node });
        drop(t);
        drop(old);
    }

    /// Reads the document at this element.
    pub(crate) fn read<R>(&self, py: Python<'_>, f: impl FnOnce(&Document, Node) -> R) -> R {
        let (cell, node) = self.target();
        let doc = cell.read(py);
        f(&doc, node)
    }

    /// Changes the document at this element (a panic becomes an `MjcfError`).
    pub(crate) fn write<R>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut Document, Node) -> Result<R, Failure>,
    ) -> PyResult<R> {
        let (cell, node) = self.target();
        let mut doc = cell.write(py);
        Ok(catch(|| f(&mut doc, node))?)
    }
}

impl Drop for PyElement {
    fn drop(&mut self) {
        let t = self.target.get_mut().unwrap_or_else(|p| p.into_inner());
        t.cell.forget(t.node, self.serial);
    }
}

/// A new element in a document of its own (``Element(tag, attrib, **extra)``).
pub(crate) fn new_element<'py>(
    py: Python<'py>,
    tag: &str,
    attrib: Option<&Bound<'py, PyAny>>,
    extra: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyElement>> {
    check_xml_name("tag", tag)?;
    let pairs = attr_pairs(attrib, extra)?;
    let mut doc = Document::with_root(tag);
    let root = doc.root();
    for (k, v) in &pairs {
        doc.set_attr(root, k, v);
    }
    proxy(py, &DocCell::new(doc), root)
}

#[pymethods]
impl PyElement {
    /// A new element, in no document yet: append it to one (it is then copied in, and
    /// this handle stands for the copy).
    #[new]
    #[pyo3(signature = (tag, attrib = None, **extra))]
    fn py_new(
        py: Python<'_>,
        tag: &str,
        attrib: Option<&Bound<'_, PyAny>>,
        extra: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Py<PyElement>> {
        Ok(new_element(py, tag, attrib, extra)?.unbind())
    }

    /// The element's tag (``"body"``, ``"geom"``, ...); settable.
    #[getter]
    fn tag(&self, py: Python<'_>) -> String {
        self.read(py, |d, n| d.tag(n).to_owned())
    }

    #[setter(tag)]
    fn set_tag(&self, py: Python<'_>, tag: Option<&str>) -> PyResult<()> {
        let tag = tag.ok_or_else(|| PyTypeError::new_err("an element's tag cannot be deleted"))?;
        check_xml_name("tag", tag)?;
        self.write(py, |d, n| {
            d.rename(n, tag);
            Ok(())
        })
    }

    /// The character data before the first child element, or ``None`` (MJCF files carry
    /// almost none). Settable; ``None`` or ``""`` removes it.
    #[getter]
    fn text(&self, py: Python<'_>) -> Option<String> {
        self.read(py, |d, n| d.element_text(n).map(|t| t.into_owned()))
    }

    #[setter(text)]
    fn set_text(&self, py: Python<'_>, text: Option<&str>) -> PyResult<()> {
        if let Some(t) = text {
            check_xml_text("text", t)?;
        }
        self.write(py, |d, n| {
            d.set_element_text(n, text);
            Ok(())
        })
    }

    /// The character data after this element up to the next one, or ``None``. Settable;
    /// an element without a parent has no tail, and setting one raises :class:`MjcfError`.
    #[getter]
    fn tail(&self, py: Python<'_>) -> Option<String> {
        self.read(py, |d, n| d.element_tail(n).map(|t| t.into_owned()))
    }

    #[setter(tail)]
    fn set_tail(&self, py: Python<'_>, tail: Option<&str>) -> PyResult<()> {
        if let Some(t) = tail {
            check_xml_text("tail", t)?;
        }
        self.write(py, |d, n| Ok(d.set_element_tail(n, tail)?))
    }

    /// The attributes as a live mapping (a ``collections.abc.MutableMapping``): reading
    /// and changing it reads and changes the document. Assigning a mapping replaces them.
    #[getter]
    fn attrib(slf: &Bound<'_, Self>) -> PyAttrib {
        PyAttrib::new(slf.clone().unbind())
    }

    #[setter(attrib)]
    fn set_attrib(&self, py: Python<'_>, attrib: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let attrib =
            attrib.ok_or_else(|| PyTypeError::new_err("an element's attrib cannot be deleted"))?;
        let pairs = attr_pairs(Some(attrib), None)?;
        self.write(py, |d, n| {
            let keys: Vec<String> = d.attrs(n).map(|(k, _)| k.to_owned()).collect();
            for k in keys {
                d.remove_attr(n, &k);
            }
            for (k, v) in &pairs {
                d.set_attr(n, k, v);
            }
            Ok(())
        })
    }

    /// The ``name`` attribute, or ``None``.
    #[getter]
    fn name(&self, py: Python<'_>) -> Option<String> {
        self.read(py, |d, n| d.attr(n, "name").map(str::to_owned))
    }

    /// The value of attribute ``key``, or ``default``.
    #[pyo3(signature = (key, default = None))]
    fn get<'py>(
        &self,
        py: Python<'py>,
        key: &Bound<'py, PyAny>,
        default: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        let value = match key.cast::<PyString>() {
            Ok(k) => {
                let k = k.to_cow()?;
                self.read(py, |d, n| d.attr(n, &k).map(str::to_owned))
            }
            Err(_) => None,
        };
        Ok(match value {
            Some(v) => Some(PyString::new(py, &v).into_any()),
            None => default,
        })
    }

    /// Sets attribute ``key``: a ``str`` as is; ``bool`` as ``true``/``false``; numbers and
    /// sequences of numbers (lists, tuples, numpy arrays) space-separated.
    fn set(&self, py: Python<'_>, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let (key, text) = checked_attr(key, value)?;
        self.write(py, |d, n| {
            d.set_attr(n, &key, &text);
            Ok(())
        })
    }

    /// The attribute names, in order.
    fn keys(&self, py: Python<'_>) -> Vec<String> {
        self.read(py, |d, n| d.attrs(n).map(|(k, _)| k.to_owned()).collect())
    }

    /// This element and its subtree as ``xml.etree.ElementTree.tostring(element,
    /// encoding="unicode")`` writes them (its tail included), or ``None`` where a name is
    /// namespaced (``{uri}local``): what :func:`mjcf_forge.etree.tostring` writes.
    fn _etree_xml(&self, py: Python<'_>) -> Option<String> {
        self.read(py, super::etree_text::etree_xml)
    }

    /// The (name, value) pairs, in order.
    fn items(&self, py: Python<'_>) -> Vec<(String, String)> {
        self.read(py, |d, n| {
            d.attrs(n)
                .map(|(k, v)| (k.to_owned(), v.to_owned()))
                .collect()
        })
    }

    /// Removes every attribute, child element, the text and the tail.
    fn clear(&self, py: Python<'_>) -> PyResult<()> {
        self.write(py, |d, n| {
            d.clear_element(n);
            Ok(())
        })
    }

    /// Removes attribute ``key``; returns whether it was there.
    fn remove_attr(&self, py: Python<'_>, key: &str) -> PyResult<bool> {
        self.write(py, |d, n| Ok(d.remove_attr(n, key)))
    }

    /// The child element at an index (``el[0]``, ``el[-1]``), a list of them for a slice;
    /// for a ``str`` key, the attribute's value (``KeyError`` when missing).
    fn __getitem__<'py>(
        slf: &Bound<'py, Self>,
        key: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if let Ok(k) = key.cast::<PyString>() {
            let k = k.to_cow()?;
            let py = slf.py();
            return match slf.get().read(py, |d, n| d.attr(n, &k).map(str::to_owned)) {
                Some(v) => Ok(PyString::new(py, &v).into_any()),
                None => Err(PyKeyError::new_err(k.into_owned())),
            };
        }
        children::get_item(slf.get(), slf.py(), key)
    }

    /// ``el[i] = child`` and ``el[i:j] = children`` replace child elements; ``el["pos"] =
    /// value`` sets an attribute.
    fn __setitem__(
        &self,
        py: Python<'_>,
        key: &Bound<'_, PyAny>,
        value: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        if let Ok(k) = key.cast::<PyString>() {
            return self.set(py, &k.to_cow()?, value);
        }
        children::set_item(self, py, key, value)
    }

    /// ``del el[i]`` and ``del el[i:j]`` remove child elements; ``del el["pos"]`` an
    /// attribute.
    fn __delitem__(&self, py: Python<'_>, key: &Bound<'_, PyAny>) -> PyResult<()> {
        if let Ok(k) = key.cast::<PyString>() {
            let k = k.to_cow()?;
            return if self.remove_attr(py, &k)? {
                Ok(())
            } else {
                Err(PyKeyError::new_err(k.into_owned()))
            };
        }
        children::del_item(self, py, key)
    }

    /// ``child in el`` for a child element; ``"pos" in el`` for an attribute.
    fn __contains__(&self, py: Python<'_>, item: &Bound<'_, PyAny>) -> PyResult<bool> {
        if let Ok(k) = item.cast::<PyString>() {
            let k = k.to_cow()?;
            return Ok(self.read(py, |d, n| d.attr(n, &k).is_some()));
        }
        let Ok(child) = item.cast::<PyElement>() else {
            return Ok(false);
        };
        let (cell, node) = self.target();
        let (child_cell, child_node) = child.get().target();
        Ok(Arc::ptr_eq(&cell, &child_cell) && cell.read(py).parent(child_node) == Some(node))
    }

    fn __len__(&self, py: Python<'_>) -> usize {
        self.read(py, |d, n| d.elements(n).count())
    }

    /// Whether the element has children, as ElementTree (which warns that this will
    /// change: test ``len(el)`` or ``el is not None``).
    fn __bool__(&self, py: Python<'_>) -> PyResult<bool> {
        PyErr::warn(
            py,
            &py.get_type::<PyDeprecationWarning>(),
            c"Testing an element's truth value will always return True in future versions.  \
              Use specific 'len(elem)' or 'elem is not None' test instead.",
            1,
        )?;
        Ok(self.__len__(py) != 0)
    }

    /// Iterates over the child elements (those there when the iteration starts).
    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(PyList::new(py, self.children(py)?)?.try_iter()?.into_any())
    }

    /// The child elements, in order.
    fn children<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyElement>>> {
        let (cell, node) = self.target();
        let nodes: Vec<Node> = cell.read(py).elements(node).collect();
        proxies(py, &cell, nodes)
    }

    /// Appends ``element`` (an element of this or another document, a new one, or an
    /// ``xml.etree`` element; see the class). Given a tag (``str``) and attributes
    /// instead, makes that new child and returns it.
    #[pyo3(signature = (element, attrib = None))]
    fn append<'py>(
        slf: &Bound<'py, Self>,
        element: &Bound<'py, PyAny>,
        attrib: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyElement>>> {
        children::append(slf, element, attrib)
    }

    /// Appends each element of ``elements``.
    fn extend(&self, py: Python<'_>, elements: &Bound<'_, PyAny>) -> PyResult<()> {
        children::extend(self, py, elements)
    }

    /// Inserts ``element`` before child element number ``index`` (as ``list.insert``).
    fn insert(&self, py: Python<'_>, index: isize, element: &Bound<'_, PyAny>) -> PyResult<()> {
        children::insert(self, py, index, element)
    }

    /// Removes the child element ``element`` (``ValueError`` when it is not a child); the
    /// removed element stays usable, detached. Without an argument, removes this element
    /// from its parent.
    #[pyo3(signature = (element = None))]
    fn remove(&self, py: Python<'_>, element: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        children::remove(self, py, element)
    }

    /// A new element (``Element(tag, attrib)``), in no document yet.
    fn makeelement<'py>(
        &self,
        py: Python<'py>,
        tag: &str,
        attrib: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyElement>> {
        new_element(py, tag, Some(attrib), None)
    }

    /// The first element matching the ElementPath ``path``, or ``None``.
    #[pyo3(signature = (path, namespaces = None))]
    fn find<'py>(
        slf: &Bound<'py, Self>,
        path: &str,
        namespaces: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        path::find(slf, path, namespaces)
    }

    /// Every element matching the ElementPath ``path``, in document order.
    #[pyo3(signature = (path, namespaces = None))]
    fn findall<'py>(
        slf: &Bound<'py, Self>,
        path: &str,
        namespaces: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        path::findall(slf, path, namespaces)
    }

    /// An iterator over the elements matching the ElementPath ``path``.
    #[pyo3(signature = (path, namespaces = None))]
    fn iterfind<'py>(
        slf: &Bound<'py, Self>,
        path: &str,
        namespaces: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        path::iterfind(slf, path, namespaces)
    }

    /// The text of the first element matching ``path`` (``""`` when it has none), or
    /// ``default`` when nothing matches.
    #[pyo3(signature = (path, default = None, namespaces = None))]
    fn findtext<'py>(
        slf: &Bound<'py, Self>,
        path: &str,
        default: Option<Bound<'py, PyAny>>,
        namespaces: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        path::findtext(slf, path, default, namespaces)
    }

    /// An iterator over this element and every element below it (document order), only
    /// those tagged ``tag`` when given (``"*"``: all).
    #[pyo3(signature = (tag = None))]
    fn iter<'py>(&self, py: Python<'py>, tag: Option<&str>) -> PyResult<Bound<'py, PyAny>> {
        path::iter(self, py, tag)
    }

    /// An iterator over the character data inside this element, in document order.
    fn itertext<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pieces: Vec<String> = self.read(py, |d, n| {
            d.text_pieces(n)
                .into_iter()
                .map(|p| p.into_owned())
                .collect()
        });
        Ok(PyList::new(py, pieces)?.try_iter()?.into_any())
    }

    /// The first element below this one (itself included) tagged ``kind`` and, when given,
    /// named ``name``; ``None`` when there is none.
    #[pyo3(signature = (kind, name = None))]
    fn find_named<'py>(
        &self,
        py: Python<'py>,
        kind: &str,
        name: Option<&str>,
    ) -> PyResult<Option<Bound<'py, PyElement>>> {
        let (cell, node) = self.target();
        let found = path::named(&cell.read(py), node, Some(kind), name).next();
        found.map(|n| proxy(py, &cell, n)).transpose()
    }

    /// Every element below this one (itself included) tagged ``kind`` (any tag when
    /// ``None``) and, when given, named ``name``.
    #[pyo3(signature = (kind = None, name = None))]
    fn find_all_named<'py>(
        &self,
        py: Python<'py>,
        kind: Option<&str>,
        name: Option<&str>,
    ) -> PyResult<Vec<Bound<'py, PyElement>>> {
        let (cell, node) = self.target();
        let nodes: Vec<Node> = path::named(&cell.read(py), node, kind, name).collect();
        proxies(py, &cell, nodes)
    }

    /// The parent element (``None`` for the root, and for an element not in a tree).
    #[getter]
    fn parent<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyElement>>> {
        let (cell, node) = self.target();
        let parent = cell.read(py).parent(node);
        parent.map(|p| proxy(py, &cell, p)).transpose()
    }

    /// ``mjcf_forge._mjcf_utils.sort_elements(self, self.parent)``'s default path in one
    /// native pass (the element sort of ``Document._sort_elements``, over the elements
    /// under this one, itself included): a dict of the keys, in the order they first
    /// appear, to their elements in document order, and one of the same keys to those
    /// elements' names (None for an unnamed one); unnamed geoms of groups 0 and 1 named
    /// ``g{n}_col`` / ``g{n}_vis`` first when ``name_geoms``.
    #[pyo3(signature = (name_geoms = false))]
    fn _sort_elements<'py>(
        &self,
        py: Python<'py>,
        name_geoms: bool,
    ) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
        let (cell, node) = self.target();
        super::sort::sorted_dicts(py, &cell, node, name_geoms)
    }

    /// Where the element was read: ``file:line:col`` (with ``(included from ...)`` when
    /// it came from an included file).
    #[getter]
    fn location(&self, py: Python<'_>) -> String {
        let loc = self.read(py, |d, n| d.location(n));
        let mut text = loc.to_string();
        for (file, line, col) in loc.included_from.iter().rev() {
            text.push_str(&format!(" (included from {}:{line}:{col})", file.display()));
        }
        text
    }

    /// A copy of the element and everything below it, detached (in a document of its
    /// own): as lxml, ``copy.copy`` copies the children too, since an element of a tree
    /// has one parent. The copy has no tail.
    fn __copy__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyElement>> {
        let (doc, _) = self.read(py, |d, n| d.element_document(n));
        let root = doc.root();
        proxy(py, &DocCell::new(doc), root)
    }

    fn __deepcopy__<'py>(
        &self,
        py: Python<'py>,
        _memo: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyElement>> {
        self.__copy__(py)
    }

    /// Pickling (multiprocessing, Ray) goes through the element's XML, read back by
    /// ``mjcf_forge.etree`` as a new, detached element: the same tag, attributes, text and
    /// children, and, as a copy, no tail (the text after an element lives in its parent).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let xml = self.read(py, |d, n| d.element_document(n).0.to_xml_string());
        let rebuild = crate::upcalls::get(py, "fromstring")?;
        let args = PyTuple::new(py, [xml])?;
        PyTuple::new(py, [rebuild, args.into_any()])
    }

    fn __repr__(slf: &Bound<'_, Self>) -> String {
        let (tag, name) = slf.get().read(slf.py(), |d, n| {
            (d.tag(n).to_owned(), d.attr(n, "name").map(str::to_owned))
        });
        let at = slf.as_ptr() as usize;
        match name {
            Some(name) => format!("<Element '{tag}' name='{name}' at {at:#x}>"),
            None => format!("<Element '{tag}' at {at:#x}>"),
        }
    }
}
