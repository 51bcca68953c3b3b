//! A structure's values as the user's `mujoco` compiled them, of everything a patch or a
//! caller may change (every array but the bulk data, `model.opt`, `model.vis`: the fields
//! `_mujoco.snapshot_fields` names for the user's version), taken once after the compile
//! and written back into a model of the structure before each patch: what the document
//! cache's snapshot is on this face (`mjcf_forge::split::DocumentBackend::Snapshot`).

use pyo3::prelude::*;
use pyo3::types::PyString;

use super::arrays::Memory;
use crate::upcalls;
use mjcf_forge::split::{Held, Statistics};

/// One field as compiled: an array's bytes, or a number (immutable in Python).
enum Saved {
    Bytes(Vec<u8>),
    Value(Py<PyAny>),
}

/// One field: where it sits (`model.a.b`), its name, what it held.
struct Field {
    path: Vec<String>,
    name: Py<PyString>,
    saved: Saved,
}

/// The object at `path` under `model`.
fn walk<'py>(model: &Bound<'py, PyAny>, path: &[String]) -> PyResult<Bound<'py, PyAny>> {
    let mut obj = model.clone();
    for part in path {
        obj = obj.getattr(part.as_str())?;
    }
    Ok(obj)
}

/// A structure's values as compiled, and its statistics.
pub(crate) struct Snapshot {
    fields: Vec<Field>,
    nbytes: usize,
    /// The statistics as compiled (what the document fixes stays at these).
    pub(crate) stat: Statistics,
}

impl Held for Snapshot {
    fn nbytes(&self) -> usize {
        self.nbytes
    }
}

impl Snapshot {
    /// The snapshot of `model` (just compiled by `mujoco`), with its statistics `stat`.
    pub(crate) fn of(
        mujoco: &Bound<'_, PyAny>,
        model: &Bound<'_, PyAny>,
        stat: Statistics,
    ) -> PyResult<Snapshot> {
        let py = model.py();
        let names: Vec<(Vec<String>, String)> = upcalls::get(py, "snapshot_fields")?
            .call1((mujoco, model))?
            .extract()?;
        let mut fields = Vec::with_capacity(names.len());
        let mut nbytes = 0;
        for (path, name) in names {
            let value = walk(model, &path)?.getattr(name.as_str())?;
            let saved = match Memory::of(&value, &name)? {
                Some(memory) => {
                    nbytes += memory.bytes().len();
                    Saved::Bytes(memory.bytes().to_vec())
                }
                None => Saved::Value(value.unbind()),
            };
            fields.push(Field {
                path,
                name: PyString::intern(py, &name).unbind(),
                saved,
            });
        }
        Ok(Snapshot {
            fields,
            nbytes,
            stat,
        })
    }

    /// `model`'s views of what this snapshot writes back (a model of its structure).
    pub(crate) fn views(&self, model: &Bound<'_, PyAny>) -> PyResult<Views> {
        let mut views = Views {
            arrays: Vec::new(),
            structs: Vec::new(),
        };
        for (k, field) in self.fields.iter().enumerate() {
            let obj = walk(model, &field.path)?;
            match &field.saved {
                Saved::Bytes(_) => {
                    let value = obj.getattr(field.name.bind(model.py()))?;
                    let what = field.name.bind(model.py()).to_cow()?;
                    if let Some(memory) = Memory::of(&value, &what)? {
                        views.arrays.push((memory, k));
                    }
                }
                Saved::Value(_) => views.structs.push((obj.unbind(), k)),
            }
        }
        Ok(views)
    }
}

/// One model's views of what a snapshot writes back: its arrays' memory and the structs
/// whose numbers are set.
pub(crate) struct Views {
    arrays: Vec<(Memory, usize)>,
    structs: Vec<(Py<PyAny>, usize)>,
}

impl Views {
    /// Writes `snapshot` (the one these views were made from) back into the model.
    pub(crate) fn restore(&self, py: Python<'_>, snapshot: &Snapshot) -> PyResult<()> {
        for (memory, k) in &self.arrays {
            if let Saved::Bytes(saved) = &snapshot.fields[*k].saved {
                memory.write(saved);
            }
        }
        for (obj, k) in &self.structs {
            let field = &snapshot.fields[*k];
            if let Saved::Value(value) = &field.saved {
                obj.bind(py).setattr(field.name.bind(py), value.bind(py))?;
            }
        }
        Ok(())
    }
}

/// How many references `obj` has (CPython's count): the document cache's test of whether
/// anyone but itself holds a model.
pub(crate) fn references(obj: &Py<PyAny>) -> isize {
    // SAFETY: `obj` is a live object (held by the reference passed in) and the GIL is held
    // by the caller's `Python::attach`.
    unsafe { pyo3::ffi::Py_REFCNT(obj.as_ptr()) }
}
