//! `ModelArrays`: the arrays of a user's `MjModel` that a body model's compile is copied
//! from and into, found once, and the copy itself: [`mjcf_forge::split::copy_body_model`],
//! the rule both faces share (`mjcf_forge._plan.Plan` compiles the body models with the
//! user's `mujoco`).

use ahash::AHashMap;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use super::arrays::Array;
use super::patch_error;
use mjcf_forge::Error;
use mjcf_forge::split::{self, MasslessFrame};

/// The arrays the copy reads or writes, by type.
const FLOATS: [&str; 14] = [
    "body_mass",
    "body_inertia",
    "body_pos",
    "body_quat",
    "body_ipos",
    "body_iquat",
    "geom_size",
    "geom_rbound",
    "geom_aabb",
    "geom_pos",
    "geom_quat",
    "bvh_aabb",
    "site_pos",
    "site_quat",
];
const INTS: [&str; 14] = [
    "body_geomadr",
    "body_parentid",
    "dof_bodyid",
    "body_geomnum",
    "body_bvhadr",
    "body_bvhnum",
    "geom_type",
    "bvh_child",
    "bvh_depth",
    "bvh_nodeid",
    "geom_contype",
    "geom_conaffinity",
    "geom_bodyid",
    "site_bodyid",
];
const BYTES: [&str; 3] = ["body_sameframe", "geom_sameframe", "site_sameframe"];
/// The arrays a superset's tree-by-tree derivation reads or writes besides
/// (`mjcf_forge::split::TreeDerivation`), where this MuJoCo has them.
const TREE_FLOATS: [&str; 17] = [
    "jnt_pos",
    "jnt_axis",
    "dof_armature",
    "qpos0",
    "body_invweight0",
    "dof_invweight0",
    "dof_M0",
    "body_subtreemass",
    "cam_pos0",
    "cam_poscom0",
    "cam_mat0",
    "light_pos0",
    "light_poscom0",
    "light_dir0",
    "geom_margin",
    "body_margin",
    "body_gravcomp",
];
const TREE_INTS: [&str; 28] = [
    "body_rootid",
    "body_weldid",
    "jnt_bodyid",
    "jnt_qposadr",
    "jnt_dofadr",
    "jnt_type",
    "dof_simplenum",
    "M_rownnz",
    "M_rowadr",
    "M_colind",
    "cam_bodyid",
    "cam_targetbodyid",
    "cam_mode",
    "light_bodyid",
    "light_targetbodyid",
    "light_mode",
    "body_contype",
    "body_conaffinity",
    "tendon_adr",
    "tendon_num",
    "wrap_type",
    "wrap_objid",
    "actuator_trntype",
    "actuator_trnid",
    "eq_type",
    "eq_objtype",
    "eq_obj1id",
    "eq_obj2id",
];
const TREE_BYTES: [&str; 1] = ["body_simple"];

/// A compiled model's arrays a body model is copied from or into, found once.
///
/// ``ModelArrays(model)``; :meth:`copy_body_model` writes into ``model`` what MuJoCo
/// derives from a body's geoms, read off the compile of its body model.
///
/// >>> import mujoco
/// >>> from mjcf_forge._mjcf_forge import ModelArrays
/// >>> body = '<body name="b"><geom type="box" size="{}"/></body>'
/// >>> whole = mujoco.MjModel.from_xml_string(
/// ...     f'<mujoco><worldbody><body name="a"/>{body.format("0.1 0.1 0.1")}</worldbody></mujoco>')
/// >>> part = mujoco.MjModel.from_xml_string(
/// ...     f'<mujoco><worldbody>{body.format("0.2 0.1 0.1")}</worldbody></mujoco>')
/// >>> ModelArrays(whole).copy_body_model(2, "b", ModelArrays(part))
/// >>> bool(whole.body_mass[2] == part.body_mass[1])
/// True
#[pyclass(name = "ModelArrays", module = "mjcf_forge._mjcf_forge", frozen)]
pub(crate) struct PyModelArrays {
    pub(super) floats: AHashMap<&'static str, Array<f64>>,
    pub(super) ints: AHashMap<&'static str, Array<i32>>,
    pub(super) bytes: AHashMap<&'static str, Array<u8>>,
    /// The massless bodies' inertial frames as the model held them when this was made.
    massless: Vec<(usize, MasslessFrame)>,
    /// The model, held while its arrays are (NumPy's views of the bindings' arrays do not
    /// hold the model itself).
    _model: Py<PyAny>,
}

fn missing(name: &str) -> Error {
    patch_error(format!("no array {name} here"))
}

/// Write access to the model, for the length of one copy (the GIL held, no Python code
/// running).
struct Writer<'a>(&'a PyModelArrays);

impl split::ModelArrays for PyModelArrays {
    fn floats(&self, name: &str) -> Result<&[f64], Error> {
        // SAFETY: the GIL is held and no Python code runs while the slice lives; the
        // part and the model are different models (checked by `copy_body_model`).
        self.floats
            .get(name)
            .map(|a| unsafe { a.slice() })
            .ok_or_else(|| missing(name))
    }
    fn ints(&self, name: &str) -> Result<&[i32], Error> {
        // SAFETY: as above.
        self.ints
            .get(name)
            .map(|a| unsafe { a.slice() })
            .ok_or_else(|| missing(name))
    }
    fn bytes(&self, name: &str) -> Result<&[u8], Error> {
        // SAFETY: as above.
        self.bytes
            .get(name)
            .map(|a| unsafe { a.slice() })
            .ok_or_else(|| missing(name))
    }
}

