//! A Python callable as the merge's and the scene's inertia compiler: `Document.merge`'s
//! `compile_inertia`, and the installed `mujoco` for scenes.

use mjcf_forge::{CompiledInertia, Document};
use pyo3::prelude::*;

/// The inertias of `part` as the Python callable `compile` says MuJoCo compiles it alone
/// (`Document.merge`'s `compile_inertia`), called with the GIL taken for the call.
pub(crate) fn python_inertia(
    compile: &Py<PyAny>,
    part: &Document,
) -> Result<CompiledInertia, mjcf_forge::Error> {
    let xml = part.to_xml_string();
    let dir = part.model_dir().to_path_buf();
    type Arrays = (Vec<String>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);
    Python::attach(|py| {
        let (body_names, mass, ipos, iquat, inertia): Arrays =
            compile.bind(py).call1((xml, dir))?.extract()?;
        Ok::<_, PyErr>(CompiledInertia {
            body_names,
            mass,
            ipos,
            iquat,
            inertia,
        })
    })
    .map_err(|e| mjcf_forge::Error {
        location: None,
        kind: mjcf_forge::ErrorKind::InertiaCompile(format!("compile_inertia: {e}")),
    })
}
