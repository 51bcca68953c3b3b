//! `Statistics`: the compiler's statistics of a user's `MjModel`, computed by
//! [`mjcf_forge::split::statistics`] over its arrays in place (the one implementation both
//! faces use; `mjcf_forge._plan.Plan` runs MuJoCo's kinematics before it).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use super::arrays::Array;
use mjcf_forge::split::{STATISTIC_NAMES, StatArrays, mean_inertia, statistics};

/// The arrays of one model and its scratch data the statistics read, found once.
///
/// ``Statistics(model, data, inertia, diagonal)``: ``inertia`` the data's joint-space
/// inertia as this MuJoCo keeps it (``data.M``, or ``data.qM``), ``diagonal`` where each
/// dof's diagonal element sits in it. :meth:`compute` after the kinematics, centres of
/// mass and inertia at ``qpos0`` sets ``model.stat`` and ``model.dof_length`` (where this
/// MuJoCo has it) as the compiler does.
///
/// >>> import mujoco
/// >>> from mjcf_forge._mjcf_forge import Statistics
/// >>> m = mujoco.MjModel.from_xml_string(
/// ...     '<mujoco><worldbody><body><joint/><geom size="0.1"/></body></worldbody></mujoco>')
/// >>> d = mujoco.MjData(m)
/// >>> stats = Statistics(m, d, d.M, m.M_rowadr + m.M_rownnz - 1)
/// >>> mean_size = m.stat.meansize
/// >>> m.stat.meansize = 0
/// >>> mujoco.mj_kinematics(m, d); mujoco.mj_comPos(m, d); mujoco.mj_makeM(m, d)
/// >>> stats.compute()
/// >>> m.stat.meansize == mean_size
/// True
#[pyclass(name = "Statistics", module = "mjcf_forge._mjcf_forge", frozen)]
pub(crate) struct PyStatistics {
    xpos: Array<f64>,
    xipos: Array<f64>,
    xanchor: Array<f64>,
    site_xpos: Array<f64>,
    geom_xpos: Array<f64>,
    geom_rbound: Array<f64>,
    geom_type: Array<i32>,
    geom_size: Array<f64>,
    geom_dataid: Array<i32>,
    hfield_size: Array<f64>,
    body_parentid: Array<i32>,
    body_geomadr: Array<i32>,
    body_geomnum: Array<i32>,
    body_mass: Array<f64>,
    jnt_bodyid: Array<i32>,
    jnt_type: Array<i32>,
    jnt_dofadr: Array<i32>,
    dof_jntid: Array<i32>,
    dof_bodyid: Array<i32>,
    inertia: Array<f64>,
    diagonal: Vec<i32>,
    dof_length: Option<Array<f64>>,
    stat: Py<PyAny>,
    center: Array<f64>,
}

impl PyStatistics {
    /// The arrays' lengths agree with each other (per body, joint, geom and dof).
    fn check(&self) -> PyResult<()> {
        let nbody = self.body_mass.len();
        let njnt = self.jnt_bodyid.len();
        let ngeom = self.geom_type.len();
        let nv = self.dof_jntid.len();
        let agree = self.xpos.len() == 3 * nbody
            && self.xipos.len() == 3 * nbody
            && [&self.body_parentid, &self.body_geomadr, &self.body_geomnum]
                .iter()
                .all(|a| a.len() == nbody)
            && self.xanchor.len() == 3 * njnt
            && self.jnt_type.len() == njnt
            && self.jnt_dofadr.len() == njnt
            && self.geom_xpos.len() == 3 * ngeom
            && self.geom_size.len() == 3 * ngeom
            && self.geom_rbound.len() == ngeom
            && self.geom_dataid.len() == ngeom
            && self.hfield_size.len().is_multiple_of(4)
            && self.site_xpos.len().is_multiple_of(3)
            && self.dof_bodyid.len() == nv
            && self.diagonal.len() == nv
            && self.dof_length.as_ref().is_none_or(|a| a.len() == nv);
        if agree {
            Ok(())
        } else {
            Err(PyValueError::new_err(
                "the model's and data's arrays do not belong to one model",
            ))
        }
    }

