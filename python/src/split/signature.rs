//! `structure_signature`: the split tier's [`mjcf_forge::split::Signature`] of a user's
//! `MjModel` (its sizes read off the bindings' attributes, its names buffer and integer
//! arrays through NumPy), the one definition both faces' caches take.

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyInt};

use mjcf_forge::split::{Signature, SignatureSource};

/// `obj`'s bytes (a `bytes`, or anything `bytes()` takes).
fn python_bytes(obj: &Bound<'_, PyAny>) -> PyResult<Vec<u8>> {
    if let Ok(b) = obj.cast::<PyBytes>() {
        return Ok(b.as_bytes().to_vec());
    }
    let b = crate::upcalls::python(obj.py(), "builtins", "bytes")?.call1((obj,))?;
    Ok(b.cast::<PyBytes>()?.as_bytes().to_vec())
}

/// The user's model as a signature reads it.
struct UserModel<'a, 'py>(&'a Bound<'py, PyAny>);

impl SignatureSource for UserModel<'_, '_> {
    fn sizes(&self) -> Vec<(String, i64)> {
        let Ok(names) = self.0.dir() else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for name in names.iter() {
            let Ok(name) = name.extract::<String>() else {
                continue;
            };
            if !name.starts_with('n') {
                continue;
            }
            let Ok(value) = self.0.getattr(name.as_str()) else {
                continue;
            };
            // A size is a Python int (not a bool, not a method or an array).
            if value.is_exact_instance_of::<PyInt>()
                && let Ok(v) = value.extract::<i64>()
            {
                out.push((name, v));
            }
        }
        out
    }

    fn names_buffer(&self) -> Vec<u8> {
        // `bytes(model.names)`: the bindings give the buffer as bytes.
        self.0
            .getattr("names")
            .and_then(|n| python_bytes(&n))
            .unwrap_or_default()
    }

    fn array_bytes(&self, name: &str) -> Vec<u8> {
        self.0
            .getattr(name)
            .and_then(|a| python_bytes(&a.call_method0("tobytes")?))
            .unwrap_or_default()
    }
}

/// What decides ``model``'s structure (``mjcf_forge::split::Signature``: every size but
/// those a patch changes, the names, the integer arrays that tell structures apart), as
/// bytes: two models of one structure have equal bytes.
///
/// >>> import mujoco
/// >>> from mjcf_forge._mjcf_forge import structure_signature
/// >>> xml = '<mujoco><worldbody><geom size="{}"/></worldbody></mujoco>'
/// >>> a, b = (mujoco.MjModel.from_xml_string(xml.format(s)) for s in (".1", ".2"))
/// >>> structure_signature(a) == structure_signature(b)
/// True
#[pyfunction]
pub(super) fn structure_signature<'py>(model: &Bound<'py, PyAny>) -> Bound<'py, PyBytes> {
    PyBytes::new(model.py(), &signature_of(model).to_bytes())
}

/// The signature of the user's `model`.
pub(crate) fn signature_of(model: &Bound<'_, PyAny>) -> Signature {
    Signature::of(&UserModel(model))
}
