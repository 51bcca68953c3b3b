//! `Document` and `Element`: the document tier, with ElementTree-like element access.
//!
//! A `Document` owns its `mjcf_forge::Document` behind an `Arc<RwLock<..>>`: Python threads
//! may share one, readers run at once, and an `Element` keeps the document alive by holding
//! the same `Arc`. Locks are only held by Rust code that never waits for the GIL, so
//! taking one with the GIL held cannot deadlock.

use std::path::PathBuf;
use std::sync::{Arc, RwLock};

use mjcf_forge::{Document, MergeOptions, Node, Section};
use pyo3::exceptions::{PyKeyError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};

use crate::errors::{Failure, catch, read, run, write};

/// A shared, lockable document.
pub(crate) type SharedDoc = Arc<RwLock<Document>>;

/// An MJCF model as MuJoCo reads it: ``<include>`` expanded, default classes inlined
/// into explicit attributes, asset file paths absolute.
///
/// Load one with :meth:`Document.load` or :meth:`Document.from_string`; edit it in place
/// (:meth:`prefix`, :meth:`merge`, element attributes); write it with :meth:`to_xml` or
/// :meth:`write`. Safe to share between threads; loading, writing, prefixing, merging and
/// validating release the GIL.
///
/// Example::
///
///     doc = Document.load("panda.xml")
///     doc.prefix("robot0_")
///     hand = doc.find("body", "robot0_right_hand")
///     hand.set("pos", [0, 0, 0.1])
///     doc.write("out.xml")
#[pyclass(name = "Document", module = "mjcf_forge", frozen)]
pub(crate) struct PyDocument {
    pub(crate) doc: SharedDoc,
}

impl PyDocument {
    pub(crate) fn new(doc: Document) -> PyDocument {
        PyDocument {
            doc: Arc::new(RwLock::new(doc)),
        }
    }

    /// A copy of the Rust document (for parts that are merged or wrapped by a model).
    pub(crate) fn snapshot(&self) -> Document {
        read(&self.doc).clone()
    }
}

/// What a merge did besides merging.
#[pyclass(name = "MergeReport", module = "mjcf_forge", frozen, get_all)]
pub(crate) struct PyMergeReport {
    /// One line per part setting the base overrode or adjusted (``option``, ``size``,
    /// ``visual``, ``statistic`` conflicts), each with its position in the part.
    warnings: Vec<String>,
    /// How many of the part's assets were already in the base (same tag, name and
    /// content) and are shared rather than copied.
    shared_assets: usize,
}

#[pymethods]
impl PyMergeReport {
    fn __repr__(&self) -> String {
        format!(
            "MergeReport(warnings={:?}, shared_assets={})",
            self.warnings, self.shared_assets
        )
    }
}

impl From<mjcf_forge::MergeReport> for PyMergeReport {
    fn from(report: mjcf_forge::MergeReport) -> PyMergeReport {
        PyMergeReport {
            warnings: report.warnings,
            shared_assets: report.shared_assets,
        }
    }
}

