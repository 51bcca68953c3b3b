//! The split tier's tables the package's caches read (`mjcf_forge._cache`,
//! `batch`, `_mujoco`): the one copy of each, `mjcf_forge::split::targets`.

use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// The split tier's tables the package's caches read (`mjcf_forge._cache`,
/// `batch`, `_mujoco`), added to the module: the one copy of each (`mjcf_forge::split::targets`).
pub(super) fn add(m: &Bound<'_, PyModule>) -> PyResult<()> {
    use mjcf_forge::split;
    let py = m.py();
    let objects = pyo3::types::PyDict::new(py);
    for o in split::PATCH_OBJECTS {
        objects.set_item(o.object, (o.prefix, o.obj_type, o.count))?;
    }
    m.add("PATCH_OBJECTS", objects)?;
    m.add("DOF_FIELDS", PyTuple::new(py, split::DOF_FIELDS)?)?;
    m.add("QPOS_FIELDS", PyTuple::new(py, split::QPOS_FIELDS)?)?;
    m.add("STATIC_PREFIXES", PyTuple::new(py, split::STATIC_PREFIXES)?)?;
    m.add("MODEL_FIELDS", PyTuple::new(py, split::MODEL_FIELDS)?)?;
    m.add("GEOM_FACTORS", split::GEOM_FACTORS)?;
    m.add("MASS_DERIVED", PyTuple::new(py, split::MASS_DERIVED)?)?;
    m.add("STATISTIC_NAMES", PyTuple::new(py, split::STATISTIC_NAMES)?)?;
    m.add("JOINT_TYPES", PyTuple::new(py, split::JOINT_TYPES)?)?;
    m.add("BODY_MODELS_KEPT", split::BODY_MODELS_KEPT)?;
    m.add("LAYOUTS_KEPT", split::LAYOUTS_KEPT)?;
    m.add(
        "SET_CONST_DERIVED",
        PyTuple::new(py, split::SET_CONST_DERIVED)?,
    )?;
    m.add(
        "BODY_MODEL_WRITES",
        PyTuple::new(py, split::body_model_writes())?,
    )?;
    m.add("BULK_SIZES", PyTuple::new(py, split::BULK_SIZES)?)?;
    m.add("FROM_GEOMS", PyTuple::new(py, split::FROM_GEOMS)?)?;
    m.add("BULK_PREFIXES", PyTuple::new(py, split::BULK_PREFIXES)?)?;
    m.add_function(wrap_pyfunction!(target_array, m)?)?;
    m.add_function(wrap_pyfunction!(joint_widths, m)?)?;
    Ok(())
}

/// The ``MjModel`` array a patch entry of an ``object``'s ``field`` writes (a joint's dof
/// and qpos fields have arrays of their own), or ``None`` (the options).
///
/// >>> from mjcf_forge._mjcf_forge import target_array
/// >>> target_array("joint", "damping")
/// 'dof_damping'
#[pyfunction]
fn target_array(object: &str, field: &str) -> Option<String> {
    mjcf_forge::split::target_array(object, field)
}

/// How many degrees of freedom and ``qpos`` coordinates a joint of MuJoCo type
/// ``jnt_type`` has (free, ball, slide, hinge).
///
/// >>> from mjcf_forge._mjcf_forge import joint_widths
/// >>> joint_widths(0)
/// (6, 7)
#[pyfunction]
fn joint_widths(jnt_type: i64) -> (usize, usize) {
    mjcf_forge::split::joint_widths(jnt_type)
}
