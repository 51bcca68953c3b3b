//! Child elements as ElementTree edits them: `append`, `extend`, `insert`, `remove`, and
//! indexing and slicing (`el[0]`, `el[1:3] = [...]`, `del el[-1]`).
//!
//! What comes in is sorted first ([`prepare`]): an element of the same document is moved
//! (ElementTree has no parent pointers and would let it sit in two places; robosuite's code
//! means "move it here"), an element of another document is copied in and its handles
//! follow the copy (and the other document's view of it is the copy from then on: see
//! `cell::alias`), and an element of another ElementTree implementation (`xml.etree`,
//! lxml) is copied in. Positions count child elements once the moved element has left its
//! old place.

use std::sync::Arc;

use mjcf_forge::{Document, Node};
use pyo3::exceptions::{PyIndexError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyList, PySlice, PyString};

use super::cell::{DocCell, alias, proxies, proxy, retarget};
use super::element::PyElement;
use super::values::{attr_pairs, check_xml_name, check_xml_text};
use crate::errors::{Failure, catch};

/// An element about to become a child.
enum Incoming {
    /// Of the same document: moved.
    Same(Node),
    /// Of another document (or a new element): copied in.
    Other(Arc<DocCell>, Node),
    /// Of another ElementTree implementation: copied in, in document order.
    Foreign(Vec<Flat>),
}

/// One element of a foreign tree, read out before the document is locked.
struct Flat {
    tag: String,
    attrs: Vec<(String, String)>,
    text: Option<String>,
    tail: Option<String>,
    /// Index of the parent in the list; `None` for the top.
    parent: Option<usize>,
}

fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default()
}

/// Sorts `item` for a place under `parent` of `cell`, refusing what cannot go there
/// before anything changes.
fn prepare(
    py: Python<'_>,
    cell: &Arc<DocCell>,
    parent: Node,
    item: &Bound<'_, PyAny>,
) -> PyResult<Incoming> {
    if let Ok(el) = item.cast::<PyElement>() {
        let (c, n) = el.get().target();
        if !Arc::ptr_eq(&c, cell) {
            return Ok(Incoming::Other(c, n));
        }
        let doc = cell.read(py);
        if n == doc.root() || doc.contains_node(n, parent) {
            return Err(PyValueError::new_err(format!(
                "cannot put <{}> into <{}>: an element cannot go into itself, below itself, \
                 or out of its place as the document's root",
                doc.tag(n),
                doc.tag(parent)
            )));
        }
        return Ok(Incoming::Same(n));
    }
    if item.hasattr("tag")? && !item.is_instance_of::<PyString>() {
        return Ok(Incoming::Foreign(flatten(item)?));
    }
    Err(PyTypeError::new_err(format!(
        "expected an Element (of mjcf_forge or xml.etree), not {}",
        type_name(item)
    )))
}