#[pymethods]
impl PyDocument {
    /// Loads an MJCF file (``str`` or path-like) as MuJoCo reads it.
    ///
    /// Raises :class:`MjcfError` with every problem found (``file:line:col: message``).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyDocument> {
        run(py, || Ok(Document::load(&path)?)).map(PyDocument::new)
    }

    /// Reads MJCF text. ``base_dir`` plays the part of the main file's folder: includes
    /// and asset files are found from there (default: the current folder). Positions in
    /// errors name ``<string>``.
    #[staticmethod]
    #[pyo3(signature = (xml, base_dir = None))]
    fn from_string(py: Python<'_>, xml: &str, base_dir: Option<PathBuf>) -> PyResult<PyDocument> {
        let xml = xml.to_owned();
        let base_dir = base_dir.unwrap_or_else(|| PathBuf::from("."));
        run(py, move || Ok(Document::from_str(&xml, &base_dir)?)).map(PyDocument::new)
    }

    /// The document as XML text: compact (no white space between elements) by default,
    /// indented by two spaces a level with ``pretty=True`` (what :meth:`write` writes and
    /// what ``mjcf-forge inline`` prints).
    #[pyo3(signature = (pretty = false))]
    fn to_xml(&self, py: Python<'_>, pretty: bool) -> PyResult<String> {
        run(py, || {
            let doc = read(&self.doc);
            Ok(if pretty {
                doc.to_pretty_string()
            } else {
                doc.to_xml_string()
            })
        })
    }

    /// Writes the indented XML to ``path`` atomically: through a temporary file in the
    /// same folder and a rename, so a failure never leaves a partial or clobbered file.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        run(py, || Ok(read(&self.doc).write_file(&path)?))
    }

    /// Prefixes every name in place (bodies, joints, geoms, assets, classes, ...) and every
    /// reference to it, following MuJoCo's schema; references to ``world`` stay.
    fn prefix(&self, py: Python<'_>, prefix: &str) -> PyResult<()> {
        check_xml_text("prefix", prefix)?;
        let prefix = prefix.to_owned();
        run(py, || Ok(write(&self.doc).apply_prefix(&prefix)?))
    }

    /// Merges ``other`` into this document, in place: its worldbody children into the
    /// world (``body=None``) or into the body named ``body``, every other section carried
    /// over (identical assets shared, compiler settings converted where exact).
    ///
    /// ``fuse_keys`` makes the part's keyframe ``part_prefix + N`` one with this
    /// document's key ``N`` (``part_prefix``: the prefix the part's names carry). Returns a :class:`MergeReport`; raises :class:`MjcfError`
    /// (all name clashes at once, with positions), leaving this document unchanged.
    #[pyo3(signature = (other, body = None, *, fuse_keys = false, part_prefix = None))]
    fn merge(
        &self,
        py: Python<'_>,
        other: &PyDocument,
        body: Option<String>,
        fuse_keys: bool,
        part_prefix: Option<String>,
    ) -> PyResult<PyMergeReport> {
        let options = MergeOptions {
            fuse_keys,
            part_prefix: part_prefix.unwrap_or_default(),
        };
        run(py, || {
            // A copy of the part first: it may be this very document (merging a model with
            // itself), and two locks on one RwLock would deadlock.
            let part = read(&other.doc).clone();
            let mut doc = write(&self.doc);
            // Merge into a copy so that a refused merge leaves the document as it was.
            let mut merged = doc.clone();
            let report = merged.merge(&part, body.as_deref(), &options)?;
            *doc = merged;
            Ok(report)
        })
        .map(PyMergeReport::from)
    }

    /// Checks names: duplicates within a namespace and references to nothing. Raises
    /// :class:`MjcfError` listing every problem with its position.
    fn validate(&self, py: Python<'_>) -> PyResult<()> {
        run(py, || Ok(read(&self.doc).validate()?))
    }

    /// An independent copy (cheap: a few flat buffers).
    fn copy(&self, py: Python<'_>) -> PyResult<PyDocument> {
        run(py, || Ok(self.snapshot())).map(PyDocument::new)
    }

    fn __copy__(&self, py: Python<'_>) -> PyResult<PyDocument> {
        self.copy(py)
    }

    fn __deepcopy__(&self, py: Python<'_>, _memo: &Bound<'_, PyAny>) -> PyResult<PyDocument> {
        self.copy(py)
    }

    /// Pickling (Ray, multiprocessing) goes through the XML text and the model folder: the
    /// text is already inlined with absolute paths, so reading it back gives the same model.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let (xml, dir) = run(py, || {
            let doc = read(&self.doc);
            Ok((doc.to_xml_string(), doc.model_dir().to_path_buf()))
        })?;
        let from_string = py.get_type::<PyDocument>().getattr("from_string")?;
        PyTuple::new(
            py,
            [
                from_string,
                PyTuple::new(
                    py,
                    [
                        xml.into_pyobject(py)?.into_any(),
                        dir.into_pyobject(py)?.into_any(),
                    ],
                )?
                .into_any(),
            ],
        )
    }

    /// The ``model`` attribute of ``<mujoco>``, or ``None``.
    #[getter]
    fn model_name(&self) -> Option<String> {
        read(&self.doc).model_name().map(str::to_owned)
    }

    /// The folder of the main file (includes and relative asset paths were resolved from it).
    #[getter]
    fn model_dir(&self) -> PathBuf {
        read(&self.doc).model_dir().to_path_buf()
    }

    /// The root ``<mujoco>`` element.
    #[getter]
    fn root(&self) -> PyElement {
        let root = read(&self.doc).root();
        self.element(root)
    }

    /// The ``<worldbody>`` element (created, empty, when the model has none).
    #[getter]
    fn worldbody(&self) -> PyResult<PyElement> {
        self.section("worldbody")
    }

    /// The top-level section with this tag (``"asset"``, ``"actuator"``, ``"sensor"``, ...),
    /// created empty at the end when the model has none. Repeated sections were already
    /// merged into one at load, as MuJoCo reads them all in order.
    fn section(&self, tag: &str) -> PyResult<PyElement> {
        let section = Section::from_tag(tag).ok_or_else(|| {
            Failure(vec![format!(
                "'{tag}' is not a section of an MJCF model (asset, worldbody, actuator, ...)"
            )])
        })?;
        let node = write(&self.doc).section(section);
        Ok(self.element(node))
    }

    /// The first element (document order) whose tag is ``kind`` (``"body"``, ``"geom"``,
    /// ``"joint"``, ``"mesh"``, ...) and, when given, whose ``name`` is ``name``; ``None``
    /// when there is none.
    #[pyo3(signature = (kind, name = None))]
    fn find(&self, kind: &str, name: Option<&str>) -> Option<PyElement> {
        let doc = read(&self.doc);
        let found = find_nodes(&doc, doc.root(), Some(kind), name).next();
        drop(doc);
        found.map(|n| self.element(n))
    }

    /// Every element (document order) whose tag is ``kind`` (any tag when ``None``) and,
    /// when given, whose ``name`` is ``name``.
    #[pyo3(signature = (kind = None, name = None))]
    fn find_all(&self, kind: Option<&str>, name: Option<&str>) -> Vec<PyElement> {
        let doc = read(&self.doc);
        let nodes: Vec<Node> = find_nodes(&doc, doc.root(), kind, name).collect();
        drop(doc);
        nodes.into_iter().map(|n| self.element(n)).collect()
    }

    fn __repr__(&self) -> String {
        let doc = read(&self.doc);
        format!(
            "<mjcf_forge.Document model={:?} dir={:?} nodes={}>",
            doc.model_name().unwrap_or(""),
            doc.model_dir().display().to_string(),
            doc.node_count()
        )
    }
}

