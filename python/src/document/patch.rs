//! Patches as Python holds them: `(object, name or id, field, value)` tuples, for a
//! document's patch (`Document.patch`) and a variant's (`Variant.patch`, `Superset.patch`).

use mjcf_forge::split::{PatchEntry, PatchValue};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyList, PyTuple};

/// A patch entry as Python holds it: `(object, name or id, field, value)`.
pub(crate) type PatchTuple<'py> = (String, Bound<'py, PyAny>, String, Bound<'py, PyAny>);

/// A patch as Python tuples (see `Variant.patch`).
pub(crate) fn patch_list<'py>(
    py: Python<'py>,
    entries: &[PatchEntry],
) -> PyResult<Bound<'py, PyList>> {
    let items = entries
        .iter()
        .map(|e| {
            let value = match &e.value {
                PatchValue::Numbers(v) => PyTuple::new(py, v)?.into_any(),
                PatchValue::Id { name, .. } | PatchValue::BodyModel(name) => {
                    name.as_str().into_pyobject(py)?.into_any()
                }
            };
            let name = match e.id {
                Some(id) => id.into_pyobject(py)?.into_any(),
                None => e.name.as_str().into_pyobject(py)?.into_any(),
            };
            (e.object, name, e.field, value).into_pyobject(py)
        })
        .collect::<PyResult<Vec<_>>>()?;
    PyList::new(py, items)
}

/// A patch entry back from its Python tuple (an unpickled variant's): the object and
/// field names are the library's own, matched against its table.
pub(crate) fn patch_entry(
    object: String,
    name: &Bound<'_, PyAny>,
    field: String,
    value: &Bound<'_, PyAny>,
) -> PyResult<PatchEntry> {
    let (name, id) = match name.extract::<usize>() {
        Ok(id) => (String::new(), Some(id)),
        Err(_) => (name.extract::<String>()?, None),
    };
    let unknown =
        || PyValueError::new_err(format!("not a patch entry: ({object}, {name}, {field})"));
    let object = mjcf_forge::split::PATCH_OBJECTS
        .iter()
        .map(|o| o.object)
        .find(|o| *o == object)
        .ok_or_else(unknown)?;
    let field = if field == "matid" {
        "matid"
    } else if let Some(f) = mjcf_forge::split::MODEL_FIELDS
        .iter()
        .chain([&mjcf_forge::split::GEOM_FACTORS])
        .find(|f| **f == field)
    {
        f
    } else {
        mjcf_forge::split::PATCHABLE
            .iter()
            .map(|p| p.2)
            .chain([
                "qpos0",
                "qpos_spring",
                "key_qpos",
                "ipos",
                "iquat",
                "gravcomp",
                "contype",
                "conaffinity",
            ])
            .find(|f| *f == field)
            .ok_or_else(unknown)?
    };
    let value = match value.extract::<String>() {
        // A body model: its geoms as MJCF text.
        Ok(model) if mjcf_forge::split::MODEL_FIELDS.contains(&field) => {
            PatchValue::BodyModel(model)
        }
        Ok(target) => PatchValue::Id {
            object: "material",
            name: target,
        },
        Err(_) => PatchValue::Numbers(value.extract::<Vec<f64>>()?),
    };
    Ok(PatchEntry {
        object,
        name,
        id,
        field,
        value,
    })
}

/// A document's split as the document cache takes it (`Document._split()`): its structure
/// key and its patch's values by kind, in the patch's order.
#[pyclass(
    name = "DocumentSplit",
    module = "mjcf_forge._mjcf_forge",
    frozen,
    get_all
)]
pub(crate) struct PyDocumentSplit {
    /// The structure key (`Document.structure_key`).
    pub structure_key: String,
    /// Every number of the patch end to end, as little-endian float64 bytes.
    pub numbers: Py<PyBytes>,
    /// The material names of its `matid` entries, in order.
    pub materials: Vec<String>,
    /// The statistics the document's `<statistic>` sets (`STATISTIC_NAMES`' names).
    pub fixed_statistics: Vec<&'static str>,
    /// The body models of its `geoms` entries, in order.
    pub bodies: Vec<String>,
}

impl PyDocumentSplit {
    /// The split of a document's patch `entries` under `structure_key`.
    pub(crate) fn new(
        py: Python<'_>,
        structure_key: String,
        entries: Vec<PatchEntry>,
        fixed_statistics: Vec<&'static str>,
    ) -> Self {
        let mut numbers: Vec<u8> = Vec::new();
        let mut materials = Vec::new();
        let mut bodies = Vec::new();
        for e in entries {
            match e.value {
                PatchValue::Numbers(v) => numbers.extend(v.iter().flat_map(|x| x.to_le_bytes())),
                PatchValue::Id { name, .. } => materials.push(name),
                PatchValue::BodyModel(model) => bodies.push(model),
            }
        }
        PyDocumentSplit {
            structure_key,
            numbers: PyBytes::new(py, &numbers).unbind(),
            materials,
            fixed_statistics,
            bodies,
        }
    }
}
