//! robosuite's `sort_elements` with `mjcf_forge.base._element_filter` (and the naming of
//! unnamed geoms), done in one native pass: what `MujocoXMLModel.__init__` asks for.

use mjcf_forge::{Document, Node};
use pyo3::prelude::*;

/// The keys of `_element_filter`, in the order of the `KEYS` table.
const KEYS: [&str; 8] = [
    "root_body",
    "bodies",
    "joints",
    "actuators",
    "sites",
    "sensors",
    "contact_geoms",
    "visual_geoms",
];

/// One key of the sorting: its elements and their names (None for an unnamed one).
pub(crate) type Sorted = (&'static str, Vec<Node>, Vec<Option<String>>);

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

/// The key (index into `KEYS`) `_element_filter(node, parent)` gives, or None.
fn key(py: Python<'_>, doc: &Document, node: Node) -> PyResult<Option<usize>> {
    let Some(parent) = doc.parent(node) else {
        return Ok(None);
    };
    let above_tag = doc.tag(parent);
    match above_tag {
        "actuator" => return Ok(Some(3)),
        "sensor" => return Ok(Some(5)),
        "worldbody" | "body" | "frame" | "replicate" => {}
        _ => return Ok(None),
    }
    Ok(match doc.tag(node) {
        "joint" => Some(2),
        "body" => {
            let mut above = Some(parent);
            while let Some(a) = above {
                if matches!(doc.tag(a), "frame" | "replicate") {
                    above = doc.parent(a);
                } else {
                    break;
                }
            }
            if above.is_some_and(|a| doc.tag(a) == "body") {
                Some(1)
            } else {
                Some(0)
            }
        }
        "site" => Some(4),
        "geom" => match group(py, doc.attr(node, "group"))? {
            Some(0) => Some(6),
            Some(1) => Some(7),
            _ => None,
        },
        _ => None,
    })
}

/// The sorted elements (key, nodes, names), keys in the order they first appear, every
/// element under the root in document order; unnamed geoms of groups 0 and 1 named
/// `g{n}_col` / `g{n}_vis` first when `name_geoms`.
pub(crate) fn sort(py: Python<'_>, doc: &mut Document, name_geoms: bool) -> PyResult<Vec<Sorted>> {
    let mut slots: [Option<usize>; 8] = [None; 8];
    let mut out: Vec<Sorted> = Vec::new();
    let (mut col, mut vis) = (0usize, 0usize);
    let nodes: Vec<Node> = doc.descendants(doc.root()).collect();
    for node in nodes {
        let Some(k) = key(py, doc, node)? else {
            continue;
        };
        let mut name = doc.attr(node, "name").map(str::to_owned);
        if name_geoms && (k == 6 || k == 7) && name.is_none() {
            let made = if k == 6 {
                col += 1;
                format!("g{}_col", col - 1)
            } else {
                vis += 1;
                format!("g{}_vis", vis - 1)
            };
            doc.set_attr(node, "name", &made);
            name = Some(made);
        }
        let slot = *slots[k].get_or_insert_with(|| {
            out.push((KEYS[k], Vec::new(), Vec::new()));
            out.len() - 1
        });
        out[slot].1.push(node);
        out[slot].2.push(name);
    }
    Ok(out)
}