impl PyDocument {
    fn element(&self, node: Node) -> PyElement {
        PyElement {
            doc: self.doc.clone(),
            node,
        }
    }
}

/// Elements below `from` (itself included) matching an optional tag and name.
fn find_nodes<'a>(
    doc: &'a Document,
    from: Node,
    kind: Option<&'a str>,
    name: Option<&'a str>,
) -> impl Iterator<Item = Node> + 'a {
    doc.descendants(from).filter(move |&n| {
        kind.is_none_or(|k| doc.tag(n) == k) && name.is_none_or(|w| doc.attr(n, "name") == Some(w))
    })
}

/// One element of a :class:`Document`, with an interface close to
/// ``xml.etree.ElementTree.Element`` (what robosuite code edits): ``tag``, ``attrib``,
/// ``get``, ``set``, ``[key]``, iteration over child elements, ``iter``.
///
/// Attribute values are MJCF text; :meth:`set` also takes numbers, booleans and sequences
/// of numbers (written as MuJoCo reads them: ``[0, 0.5, 1]`` becomes ``"0 0.5 1"``).
/// Changes are made in the document itself. An element keeps its document alive.
#[pyclass(name = "Element", module = "mjcf_forge", frozen)]
pub(crate) struct PyElement {
    doc: SharedDoc,
    node: Node,
}

#[pymethods]
impl PyElement {
    /// The element's tag (``"body"``, ``"geom"``, ...).
    #[getter]
    fn tag(&self) -> String {
        read(&self.doc).tag(self.node).to_owned()
    }

    /// The ``name`` attribute, or ``None``.
    #[getter]
    fn name(&self) -> Option<String> {
        self.get("name", None)
    }