impl split::ModelArrays for Writer<'_> {
    fn floats(&self, name: &str) -> Result<&[f64], Error> {
        self.0.floats(name)
    }
    fn ints(&self, name: &str) -> Result<&[i32], Error> {
        self.0.ints(name)
    }
    fn bytes(&self, name: &str) -> Result<&[u8], Error> {
        self.0.bytes(name)
    }
}

impl split::ModelArraysMut for Writer<'_> {
    fn floats_mut(&mut self, name: &str) -> Result<&mut [f64], Error> {
        // SAFETY: the only view of this array while `self` is borrowed mutably (each array
        // is one entry; the GIL is held and no Python code runs).
        self.0
            .floats
            .get(name)
            .map(|a| unsafe { a.slice_mut() })
            .ok_or_else(|| missing(name))
    }
    fn bytes_mut(&mut self, name: &str) -> Result<&mut [u8], Error> {
        // SAFETY: as above.
        self.0
            .bytes
            .get(name)
            .map(|a| unsafe { a.slice_mut() })
            .ok_or_else(|| missing(name))
    }
    fn ints_mut(&mut self, name: &str) -> Result<&mut [i32], Error> {
        // SAFETY: as above.
        self.0
            .ints
            .get(name)
            .map(|a| unsafe { a.slice_mut() })
            .ok_or_else(|| missing(name))
    }
}

impl PyModelArrays {
    /// Adds the arrays a superset's tree-by-tree derivation reads and writes (the
    /// patched model's and its skeletons', not a body model's).
    pub(super) fn add_tree_arrays(&mut self, model: &Bound<'_, PyAny>) -> PyResult<()> {
        // Where this MuJoCo has them (an older one may lack some: the derivation then
        // declines, and mj_setConst runs).
        let found = |name: &str| model.getattr(name).ok().filter(|a| !a.is_none());
        for name in TREE_FLOATS {
            if let Some(a) = found(name) {
                self.floats.insert(name, Array::of(&a, name, true)?);
            }
        }
        for name in TREE_INTS {
            if let Some(a) = found(name) {
                self.ints.insert(name, Array::of(&a, name, true)?);
            }
        }
        for name in TREE_BYTES {
            if let Some(a) = found(name) {
                self.bytes.insert(name, Array::of(&a, name, true)?);
            }
        }
        Ok(())
    }
}

#[pymethods]
impl PyModelArrays {
    #[new]
    pub(super) fn new(model: &Bound<'_, PyAny>) -> PyResult<Self> {
        let mut arrays = PyModelArrays {
            floats: AHashMap::new(),
            ints: AHashMap::new(),
            bytes: AHashMap::new(),
            massless: Vec::new(),
            _model: model.clone().unbind(),
        };
        for name in FLOATS {
            arrays
                .floats
                .insert(name, Array::of(&model.getattr(name)?, name, true)?);
        }
        for name in INTS {
            arrays
                .ints
                .insert(name, Array::of(&model.getattr(name)?, name, true)?);
        }
        for name in BYTES {
            arrays
                .bytes
                .insert(name, Array::of(&model.getattr(name)?, name, true)?);
        }
        arrays.massless =
            split::massless_frames(&arrays).map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(arrays)
    }

    /// Writes into body ``body`` (``name`` in errors) of this model what MuJoCo derives
    /// from its geoms, read off ``part``, the compile of its body model; raises
    /// ``ValueError``, with nothing written, when ``part`` has another layout than the
    /// body (the document is then compiled).
    fn copy_body_model(
        &self,
        body: usize,
        name: &str,
        part: &Bound<'_, PyModelArrays>,
    ) -> PyResult<()> {
        let part = part.get();
        let address = |a: &PyModelArrays| a.floats.get("body_mass").map(Array::address);
        if address(part) == address(self) {
            return Err(PyValueError::new_err(
                "a body model is copied from another model",
            ));
        }
        let kept = self
            .massless
            .iter()
            .find(|(b, _)| *b == body)
            .map(|(_, k)| k);
        split::copy_body_model(&mut Writer(self), body, name, kept, part)
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Sets the same-frame flags of ``bodies``, ``geoms`` and ``sites`` of this model from
    /// their frames (``mjcf_forge::split::write_frame_flags``: what MuJoCo 4.0's
    /// ``mj_setConst`` sets again).
    fn write_frame_flags(
        &self,
        bodies: Vec<usize>,
        geoms: Vec<usize>,
        sites: Vec<usize>,
    ) -> PyResult<()> {
        split::write_frame_flags(&mut Writer(self), &bodies, &geoms, &sites)
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Writes into body ``body`` (``name`` in errors) of this model its mass properties
    /// for geoms of densities or masses ``factors``, read off ``unit``, the compile of the
    /// body's unit model (``mjcf_forge::split::write_geom_masses``); raises ``ValueError``,
    /// with nothing written, when the result is not a patch of this model.
    fn write_geom_masses(
        &self,
        body: usize,
        name: &str,
        unit: &Bound<'_, PyModelArrays>,
        factors: Vec<f64>,
    ) -> PyResult<()> {
        let unit = unit.get();
        let address = |a: &PyModelArrays| a.floats.get("body_mass").map(Array::address);
        if address(unit) == address(self) {
            return Err(PyValueError::new_err("a unit model is another model"));
        }
        split::write_geom_masses(&mut Writer(self), body, name, unit, &factors)
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }
}
