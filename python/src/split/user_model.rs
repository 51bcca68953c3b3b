//! The user's `MjModel` as the split tier's rules run over it: [`PatchModel`] (what the
//! patch plan needs: its arrays in place through `arrays.rs`, `patch.rs`' `Whole`,
//! `body_models.rs`' `ModelArrays` and `statistics.rs`' `Statistics`; its `mj_name2id`,
//! `mj_setConst` and kinematics called up; its body models compiled by the package's
//! `compile_xml`, through `upcalls.rs`) and [`TreeModel`] (what a superset's tree-by-tree
//! derivation needs besides: skeletons compiled, MuJoCo's constants, `mj_camlight`).

use std::sync::OnceLock;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use super::arrays::Array;
use super::body_models::PyModelArrays;
use super::patch::Whole;
use super::patch_error;
use super::statistics::PyStatistics;
use crate::upcalls;
use mjcf_forge::Error;
use mjcf_forge::split::{
    self, ArrayMut, PatchModel, STATISTIC_NAMES, StatArrays, Statistics, TreeModel,
};

/// A user's model as the patch plan writes it: the model, its `mujoco`, the arrays a body
/// model is copied into, its option and statistics structs, and the first Python error a
/// call up raised (raised again in place of the plan's message).
pub(super) struct UserModel {
    pub(super) model: Py<PyAny>,
    mujoco: Py<PyAny>,
    arrays: PyModelArrays,
    opt: Py<PyAny>,
    stat: Py<PyAny>,
    center: Array<f64>,
    pub(super) pending: Option<PyErr>,
}

/// The user's scratch `MjData`, with the views the kinematics and statistics read.
pub(super) struct UserData {
    pub(super) data: Py<PyAny>,
    qpos: Array<f64>,
    qpos0: Array<f64>,
    statistics: PyStatistics,
    nbytes: usize,
}

fn missing(name: &str) -> Error {
    patch_error(format!("no array {name} here"))
}

impl split::ModelArrays for UserModel {
    fn floats(&self, name: &str) -> Result<&[f64], Error> {
        self.arrays.floats(name)
    }
    fn ints(&self, name: &str) -> Result<&[i32], Error> {
        self.arrays.ints(name)
    }
    fn bytes(&self, name: &str) -> Result<&[u8], Error> {
        self.arrays.bytes(name)
    }
}

/// The array `name` of `arrays`, to write (called only through `&mut UserModel`, which
/// owns `arrays`: the borrow that makes the slice the only view).
#[allow(clippy::mut_from_ref)]
fn writable<'a, T: super::arrays::Element>(
    arrays: &'a ahash::AHashMap<&'static str, Array<T>>,
    name: &str,
) -> Result<&'a mut [T], Error> {
    // SAFETY: the only view of this array while the model is borrowed mutably (each array
    // is one entry; the GIL is held and no Python code runs meanwhile).
    arrays
        .get(name)
        .map(|a| unsafe { a.slice_mut() })
        .ok_or_else(|| missing(name))
}

impl split::ModelArraysMut for UserModel {
    fn floats_mut(&mut self, name: &str) -> Result<&mut [f64], Error> {
        writable(&self.arrays.floats, name)
    }
    fn bytes_mut(&mut self, name: &str) -> Result<&mut [u8], Error> {
        writable(&self.arrays.bytes, name)
    }
    fn ints_mut(&mut self, name: &str) -> Result<&mut [i32], Error> {
        writable(&self.arrays.ints, name)
    }
}

impl split::ModelLayout for UserModel {
    fn int(&self, name: &str, i: usize) -> Result<i64, Error> {
        Python::attach(|py| {
            self.model
                .bind(py)
                .getattr(name)
                .and_then(|a| a.get_item(i))
                .and_then(|v| v.extract::<i64>())
                .map_err(|_| patch_error(format!("{name}[{i}]: no such integer")))
        })
    }
    fn len(&self, name: &str) -> Result<usize, Error> {
        Python::attach(|py| {
            self.model
                .bind(py)
                .getattr(name)
                .and_then(|a| a.getattr("size"))
                .and_then(|v| v.extract::<usize>())
                .map_err(|_| patch_error(format!("this MuJoCo's MjModel has no array {name}")))
        })
    }
}

impl UserModel {
    /// `model` of the user's `mujoco`, its arrays found once.
    pub(super) fn new(mujoco: Bound<'_, PyAny>, model: Bound<'_, PyAny>) -> PyResult<UserModel> {
        let stat = model.getattr("stat")?;
        let mut arrays = PyModelArrays::new(&model)?;
        arrays.add_tree_arrays(&model)?;
        Ok(UserModel {
            arrays,
            center: Array::of(&stat.getattr("center")?, "stat.center", true)?,
            opt: model.getattr("opt")?.unbind(),
            stat: stat.unbind(),
            mujoco: mujoco.unbind(),
            model: model.unbind(),
            pending: None,
        })
    }

