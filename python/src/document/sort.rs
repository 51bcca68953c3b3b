//! `mjcf_forge.base`'s element sorting in one native pass, what `MujocoXMLModel.__init__`
//! asks for: the library's element sort (`mjcf_forge::sort`, the one `XmlModel`'s lists
//! run) with robosuite's keys, a geom's group read as Python's `int` reads it, and the
//! naming of unnamed geoms.

use mjcf_forge::sort::{SortRules, Sorted, name_unnamed_geoms, sort_elements_under};
use std::sync::Arc;

use mjcf_forge::{Document, Node};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::cell::DocCell;

/// One key of the sorting: its name, its elements and their names (None for an unnamed one).
pub(crate) type SortedKey = (&'static str, Vec<Node>, Vec<Option<String>>);

/// A geom's group as `base._group` reads it: 0 when absent, `int(value.strip())`, or
/// None when Python's `int` refuses it. Plain ASCII integers are read here; anything
/// else is handed to Python's `int`, so that every spelling it takes counts the same.
fn group(py: Python<'_>, value: Option<&str>) -> PyResult<Option<i64>> {
    let Some(value) = value else {
        return Ok(Some(0));
    };
    let t = value.trim_matches(|c: char| c.is_ascii_whitespace());
    let digits = t.strip_prefix(['+', '-']).unwrap_or(t);
    if !digits.is_empty() && digits.len() < 18 && digits.bytes().all(|b| b.is_ascii_digit()) {
        return Ok(t.parse().ok());
    }
    let stripped = crate::upcalls::python(py, "builtins", "str")?
        .call1((value,))?
        .call_method0("strip")?;
    match crate::upcalls::python(py, "builtins", "int")?.call1((stripped,)) {
        Ok(v) => Ok(v.extract::<i64>().ok().or(Some(i64::MAX))),
        Err(e) if e.is_instance_of::<pyo3::exceptions::PyValueError>(py) => Ok(None),
        Err(e) => Err(e),
    }
}

/// The sorted elements (key, nodes, names), keys in the order they first appear, every
/// element under `top` (itself included) in document order; unnamed geoms of groups 0 and
/// 1 named `g{n}_col` / `g{n}_vis` first when `name_geoms`.
pub(crate) fn sort(
    py: Python<'_>,
    doc: &mut Document,
    top: Node,
    name_geoms: bool,
) -> PyResult<Vec<SortedKey>> {
    let mut sorted: Vec<Sorted> =
        sort_elements_under(doc, top, SortRules::ROBOSUITE, |v| group(py, v))?;
    if name_geoms {
        name_unnamed_geoms(doc, &mut sorted);
    }
    Ok(sorted
        .into_iter()
        .map(|s| (s.key.as_str(), s.nodes, s.names))
        .collect())
}

/// [`sort`] as the two dicts `Document._sort_elements` and `Element._sort_elements` return:
/// each key to its elements (proxies) and to their names.
pub(crate) fn sorted_dicts<'py>(
    py: Python<'py>,
    cell: &Arc<DocCell>,
    top: Node,
    name_geoms: bool,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let sorted = {
        let mut doc = cell.write(py);
        sort(py, &mut doc, top, name_geoms)?
    };
    let elements = PyDict::new(py);
    let names = PyDict::new(py);
    for (key, nodes, found) in sorted {
        elements.set_item(key, super::cell::proxies(py, cell, nodes)?)?;
        names.set_item(key, found)?;
    }
    Ok((elements, names))
}
