//! ElementPath over our elements: `find`, `findall`, `iterfind`, `findtext`, and `iter`.
//!
//! The standard library's `xml.etree.ElementPath` is the algorithm (it works on any object
//! with ElementTree's element protocol, which ours has), so every path means what it means
//! to `xml.etree`. The common forms are answered in Rust without it: steps of tags or `*`
//! joined by `/` or `//`, each with `[@attr]` or `[@attr='value']` filters, from `.`
//! (`"body"`, `".//joint"`, `"./body/body[@name='object']"`, `"./*[@pos]"`). They select
//! exactly as ElementPath's own steps do (in the same order, without removing repeats, as
//! `prepare_descendant` does not); anything else (`..`, positions, `[tag]`, text tests,
//! namespaces) goes to ElementPath.

use mjcf_forge::{Document, Node};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyList, PyModule, PyString};

use super::cell::{proxies, proxy};
use super::element::PyElement;

/// How a step moves from each element of the current result.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Axis {
    /// `.`: the element itself.
    Itself,
    /// `tag`, `*`, `/tag`: its child elements.
    Child,
    /// `//tag`: the elements below it, not itself.
    Descendant,
}

/// An `[@attr]` or `[@attr='value']` filter.
struct Filter<'a> {
    attr: &'a str,
    value: Option<&'a str>,
}

struct Step<'a> {
    axis: Axis,
    /// `None` for `*`.
    tag: Option<&'a str>,
    filters: Vec<Filter<'a>>,
}

/// A name as ElementPath reads one, kept to plain XML names (no namespace prefix).
fn name_len(s: &str) -> usize {
    let mut chars = s.char_indices();
    match chars.next() {
        Some((_, c)) if c.is_ascii_alphabetic() || c == '_' => {}
        _ => return 0,
    }
    chars
        .find(|&(_, c)| !(c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.')))
        .map_or(s.len(), |(i, _)| i)
}

/// The steps of a path of the common forms, or `None` for ElementPath to read.
fn parse(path: &str) -> Option<Vec<Step<'_>>> {
    let mut rest = path;
    let mut steps = Vec::new();
    let mut axis = Axis::Child;
    loop {
        // One step.
        let (tag, after) = if let Some(r) = rest.strip_prefix('*') {
            (None, r)
        } else if rest.starts_with('.') && !rest.starts_with("..") && axis == Axis::Child {
            steps.push(Step {
                axis: Axis::Itself,
                tag: None,
                filters: Vec::new(),
            });
            rest = &rest[1..];
            if rest.is_empty() {
                return Some(steps);
            }
            axis = next_axis(&mut rest)?;
            continue;
        } else {
            let n = name_len(rest);
            if n == 0 {
                return None;
            }
            (Some(&rest[..n]), &rest[n..])
        };
        rest = after;
        let mut filters = Vec::new();
        while let Some(r) = rest.strip_prefix("[@") {
            let n = name_len(r);
            if n == 0 {
                return None;
            }
            let attr = &r[..n];
            let r = &r[n..];
            if let Some(r) = r.strip_prefix(']') {
                filters.push(Filter { attr, value: None });
                rest = r;
            } else {
                let r = r.strip_prefix('=')?;
                let quote = r.chars().next().filter(|&q| q == '\'' || q == '"')?;
                let end = r[1..].find(quote)? + 1;
                filters.push(Filter {
                    attr,
                    value: Some(&r[1..end]),
                });
                rest = r[end + 1..].strip_prefix(']')?;
            }
        }
        steps.push(Step { axis, tag, filters });
        if rest.is_empty() {
            return Some(steps);
        }
        axis = next_axis(&mut rest)?;
    }
}

/// The separator before the next step (a path never ends on one here).
fn next_axis(rest: &mut &str) -> Option<Axis> {
    let axis = if let Some(r) = rest.strip_prefix("//") {
        *rest = r;
        Axis::Descendant
    } else {
        *rest = rest.strip_prefix('/')?;
        Axis::Child
    };
    (!rest.is_empty()).then_some(axis)
}

/// Runs the steps from `start`.
fn select(doc: &Document, start: Node, steps: &[Step<'_>]) -> Vec<Node> {
    let mut result = vec![start];
    for step in steps {
        let keep = |n: Node| {
            step.tag.is_none_or(|t| doc.tag(n) == t)
                && step.filters.iter().all(|f| {
                    doc.attr(n, f.attr)
                        .is_some_and(|v| f.value.is_none_or(|w| v == w))
                })
        };
        let mut next = Vec::new();
        for &r in &result {
            match step.axis {
                Axis::Itself => next.extend(Some(r).filter(|&n| keep(n))),
                Axis::Child => next.extend(doc.elements(r).filter(|&n| keep(n))),
                Axis::Descendant => next.extend(doc.descendants(r).skip(1).filter(|&n| keep(n))),
            }
        }
        result = next;
    }
    result
}

/// The nodes a path of the common forms selects from `el`; `None` for other paths.
fn fast<'py>(
    el: &Bound<'py, PyElement>,
    path: &str,
    namespaces: Option<&Bound<'py, PyAny>>,
) -> Option<(std::sync::Arc<super::cell::DocCell>, Vec<Node>)> {
    if namespaces.is_some_and(|n| !n.is_none()) {
        return None;
    }
    let steps = parse(path)?;
    let (cell, node) = el.get().target();
    let nodes = select(&cell.read(el.py()), node, &steps);
    Some((cell, nodes))
}

fn element_path(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    static MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();
    MODULE
        .get_or_try_init(py, || {
            crate::upcalls::python_module(py, "xml.etree.ElementPath").map(Bound::unbind)
        })
        .map(|m| m.bind(py))
}

fn slow<'py>(
    el: &Bound<'py, PyElement>,
    function: &str,
    path: &str,
    namespaces: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let py = el.py();
    element_path(py)?.call_method1(function, (el, path, namespaces))
}