    /// A new ``dict`` of the attributes, in document order (changing it changes nothing:
    /// use :meth:`set`).
    #[getter]
    fn attrib<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let pairs: Vec<(String, String)> = read(&self.doc)
            .attrs(self.node)
            .map(|(k, v)| (k.to_owned(), v.to_owned()))
            .collect();
        let dict = PyDict::new(py);
        for (k, v) in pairs {
            dict.set_item(k, v)?;
        }
        Ok(dict)
    }

    /// The value of attribute ``key``, or ``default``.
    #[pyo3(signature = (key, default = None))]
    fn get(&self, key: &str, default: Option<String>) -> Option<String> {
        read(&self.doc)
            .attr(self.node, key)
            .map(str::to_owned)
            .or(default)
    }

    /// Sets attribute ``key``: a ``str`` as is; ``bool`` as ``true``/``false``; numbers and
    /// sequences of numbers (lists, tuples, numpy arrays) space-separated.
    fn set(&self, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let text = attr_text(value)?;
        check_xml_name("attribute name", key)?;
        check_xml_text("attribute value", &text)?;
        catch(|| {
            write(&self.doc).set_attr(self.node, key, &text);
            Ok(())
        })?;
        Ok(())
    }

    /// The attribute names, in order.
    fn keys(&self) -> Vec<String> {
        read(&self.doc)
            .attrs(self.node)
            .map(|(k, _)| k.to_owned())
            .collect()
    }

    /// The (name, value) pairs, in order.
    fn items(&self) -> Vec<(String, String)> {
        read(&self.doc)
            .attrs(self.node)
            .map(|(k, v)| (k.to_owned(), v.to_owned()))
            .collect()
    }

    fn __getitem__(&self, key: &str) -> PyResult<String> {
        self.get(key, None)
            .ok_or_else(|| PyKeyError::new_err(key.to_owned()))
    }

    fn __setitem__(&self, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set(key, value)
    }

    fn __delitem__(&self, key: &str) -> PyResult<()> {
        if write(&self.doc).remove_attr(self.node, key) {
            Ok(())
        } else {
            Err(PyKeyError::new_err(key.to_owned()))
        }
    }

    fn __contains__(&self, key: &str) -> bool {
        read(&self.doc).attr(self.node, key).is_some()
    }

    /// Removes attribute ``key``; returns whether it was there.
    fn remove_attr(&self, key: &str) -> bool {
        write(&self.doc).remove_attr(self.node, key)
    }

    /// The child elements, in order.
    fn children(&self) -> Vec<PyElement> {
        let nodes: Vec<Node> = read(&self.doc).elements(self.node).collect();
        nodes.into_iter().map(|n| self.at(n)).collect()
    }

    fn __iter__(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let list = pyo3::types::PyList::new(py, self.children())?;
        Ok(list.try_iter()?.into_any().unbind())
    }

    fn __len__(&self) -> usize {
        read(&self.doc).elements(self.node).count()
    }

    /// This element and every element below it (document order), only those tagged
    /// ``kind`` when given.
    #[pyo3(signature = (kind = None))]
    fn iter(&self, kind: Option<&str>) -> Vec<PyElement> {
        let doc = read(&self.doc);
        let nodes: Vec<Node> = find_nodes(&doc, self.node, kind, None).collect();
        drop(doc);
        nodes.into_iter().map(|n| self.at(n)).collect()
    }

    /// The first element below this one (itself included) tagged ``kind`` and, when given,
    /// named ``name``; ``None`` when there is none.
    #[pyo3(signature = (kind, name = None))]
    fn find(&self, kind: &str, name: Option<&str>) -> Option<PyElement> {
        let doc = read(&self.doc);
        let found = find_nodes(&doc, self.node, Some(kind), name).next();
        drop(doc);
        found.map(|n| self.at(n))
    }

    /// Every element below this one (itself included) tagged ``kind`` (any tag when
    /// ``None``) and, when given, named ``name``.
    #[pyo3(signature = (kind = None, name = None))]
    fn find_all(&self, kind: Option<&str>, name: Option<&str>) -> Vec<PyElement> {
        let doc = read(&self.doc);
        let nodes: Vec<Node> = find_nodes(&doc, self.node, kind, name).collect();
        drop(doc);
        nodes.into_iter().map(|n| self.at(n)).collect()
    }

    /// The parent element (``None`` for the root).
    #[getter]
    fn parent(&self) -> Option<PyElement> {
        let parent = read(&self.doc).parent(self.node);
        parent.map(|n| self.at(n))
    }

    /// Where the element was read: ``file:line:col`` (with ``(included from ...)`` when
    /// it came from an included file).
    #[getter]
    fn location(&self) -> String {
        let loc = read(&self.doc).location(self.node);
        let mut text = loc.to_string();
        for (file, line, col) in loc.included_from.iter().rev() {
            text.push_str(&format!(" (included from {}:{line}:{col})", file.display()));
        }
        text
    }

    /// Appends a new child element with tag ``tag`` and attributes ``attrib`` (values as
    /// :meth:`set` takes them); returns it.
    #[pyo3(signature = (tag, attrib = None))]
    fn append(&self, tag: &str, attrib: Option<&Bound<'_, PyDict>>) -> PyResult<PyElement> {
        check_xml_name("tag", tag)?;
        let mut pairs = Vec::new();
        if let Some(attrib) = attrib {
            for (k, v) in attrib.iter() {
                let (k, v) = (k.extract::<String>()?, attr_text(&v)?);
                check_xml_name("attribute name", &k)?;
                check_xml_text("attribute value", &v)?;
                pairs.push((k, v));
            }
        }
        let refs: Vec<(&str, &str)> = pairs
            .iter()
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect();
        let node = write(&self.doc).append_element(self.node, tag, &refs);
        Ok(self.at(node))
    }

    /// Takes this element (and everything below it) out of the document.
    fn remove(&self) {
        write(&self.doc).remove(self.node);
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyElement>()
            .is_ok_and(|o| Arc::ptr_eq(&o.get().doc, &self.doc) && o.get().node == self.node)
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (Arc::as_ptr(&self.doc) as usize).hash(&mut h);
        self.node.hash(&mut h);
        h.finish()
    }

    fn __repr__(&self) -> String {
        let doc = read(&self.doc);
        let tag = doc.tag(self.node);
        match doc.attr(self.node, "name") {
            Some(name) => format!("<Element {tag} name={name:?}>"),
            None => format!("<Element {tag}>"),
        }
    }
}