/// Text or tail of a foreign element; white space alone is dropped, as the reader drops it
/// from files (an indented file's layout is no content of an MJCF model).
fn foreign_text(el: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<String>> {
    let value = el.getattr(what)?;
    if value.is_none() {
        return Ok(None);
    }
    let text = value
        .cast::<PyString>()
        .map_err(|_| PyTypeError::new_err(format!("an element's {what} is a str or None")))?
        .to_cow()?
        .into_owned();
    if text.trim().is_empty() {
        return Ok(None);
    }
    check_xml_text(what, &text)?;
    Ok(Some(text))
}

/// A foreign element and everything below it, in document order. Comments and processing
/// instructions inside it (elements whose tag is not a `str`) are left out: an MJCF
/// document holds neither.
fn flatten(top: &Bound<'_, PyAny>) -> PyResult<Vec<Flat>> {
    let mut out = Vec::new();
    let mut stack: Vec<(Bound<'_, PyAny>, Option<usize>)> = vec![(top.clone(), None)];
    while let Some((el, parent)) = stack.pop() {
        let tag = el.getattr("tag")?;
        let Ok(tag) = tag.cast::<PyString>() else {
            if parent.is_none() {
                return Err(PyTypeError::new_err(
                    "comments and processing instructions have no place in an MJCF document",
                ));
            }
            continue;
        };
        let tag = tag.to_cow()?.into_owned();
        check_xml_name("tag", &tag)?;
        let attrs = attr_pairs(Some(&el.getattr("attrib")?), None)?;
        let me = out.len();
        out.push(Flat {
            tag,
            attrs,
            text: foreign_text(&el, "text")?,
            tail: foreign_text(&el, "tail")?,
            parent,
        });
        let kids: Vec<Bound<'_, PyAny>> = el.try_iter()?.collect::<PyResult<_>>()?;
        stack.extend(kids.into_iter().rev().map(|k| (k, Some(me))));
    }
    Ok(out)
}

/// Builds a flattened foreign tree as child element number `index` of `parent`.
fn build(doc: &mut Document, parent: Node, index: usize, flat: &[Flat]) -> Result<(), Failure> {
    let mut made: Vec<Node> = Vec::with_capacity(flat.len());
    for f in flat {
        let at = f.parent.map_or(parent, |i| made[i]);
        let attrs: Vec<(&str, &str)> = f
            .attrs
            .iter()
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect();
        let n = doc.append_element(at, &f.tag, &attrs);
        doc.set_element_text(n, f.text.as_deref());
        made.push(n);
    }
    for (f, &n) in flat.iter().zip(&made) {
        if f.tail.is_some() {
            doc.set_element_tail(n, f.tail.as_deref())?;
        }
    }
    doc.insert_element(parent, index, made[0])?;
    Ok(())
}

/// Puts a prepared element in place: child element number `index` of `parent`.
fn commit(
    py: Python<'_>,
    cell: &Arc<DocCell>,
    parent: Node,
    index: usize,
    incoming: Incoming,
) -> PyResult<()> {
    match incoming {
        Incoming::Same(n) => {
            let mut doc = cell.write(py);
            catch(|| Ok(doc.insert_element(parent, index, n)?))?;
        }
        Incoming::Other(from, n) => {
            let map = {
                let (src, mut dst) = DocCell::read_and_write(py, &from, cell);
                catch(|| Ok(dst.copy_element_from(&src, n, parent, index)))?
            };
            retarget(py, &from, cell, &map);
            alias(py, &from, cell, &map);
        }
        Incoming::Foreign(flat) => {
            let mut doc = cell.write(py);
            catch(|| build(&mut doc, parent, index, &flat))?;
        }
    }
    Ok(())
}

/// A Python index (negative from the end) into `len` children, clamped as `list.insert`.
fn clamp(index: isize, len: usize) -> usize {
    let len = len as isize;
    (if index < 0 { len + index } else { index }).clamp(0, len) as usize
}

/// A Python index into `len` children, or `IndexError`.
fn checked(index: isize, len: usize, what: &str) -> PyResult<usize> {
    let i = if index < 0 {
        index + len as isize
    } else {
        index
    };
    if (0..len as isize).contains(&i) {
        Ok(i as usize)
    } else {
        Err(PyIndexError::new_err(format!(
            "child {what}index out of range"
        )))
    }
}

fn child_nodes(py: Python<'_>, cell: &DocCell, parent: Node) -> Vec<Node> {
    cell.read(py).elements(parent).collect()
}

pub(crate) fn append<'py>(
    slf: &Bound<'py, PyElement>,
    element: &Bound<'py, PyAny>,
    attrib: Option<&Bound<'py, PyAny>>,
) -> PyResult<Option<Bound<'py, PyElement>>> {
    let py = slf.py();
    let (cell, parent) = slf.get().target();
    if let Ok(tag) = element.cast::<PyString>() {
        let tag = tag.to_cow()?;
        check_xml_name("tag", &tag)?;
        let pairs = attr_pairs(attrib, None)?;
        let refs: Vec<(&str, &str)> = pairs
            .iter()
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect();
        let node = catch(|| Ok(cell.write(py).append_element(parent, &tag, &refs)))?;
        return proxy(py, &cell, node).map(Some);
    }
    if attrib.is_some() {
        return Err(PyTypeError::new_err(
            "append(element) takes attributes only with a tag: append(tag, attrib)",
        ));
    }
    let incoming = prepare(py, &cell, parent, element)?;
    commit(py, &cell, parent, usize::MAX, incoming)?;
    Ok(None)
}

pub(crate) fn extend(el: &PyElement, py: Python<'_>, elements: &Bound<'_, PyAny>) -> PyResult<()> {
    let (cell, parent) = el.target();
    // Read out first: the items may be this element's own children, which move.
    let items: Vec<Bound<'_, PyAny>> = elements.try_iter()?.collect::<PyResult<_>>()?;
    for item in items {
        let incoming = prepare(py, &cell, parent, &item)?;
        commit(py, &cell, parent, usize::MAX, incoming)?;
    }
    Ok(())
}

pub(crate) fn insert(
    el: &PyElement,
    py: Python<'_>,
    index: isize,
    element: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let (cell, parent) = el.target();
    let incoming = prepare(py, &cell, parent, element)?;
    let moving = match incoming {
        Incoming::Same(n) => Some(n),
        _ => None,
    };
    let len = child_nodes(py, &cell, parent)
        .into_iter()
        .filter(|&c| Some(c) != moving)
        .count();
    commit(py, &cell, parent, clamp(index, len), incoming)
}

