//! Names and values coming from Python: attribute values as MJCF text, and the checks that
//! keep out what XML cannot carry.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyString};

use crate::errors::Failure;

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
        Err(Failure::new(vec![format!(
            "{what} {name:?} is not an XML name"
        )]))
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
        Some(c) => Err(Failure::new(vec![format!(
            "{what} {text:?} holds the character U+{:04X}, which XML cannot carry",
            c as u32
        )])),
    }
}

fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default()
}

/// MJCF text for an attribute value given from Python: a `str` as is, `bool` as
/// `true`/`false`, numbers and sequences of numbers space-separated.
pub(crate) fn attr_text(value: &Bound<'_, PyAny>) -> PyResult<String> {
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
                    type_name(&item)
                ))
            })?);
        }
        return Ok(parts.join(" "));
    }
    Err(PyTypeError::new_err(format!(
        "attribute values are str, bool, numbers or sequences of numbers, not {}",
        type_name(value)
    )))
}

/// A number (or bool) as MuJoCo reads it; `None` for anything else.
fn number_text(value: &Bound<'_, PyAny>) -> Option<String> {
    if let Ok(b) = value.cast::<PyBool>() {
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

/// A checked attribute: an XML name and a value XML can carry.
pub(crate) fn checked_attr(key: &str, value: &Bound<'_, PyAny>) -> PyResult<(String, String)> {
    let text = attr_text(value)?;
    check_xml_name("attribute name", key)?;
    check_xml_text("attribute value", &text)?;
    Ok((key.to_owned(), text))
}

/// The (name, value) pairs of a mapping (a `dict`, anything with `keys()`, or pairs),
/// checked, then those of `extra` (keyword arguments), in order.
pub(crate) fn attr_pairs(
    mapping: Option<&Bound<'_, PyAny>>,
    extra: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<(String, String)>> {
    let mut pairs = Vec::new();
    let mut add = |k: &Bound<'_, PyAny>, v: &Bound<'_, PyAny>| -> PyResult<()> {
        let key = k.cast::<PyString>().map_err(|_| {
            PyTypeError::new_err(format!("attribute names are str, not {}", type_name(k)))
        })?;
        pairs.push(checked_attr(&key.to_cow()?, v)?);
        Ok(())
    };
    if let Some(m) = mapping.filter(|m| !m.is_none()) {
        if let Ok(d) = m.cast::<PyDict>() {
            for (k, v) in d.iter() {
                add(&k, &v)?;
            }
        } else if m.hasattr("keys")? {
            for k in m.call_method0("keys")?.try_iter()? {
                let k = k?;
                add(&k, &m.get_item(&k)?)?;
            }
        } else {
            for pair in m.try_iter()? {
                let (k, v): (Bound<'_, PyAny>, Bound<'_, PyAny>) = pair?.extract()?;
                add(&k, &v)?;
            }
        }
    }
    if let Some(extra) = extra {
        for (k, v) in extra.iter() {
            add(&k, &v)?;
        }
    }
    Ok(pairs)
}