    /// Calls `f` with the arrays and the model's `dof_length` (empty where this MuJoCo has
    /// none).
    pub(super) fn with_lengths<R>(&self, f: impl FnOnce(&StatArrays<'_>, &mut [f64]) -> R) -> R {
        let lengths: &mut [f64] = match &self.dof_length {
            // SAFETY: the GIL is held and no Python code runs while `f` does;
            // `dof_length` is no input of the statistics.
            Some(a) => unsafe { a.slice_mut() },
            None => &mut [],
        };
        self.with_arrays(|arrays| f(arrays, lengths))
    }

    /// Calls `f` with the arrays.
    fn with_arrays<R>(&self, f: impl FnOnce(&StatArrays<'_>) -> R) -> R {
        // SAFETY: the GIL is held and no Python code runs while `f` does; the arrays this
        // reads are not the ones `compute` writes (`dof_length`, `stat.center`).
        unsafe {
            f(&StatArrays {
                xpos: self.xpos.slice(),
                xipos: self.xipos.slice(),
                xanchor: self.xanchor.slice(),
                site_xpos: self.site_xpos.slice(),
                geom_xpos: self.geom_xpos.slice(),
                geom_rbound: self.geom_rbound.slice(),
                geom_type: self.geom_type.slice(),
                geom_size: self.geom_size.slice(),
                geom_dataid: self.geom_dataid.slice(),
                hfield_size: self.hfield_size.slice(),
                body_parentid: self.body_parentid.slice(),
                body_geomadr: self.body_geomadr.slice(),
                body_geomnum: self.body_geomnum.slice(),
                body_mass: self.body_mass.slice(),
                jnt_bodyid: self.jnt_bodyid.slice(),
                jnt_type: self.jnt_type.slice(),
                jnt_dofadr: self.jnt_dofadr.slice(),
                dof_jntid: self.dof_jntid.slice(),
                dof_bodyid: self.dof_bodyid.slice(),
                inertia: self.inertia.slice(),
                inertia_diagonal: &self.diagonal,
            })
        }
    }
}

#[pymethods]
impl PyStatistics {
    #[new]
    pub(super) fn new(
        model: &Bound<'_, PyAny>,
        data: &Bound<'_, PyAny>,
        inertia: &Bound<'_, PyAny>,
        diagonal: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let f64s =
            |obj: &Bound<'_, PyAny>, name: &str| Array::<f64>::of(&obj.getattr(name)?, name, false);
        let i32s =
            |obj: &Bound<'_, PyAny>, name: &str| Array::<i32>::of(&obj.getattr(name)?, name, false);
        let dof_length = match model.getattr("dof_length") {
            Ok(a) => Some(Array::of(&a, "dof_length", true)?),
            Err(_) => None,
        };
        let stat = model.getattr("stat")?;
        let center = Array::of(&stat.getattr("center")?, "stat.center", true)?;
        let diagonal: Vec<i32> = diagonal.extract()?;
        let inertia = Array::of(inertia, "inertia", false)?;
        if diagonal
            .iter()
            .any(|&i| i < 0 || i as usize >= inertia.len())
        {
            return Err(PyValueError::new_err(
                "diagonal: an index outside the inertia",
            ));
        }
        let stats = PyStatistics {
            xpos: f64s(data, "xpos")?,
            xipos: f64s(data, "xipos")?,
            xanchor: f64s(data, "xanchor")?,
            site_xpos: f64s(data, "site_xpos")?,
            geom_xpos: f64s(data, "geom_xpos")?,
            geom_rbound: f64s(model, "geom_rbound")?,
            geom_type: i32s(model, "geom_type")?,
            geom_size: f64s(model, "geom_size")?,
            geom_dataid: i32s(model, "geom_dataid")?,
            hfield_size: f64s(model, "hfield_size")?,
            body_parentid: i32s(model, "body_parentid")?,
            body_geomadr: i32s(model, "body_geomadr")?,
            body_geomnum: i32s(model, "body_geomnum")?,
            body_mass: f64s(model, "body_mass")?,
            jnt_bodyid: i32s(model, "jnt_bodyid")?,
            jnt_type: i32s(model, "jnt_type")?,
            jnt_dofadr: i32s(model, "jnt_dofadr")?,
            dof_jntid: i32s(model, "dof_jntid")?,
            dof_bodyid: i32s(model, "dof_bodyid")?,
            inertia,
            diagonal,
            dof_length,
            stat: stat.unbind(),
            center,
        };
        stats.check()?;
        Ok(stats)
    }

    /// Sets ``model.stat`` and ``model.dof_length`` from the scratch data's kinematics,
    /// centres of mass and joint-space inertia at ``qpos0``, as the compiler does.
    fn compute(&self, py: Python<'_>) -> PyResult<()> {
        let stat = self.stat.bind(py);
        let mut previous = [0.0; 7];
        for (k, name) in STATISTIC_NAMES[..4].iter().enumerate() {
            previous[k] = stat.getattr(*name)?.extract()?;
        }
        // SAFETY: the GIL is held and nothing else runs; `center` is no input.
        previous[4..].copy_from_slice(unsafe { self.center.slice() });
        let lengths = match &self.dof_length {
            // SAFETY: as above; `dof_length` is no input of the statistics.
            Some(a) => Some(unsafe { a.slice_mut() }),
            None => None,
        };
        let out = self.with_arrays(|arrays| statistics(arrays, &previous, lengths));
        for (k, name) in STATISTIC_NAMES[..4].iter().enumerate() {
            stat.setattr(*name, out[k])?;
        }
        // SAFETY: as above.
        unsafe { self.center.slice_mut() }.copy_from_slice(&out[4..]);
        Ok(())
    }

    /// The mean of the joint-space inertia's diagonal over ``dofs`` (in their order, not
    /// empty): a superset world's ``stat.meaninertia``, the dofs of what it places.
    fn mean_inertia(&self, dofs: Vec<usize>) -> PyResult<f64> {
        if dofs.is_empty() || dofs.iter().any(|&d| d >= self.diagonal.len()) {
            return Err(PyValueError::new_err(
                "dofs: empty, or a dof the model does not have",
            ));
        }
        Ok(self.with_arrays(|arrays| mean_inertia(arrays, dofs)))
    }
}