impl PyElement {
    fn at(&self, node: Node) -> PyElement {
        PyElement {
            doc: self.doc.clone(),
            node,
        }
    }
}

/// Refuses a tag or attribute name that XML cannot carry (the library writes names as
/// given, and a file with `<bad tag>` in it would not read back).
pub(crate) fn check_xml_name(what: &str, name: &str) -> Result<(), Failure> {
    let start_ok = |c: char| c.is_alphabetic() || c == '_' || c == ':';
    let ok = name.chars().next().is_some_and(start_ok)
        && name
            .chars()
            .all(|c| start_ok(c) || c.is_alphanumeric() || matches!(c, '-' | '.'));
    if ok {
        Ok(())
    } else {
        Err(Failure(vec![format!("{what} {name:?} is not an XML name")]))
    }
}

/// Refuses text XML 1.0 cannot carry (NUL and the other control characters but tab and
/// line ends): written out, it would make a file that neither we nor MuJoCo can read.
pub(crate) fn check_xml_text(what: &str, text: &str) -> Result<(), Failure> {
    match text
        .chars()
        .find(|&c| c.is_control() && !matches!(c, '\t' | '\n' | '\r'))
    {
        None => Ok(()),
        Some(c) => Err(Failure(vec![format!(
            "{what} {text:?} holds the character U+{:04X}, which XML cannot carry",
            c as u32
        )])),
    }
}

/// MJCF text for an attribute value given from Python.
fn attr_text(value: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(s) = value.cast::<PyString>() {
        return Ok(s.to_cow()?.into_owned());
    }
    if let Some(text) = number_text(value) {
        return Ok(text);
    }
    if let Ok(iter) = value.try_iter() {
        let mut parts = Vec::new();
        for item in iter {
            let item = item?;
            parts.push(number_text(&item).ok_or_else(|| {
                PyTypeError::new_err(format!(
                    "attribute values are str, bool, numbers or sequences of numbers; found a {} in the sequence",
                    item.get_type().name().map(|n| n.to_string()).unwrap_or_default()
                ))
            })?);
        }
        return Ok(parts.join(" "));
    }
    Err(PyTypeError::new_err(format!(
        "attribute values are str, bool, numbers or sequences of numbers, not {}",
        value
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_default()
    )))
}

/// A number (or bool) as MuJoCo reads it; `None` for anything else.
fn number_text(value: &Bound<'_, PyAny>) -> Option<String> {
    if let Ok(b) = value.cast::<pyo3::types::PyBool>() {
        return Some(if b.is_true() { "true" } else { "false" }.to_owned());
    }
    // Integers first (numpy integers too, through __index__), so 3 stays "3".
    if let Ok(i) = value.extract::<i64>() {
        return Some(i.to_string());
    }
    // Rust's shortest round-trip form, with an exponent for large or small magnitudes.
    value.extract::<f64>().ok().map(|x| {
        let text = format!("{x:?}");
        text.strip_suffix(".0").map(str::to_owned).unwrap_or(text)
    })
}