pub(crate) fn findall<'py>(
    el: &Bound<'py, PyElement>,
    path: &str,
    namespaces: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    match fast(el, path, namespaces) {
        Some((cell, nodes)) => {
            Ok(PyList::new(el.py(), proxies(el.py(), &cell, nodes)?)?.into_any())
        }
        None => slow(el, "findall", path, namespaces),
    }
}

pub(crate) fn find<'py>(
    el: &Bound<'py, PyElement>,
    path: &str,
    namespaces: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    match fast(el, path, namespaces) {
        Some((cell, nodes)) => match nodes.first() {
            Some(&n) => Ok(proxy(el.py(), &cell, n)?.into_any()),
            None => Ok(el.py().None().into_bound(el.py())),
        },
        None => slow(el, "find", path, namespaces),
    }
}

pub(crate) fn iterfind<'py>(
    el: &Bound<'py, PyElement>,
    path: &str,
    namespaces: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    match fast(el, path, namespaces) {
        Some(_) => Ok(findall(el, path, namespaces)?.try_iter()?.into_any()),
        None => slow(el, "iterfind", path, namespaces),
    }
}

pub(crate) fn findtext<'py>(
    el: &Bound<'py, PyElement>,
    path: &str,
    default: Option<Bound<'py, PyAny>>,
    namespaces: Option<&Bound<'py, PyAny>>,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let found = find(el, path, namespaces)?;
    if found.is_none() {
        return Ok(default);
    }
    let text = found.getattr("text")?;
    Ok(Some(if text.is_none() {
        PyString::new(el.py(), "").into_any()
    } else {
        text
    }))
}

pub(crate) fn iter<'py>(
    el: &PyElement,
    py: Python<'py>,
    tag: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let tag = tag.filter(|&t| t != "*");
    let (cell, node) = el.target();
    let nodes: Vec<Node> = named(&cell.read(py), node, tag, None).collect();
    Ok(PyList::new(py, proxies(py, &cell, nodes)?)?
        .try_iter()?
        .into_any())
}

/// Elements below `from` (itself included) matching an optional tag and name.
pub(crate) fn named<'a>(
    doc: &'a Document,
    from: Node,
    kind: Option<&'a str>,
    name: Option<&'a str>,
) -> impl Iterator<Item = Node> + 'a {
    doc.descendants(from).filter(move |&n| {
        kind.is_none_or(|k| doc.tag(n) == k) && name.is_none_or(|w| doc.attr(n, "name") == Some(w))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape(path: &str) -> Option<String> {
        parse(path).map(|steps| {
            steps
                .iter()
                .map(|s| {
                    let axis = match s.axis {
                        Axis::Itself => ".",
                        Axis::Child => "/",
                        Axis::Descendant => "//",
                    };
                    let filters: String = s
                        .filters
                        .iter()
                        .map(|f| format!("[{}={:?}]", f.attr, f.value))
                        .collect();
                    format!("{axis}{}{filters}", s.tag.unwrap_or("*"))
                })
                .collect::<Vec<_>>()
                .join(" ")
        })
    }

    #[test]
    fn the_common_forms_are_read_and_the_rest_left_to_element_path() {
        assert_eq!(shape("body").as_deref(), Some("/body"));
        assert_eq!(shape(".//joint").as_deref(), Some(".* //joint"));
        assert_eq!(
            shape("./body/body[@name='object']").as_deref(),
            Some(".* /body /body[name=Some(\"object\")]")
        );
        assert_eq!(shape("./*[@pos]").as_deref(), Some(".* /*[pos=None]"));
        assert_eq!(
            shape("a//b[@x=\"1 2\"][@y]").as_deref(),
            Some("/a //b[x=Some(\"1 2\")][y=None]")
        );
        assert_eq!(shape(".").as_deref(), Some(".*"));
        for other in [
            "",
            "/body",
            "body/",
            "..",
            "./..",
            "body[1]",
            "body[last()]",
            "body[geom]",
            "body[geom='x']",
            "body[.='x']",
            "x:body",
            "{ns}body",
            ".//",
            "body[@name!='a']",
            "body [@name]",
            "//body",
            ".//.",
            "body[@name='a]",
        ] {
            assert!(parse(other).is_none(), "{other:?}");
        }
    }
}