    /// `f`'s Python error kept to raise (the first), told as its message.
    pub(super) fn keep<T>(&mut self, r: PyResult<T>) -> Result<T, Error> {
        r.map_err(|e| {
            let message = e.to_string();
            self.pending.get_or_insert(e);
            patch_error(message)
        })
    }

    /// `mujoco.name(model, data)`.
    fn call(&mut self, name: &str, data: &UserData) -> Result<(), Error> {
        let r = Python::attach(|py| {
            self.mujoco
                .bind(py)
                .getattr(name)?
                .call1((self.model.bind(py), data.data.bind(py)))
                .map(drop)
        });
        self.keep(r)
    }
}

impl PatchModel for UserModel {
    type Target = Whole;
    /// A body model or unit model the user's `mujoco` compiled, by its arrays (which
    /// hold the model).
    type Part = PyModelArrays;
    type Data = UserData;

    fn target(&mut self, name: &str, _int: bool) -> Result<Whole, Error> {
        Python::attach(|py| Whole::of(self.model.bind(py), name))
            .map_err(|e| patch_error(e.to_string()))
    }

    fn target_mut<'a>(&'a mut self, target: &'a Whole) -> ArrayMut<'a> {
        // SAFETY: the only view of the model's array while it is written (the GIL is
        // held, no Python code runs).
        unsafe { target.slice_mut() }
    }

    fn size(&self, name: &str) -> Option<usize> {
        Python::attach(|py| self.model.bind(py).getattr(name).ok()?.extract().ok())
    }

    fn id(&self, object: &str, name: &str) -> Option<usize> {
        let kind = split::PATCH_OBJECTS
            .iter()
            .find(|o| o.object == object)
            .map_or("mjOBJ_MATERIAL", |o| o.obj_type);
        Python::attach(|py| {
            let mujoco = self.mujoco.bind(py);
            let kind = mujoco.getattr("mjtObj").ok()?.getattr(kind).ok()?;
            let id: i64 = mujoco
                .getattr("mj_name2id")
                .ok()?
                .call1((self.model.bind(py), kind, name))
                .ok()?
                .extract()
                .ok()?;
            usize::try_from(id).ok()
        })
    }

    fn has_option(&self, field: &str, _n: usize) -> bool {
        Python::attach(|py| self.opt.bind(py).hasattr(field).unwrap_or(false))
    }

    fn write_option(&mut self, field: &str, values: &[f64]) -> Result<(), Error> {
        let r = Python::attach(|py| {
            let opt = self.opt.bind(py);
            if let [v] = values {
                return opt.setattr(field, *v);
            }
            let a = Array::<f64>::of(&opt.getattr(field)?, field, true)?;
            // SAFETY: the only view of the option while it is written (the GIL is held).
            let whole = unsafe { a.slice_mut() };
            if whole.len() != values.len() {
                return Err(PyValueError::new_err(format!(
                    "this MuJoCo's mjOption has no field {field} of {}",
                    values.len()
                )));
            }
            whole.copy_from_slice(values);
            Ok(())
        });
        self.keep(r)
    }

    fn body_name(&self, body: usize) -> String {
        Python::attach(|py| {
            let name = self
                .model
                .bind(py)
                .call_method1("body", (body,))?
                .getattr("name")?;
            name.extract::<String>()
        })
        .unwrap_or_else(|_| body.to_string())
    }

    fn compile_part(&self, xml: &str) -> Result<PyModelArrays, Error> {
        Python::attach(|py| {
            let part = upcalls::get(py, "compile_xml")?.call1((self.mujoco.bind(py), xml))?;
            PyModelArrays::new(&part)
        })
        .map_err(|e: PyErr| patch_error(e.to_string()))
    }

    fn make_data(&self) -> Result<UserData, Error> {
        Python::attach(|py| {
            let model = self.model.bind(py);
            let data = self.mujoco.bind(py).getattr("MjData")?.call1((model,))?;
            let nbytes: usize = model.getattr("nbuffer")?.extract::<usize>()?
                + data.getattr("nbuffer")?.extract::<usize>()?
                + data.getattr("narena")?.extract::<usize>()?;
            let found = upcalls::get(py, "inertia_diagonal")?.call1((model, &data))?;
            let (inertia, diagonal): (Bound<'_, PyAny>, Bound<'_, PyAny>) = found.extract()?;
            Ok(UserData {
                qpos: Array::of(&data.getattr("qpos")?, "qpos", true)?,
                qpos0: Array::of(&model.getattr("qpos0")?, "qpos0", false)?,
                statistics: PyStatistics::new(model, &data, &inertia, &diagonal)?,
                data: data.unbind(),
                nbytes,
            })
        })
        .map_err(|e: PyErr| patch_error(e.to_string()))
    }