pub(crate) fn remove(
    el: &PyElement,
    py: Python<'_>,
    element: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let (cell, node) = el.target();
    let Some(element) = element else {
        // Without an argument: this element leaves its parent (if it has one).
        let mut doc = cell.write(py);
        if doc.parent(node).is_some() {
            doc.remove_element(node);
        }
        return Ok(());
    };
    let not_a_child = || PyValueError::new_err("list.remove(x): x not in list");
    let child = element.cast::<PyElement>().map_err(|_| not_a_child())?;
    let (child_cell, child_node) = child.get().target();
    if !Arc::ptr_eq(&cell, &child_cell) {
        return Err(not_a_child());
    }
    let mut doc = cell.write(py);
    if doc.parent(child_node) != Some(node) {
        return Err(not_a_child());
    }
    doc.remove_element(child_node);
    Ok(())
}

/// The indices a slice selects from `len` children, in its order.
fn slice_indices(slice: &Bound<'_, PySlice>, len: usize) -> PyResult<Vec<usize>> {
    let s = slice.indices(len as isize)?;
    Ok((0..s.slicelength)
        .map(|k| (s.start + k as isize * s.step) as usize)
        .collect())
}

fn index_of(key: &Bound<'_, PyAny>) -> PyResult<isize> {
    key.extract::<isize>().map_err(|_| {
        PyTypeError::new_err(format!(
            "element indices must be integers, slices or attribute names (str), not {}",
            type_name(key)
        ))
    })
}

pub(crate) fn get_item<'py>(
    el: &PyElement,
    py: Python<'py>,
    key: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let (cell, parent) = el.target();
    let kids = child_nodes(py, &cell, parent);
    if let Ok(slice) = key.cast::<PySlice>() {
        let picked: Vec<Node> = slice_indices(slice, kids.len())?
            .into_iter()
            .map(|i| kids[i])
            .collect();
        return Ok(PyList::new(py, proxies(py, &cell, picked)?)?.into_any());
    }
    let i = checked(index_of(key)?, kids.len(), "")?;
    Ok(proxy(py, &cell, kids[i])?.into_any())
}

/// Replaces child element number `index` (an index into the current children).
fn replace(
    py: Python<'_>,
    cell: &Arc<DocCell>,
    parent: Node,
    index: usize,
    item: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let incoming = prepare(py, cell, parent, item)?;
    let old = child_nodes(py, cell, parent)[index];
    if matches!(incoming, Incoming::Same(n) if n == old) {
        return Ok(());
    }
    cell.write(py).remove_element(old);
    commit(py, cell, parent, index, incoming)
}

pub(crate) fn set_item(
    el: &PyElement,
    py: Python<'_>,
    key: &Bound<'_, PyAny>,
    value: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let (cell, parent) = el.target();
    let kids = child_nodes(py, &cell, parent);
    let Ok(slice) = key.cast::<PySlice>() else {
        let i = checked(index_of(key)?, kids.len(), "assignment ")?;
        return replace(py, &cell, parent, i, value);
    };
    let items: Vec<Bound<'_, PyAny>> = value.try_iter()?.collect::<PyResult<_>>()?;
    let s = slice.indices(kids.len() as isize)?;
    if s.step != 1 {
        let at = slice_indices(slice, kids.len())?;
        if at.len() != items.len() {
            return Err(PyValueError::new_err(format!(
                "attempt to assign sequence of size {} to extended slice of size {}",
                items.len(),
                at.len()
            )));
        }
        for (i, item) in at.into_iter().zip(&items) {
            replace(py, &cell, parent, i, item)?;
        }
        return Ok(());
    }
    // A plain slice: the old children out, the new ones in from its start (as a list).
    let start = s.start.clamp(0, kids.len() as isize) as usize;
    let stop = (s.stop.max(s.start)).clamp(0, kids.len() as isize) as usize;
    let prepared: Vec<Incoming> = items
        .iter()
        .map(|item| prepare(py, &cell, parent, item))
        .collect::<PyResult<_>>()?;
    {
        let mut doc = cell.write(py);
        for &old in &kids[start..stop] {
            doc.remove_element(old);
        }
    }
    for (k, incoming) in prepared.into_iter().enumerate() {
        commit(py, &cell, parent, start + k, incoming)?;
    }
    Ok(())
}

pub(crate) fn del_item(el: &PyElement, py: Python<'_>, key: &Bound<'_, PyAny>) -> PyResult<()> {
    let (cell, parent) = el.target();
    let kids = child_nodes(py, &cell, parent);
    let doomed: Vec<Node> = match key.cast::<PySlice>() {
        Ok(slice) => slice_indices(slice, kids.len())?
            .into_iter()
            .map(|i| kids[i])
            .collect(),
        Err(_) => vec![kids[checked(index_of(key)?, kids.len(), "")?]],
    };
    let mut doc = cell.write(py);
    for n in doomed {
        doc.remove_element(n);
    }
    Ok(())
}