    fn nbytes(&self, data: &UserData) -> usize {
        data.nbytes
    }

    fn set_const(&mut self, data: &mut UserData) -> Result<(), Error> {
        self.call("mj_setConst", data)
    }

    fn kinematics(&mut self, data: &mut UserData) -> Result<(), Error> {
        // SAFETY: the data's and model's own arrays, distinct, while no Python code runs.
        unsafe { data.qpos.slice_mut() }.copy_from_slice(unsafe { data.qpos0.slice() });
        self.call("mj_kinematics", data)?;
        self.call("mj_comPos", data)
    }

    fn inertia(&mut self, data: &mut UserData) -> Result<(), Error> {
        let r = Python::attach(|py| {
            let (mujoco, model) = (self.mujoco.bind(py), self.model.bind(py));
            upcalls::get(py, "make_inertia")?
                .call1((mujoco, model, data.data.bind(py)))
                .map(drop)
        });
        self.keep(r)
    }

    fn with_statistics<R>(
        &mut self,
        data: &UserData,
        f: impl FnOnce(&StatArrays<'_>, &mut [f64]) -> R,
    ) -> Result<R, Error> {
        Ok(data.statistics.with_lengths(f))
    }

    fn stat(&self) -> Statistics {
        let mut out = [0.0; 7];
        Python::attach(|py| {
            let stat = self.stat.bind(py);
            for (k, name) in STATISTIC_NAMES[..4].iter().enumerate() {
                out[k] = stat.getattr(*name).and_then(|v| v.extract()).unwrap_or(0.0);
            }
        });
        // SAFETY: the GIL is held and nothing writes the centre meanwhile.
        out[4..].copy_from_slice(unsafe { self.center.slice() });
        out
    }

    fn set_stat(&mut self, stat: &Statistics) -> Result<(), Error> {
        let r = Python::attach(|py| {
            let s = self.stat.bind(py);
            for (k, name) in STATISTIC_NAMES[..4].iter().enumerate() {
                s.setattr(*name, stat[k])?;
            }
            Ok(())
        });
        // SAFETY: as above.
        unsafe { self.center.slice_mut() }.copy_from_slice(&stat[4..]);
        self.keep(r)
    }
}

/// The enum of MuJoCo's bindings that holds constant `name`, by its prefix.
const ENUMS: [(&str, &str); 5] = [
    ("mjSAMEFRAME_", "mjtSameFrame"),
    ("mjWRAP_", "mjtWrap"),
    ("mjTRN_", "mjtTrn"),
    ("mjEQ_", "mjtEq"),
    ("mjOBJ_", "mjtObj"),
];

/// Whether the user's MuJoCo's `mj_setConst` sets the same-frame flags again (one
/// `mujoco` per process).
static RECOMPUTES_SAMEFRAME: OnceLock<bool> = OnceLock::new();

impl TreeModel for UserModel {
    fn compile_model(&self, xml: &str) -> Result<UserModel, Error> {
        Python::attach(|py| {
            let mujoco = self.mujoco.bind(py);
            let model = upcalls::get(py, "compile_xml")?.call1((mujoco, xml))?;
            UserModel::new(mujoco.clone(), model)
        })
        .map_err(|e: PyErr| patch_error(e.to_string()))
    }

    fn constant(&self, name: &str) -> Option<i32> {
        let (_, kind) = ENUMS.iter().find(|(p, _)| name.starts_with(p))?;
        Python::attach(|py| {
            let value = self
                .mujoco
                .bind(py)
                .getattr(*kind)
                .ok()?
                .getattr(name)
                .ok()?;
            value.extract::<i32>().ok()
        })
    }

    fn recomputes_sameframe(&self) -> Result<bool, Error> {
        if let Some(&known) = RECOMPUTES_SAMEFRAME.get() {
            return Ok(known);
        }
        let probed = self.sameframe_probe()?;
        Ok(*RECOMPUTES_SAMEFRAME.get_or_init(|| probed))
    }

    fn camlight(&mut self, data: &mut UserData) -> Result<(), Error> {
        self.call("mj_camlight", data)
    }

    fn with_data<R>(
        &self,
        data: &UserData,
        names: &[&str],
        f: impl FnOnce(&[&[f64]]) -> R,
    ) -> Result<R, Error> {
        Python::attach(|py| {
            let d = data.data.bind(py);
            let arrays = names
                .iter()
                .map(|n| Array::<f64>::of(&d.getattr(*n)?, n, false))
                .collect::<PyResult<Vec<_>>>()?;
            // SAFETY: the GIL is held and no Python code runs while the slices live; the
            // data's arrays are not the model's.
            let slices: Vec<&[f64]> = arrays.iter().map(|a| unsafe { a.slice() }).collect();
            Ok(f(&slices))
        })
        .map_err(|e: PyErr| patch_error(e.to_string()))
    }
}
