//! `PatchPlan`: one of the user's `MjModel`s patched in place by the split tier's patch
//! plan ([`mjcf_forge::split::PatchPlan`], the one implementation both faces' caches run),
//! over the user's `mujoco`: its arrays in place (`arrays.rs`, `patch.rs`' `Whole`,
//! `body_models.rs`' `ModelArrays`, `statistics.rs`' `Statistics`), its `mj_name2id`,
//! `mj_setConst` and kinematics called up, its body models compiled by the package's
//! `compile_xml` (through `upcalls.rs`). The package's model caches (`_cache.py`,
//! `_doc_cache.py`) hold one per model they patch.

use std::sync::atomic::{AtomicI64, Ordering};
use std::sync::{Mutex, MutexGuard, TryLockError};

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};

use super::arrays::Array;
use super::body_models::PyModelArrays;
use super::patch::Whole;
use super::statistics::PyStatistics;
use crate::errors::mjcf_error;
use crate::upcalls;
use mjcf_forge::split::{
    self, ArrayMut, Carried, LayoutEntry, PatchEntry, PatchFailure, PatchModel, PatchValues,
    STATISTIC_NAMES, StatArrays, Statistics,
};

/// A user's model as the patch plan writes it: the model, its `mujoco`, the arrays a body
/// model is copied into, its option and statistics structs, and the first Python error a
/// call up raised (raised again in place of the plan's message).
struct UserModel {
    model: Py<PyAny>,
    mujoco: Py<PyAny>,
    arrays: PyModelArrays,
    opt: Py<PyAny>,
    stat: Py<PyAny>,
    center: Array<f64>,
    pending: Option<PyErr>,
}

/// The user's scratch `MjData`, with the views the kinematics and statistics read.
struct UserData {
    data: Py<PyAny>,
    qpos: Array<f64>,
    qpos0: Array<f64>,
    statistics: PyStatistics,
    nbytes: usize,
}

/// A body model or unit model the user's `mujoco` compiled, and its arrays.
struct UserPart {
    _model: Py<PyAny>,
    arrays: PyModelArrays,
}

impl split::ModelArrays for UserPart {
    fn floats(&self, name: &str) -> Result<&[f64], String> {
        self.arrays.floats(name)
    }
    fn ints(&self, name: &str) -> Result<&[i32], String> {
        self.arrays.ints(name)
    }
    fn bytes(&self, name: &str) -> Result<&[u8], String> {
        self.arrays.bytes(name)
    }
}

fn missing(name: &str) -> String {
    format!("no array {name} here")
}

impl split::ModelArrays for UserModel {
    fn floats(&self, name: &str) -> Result<&[f64], String> {
        self.arrays.floats(name)
    }
    fn ints(&self, name: &str) -> Result<&[i32], String> {
        self.arrays.ints(name)
    }
    fn bytes(&self, name: &str) -> Result<&[u8], String> {
        self.arrays.bytes(name)
    }
}

/// The array `name` of `arrays`, to write (called only through `&mut UserModel`, which
/// owns `arrays`: the borrow that makes the slice the only view).
#[allow(clippy::mut_from_ref)]
fn writable<'a, T: super::arrays::Element>(
    arrays: &'a ahash::AHashMap<&'static str, Array<T>>,
    name: &str,
) -> Result<&'a mut [T], String> {
    // SAFETY: the only view of this array while the model is borrowed mutably (each array
    // is one entry; the GIL is held and no Python code runs meanwhile).
    arrays
        .get(name)
        .map(|a| unsafe { a.slice_mut() })
        .ok_or_else(|| missing(name))
}

impl split::ModelArraysMut for UserModel {
    fn floats_mut(&mut self, name: &str) -> Result<&mut [f64], String> {
        writable(&self.arrays.floats, name)
    }
    fn bytes_mut(&mut self, name: &str) -> Result<&mut [u8], String> {
        writable(&self.arrays.bytes, name)
    }
    fn ints_mut(&mut self, name: &str) -> Result<&mut [i32], String> {
        writable(&self.arrays.ints, name)
    }
}

impl split::ModelLayout for UserModel {
    fn int(&self, name: &str, i: usize) -> Result<i64, String> {
        Python::attach(|py| {
            self.model
                .bind(py)
                .getattr(name)
                .and_then(|a| a.get_item(i))
                .and_then(|v| v.extract::<i64>())
                .map_err(|_| format!("{name}[{i}]: no such integer"))
        })
    }
    fn len(&self, name: &str) -> Result<usize, String> {
        Python::attach(|py| {
            self.model
                .bind(py)
                .getattr(name)
                .and_then(|a| a.getattr("size"))
                .and_then(|v| v.extract::<usize>())
                .map_err(|_| format!("this MuJoCo's MjModel has no array {name}"))
        })
    }
}

impl UserModel {
    /// `f`'s Python error kept to raise (the first), told as its message.
    fn keep<T>(&mut self, r: PyResult<T>) -> Result<T, String> {
        r.map_err(|e| {
            let message = e.to_string();
            self.pending.get_or_insert(e);
            message
        })
    }

    /// `mujoco.name(model, data)`.
    fn call(&mut self, name: &str, data: &UserData) -> Result<(), String> {
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
    type Part = UserPart;
    type Data = UserData;

    fn target(&mut self, name: &str, _int: bool) -> Result<Whole, String> {
        Python::attach(|py| Whole::of(self.model.bind(py), name)).map_err(|e| e.to_string())
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

    fn write_option(&mut self, field: &str, values: &[f64]) -> Result<(), String> {
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

    fn compile_part(&self, xml: &str) -> Result<UserPart, String> {
        Python::attach(|py| {
            let part = upcalls::get(py, "compile_xml")?.call1((self.mujoco.bind(py), xml))?;
            Ok(UserPart {
                arrays: PyModelArrays::new(&part)?,
                _model: part.unbind(),
            })
        })
        .map_err(|e: PyErr| e.to_string())
    }

    fn make_data(&self) -> Result<UserData, String> {
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
        .map_err(|e: PyErr| e.to_string())
    }

    fn nbytes(&self, data: &UserData) -> usize {
        data.nbytes
    }

    fn set_const(&mut self, data: &mut UserData) -> Result<(), String> {
        self.call("mj_setConst", data)
    }

    fn kinematics(&mut self, data: &mut UserData) -> Result<(), String> {
        // SAFETY: the data's and model's own arrays, distinct, while no Python code runs.
        unsafe { data.qpos.slice_mut() }.copy_from_slice(unsafe { data.qpos0.slice() });
        self.call("mj_kinematics", data)?;
        self.call("mj_comPos", data)
    }

    fn inertia(&mut self, data: &mut UserData) -> Result<(), String> {
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
    ) -> Result<R, String> {
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

    fn set_stat(&mut self, stat: &Statistics) -> Result<(), String> {
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

/// How one compiled model is patched in place, made once per model (the model caches hold
/// one per model they patch): ``mjcf_forge::split::PatchPlan`` over the user's ``mujoco``.
///
/// ``PatchPlan(mujoco, model, key, fixed)``: ``fixed`` the ``(name, value)`` pairs of the
/// statistics the document fixes, as its compile holds them. :meth:`apply` writes a patch
/// (``(object, name, field, value)`` tuples) and what follows from it; :meth:`resolve`,
/// :meth:`write` and :meth:`finish` do the same in steps, for a patch given as its
/// numbers end to end, material names and body models.
///
/// >>> import mujoco
/// >>> from mjcf_forge._mjcf_forge import PatchPlan
/// >>> model = mujoco.MjModel.from_xml_string(
/// ...     '<mujoco><worldbody><body><joint name="j"/><geom size=".1"/></body></worldbody></mujoco>')
/// >>> plan = PatchPlan(mujoco, model, "key", [])
/// >>> plan.apply([("joint", "j", "damping", [0.5])])
/// >>> float(model.dof_damping[0])
/// 0.5
#[pyclass(
    name = "PatchPlan",
    module = "mjcf_forge._mjcf_forge",
    frozen,
    subclass
)]
pub(crate) struct PyPatchPlan {
    /// The model and its plan (one call at a time: a second thread's is refused).
    core: Mutex<Core>,
    /// The layout last resolved, as ``(object, name, field)`` tuples.
    fields: Mutex<Option<Py<PyList>>>,
    /// The model this plan patches.
    #[pyo3(get)]
    model: Py<PyAny>,
    /// Its structure key.
    #[pyo3(get)]
    key: String,
    /// Bytes held: the model and the scratch data.
    #[pyo3(get)]
    nbytes: usize,
    /// The scratch ``MjData``.
    #[pyo3(get)]
    data: Py<PyAny>,
    /// The caller's derivations by layout (a superset cache's tree-by-tree ones).
    #[pyo3(get)]
    derivations: Py<PyDict>,
    derived_at: AtomicI64,
    /// The world patch the layout was last resolved from (`patch_world`).
    source: Mutex<Py<PyAny>>,
}

/// The user's model and the split tier's plan over it.
struct Core {
    user: UserModel,
    plan: split::PatchPlan<UserModel>,
}

/// A patch's entries read: the layout, numbers end to end, material names, body models.
type Read = (Vec<LayoutEntry>, Vec<f64>, Vec<String>, Vec<String>);

/// `patch`'s `(object, name, field, value)` entries read.
fn read(patch: &Bound<'_, PyAny>) -> PyResult<Read> {
    let (mut layout, mut numbers, mut materials, mut bodies) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for entry in patch.try_iter()? {
        let entry = entry?;
        let (object, name, field, value): (String, Bound<'_, PyAny>, String, Bound<'_, PyAny>) =
            entry.extract()?;
        // A name, or the id of an unnamed element (no failed extraction: an error made
        // per entry would cost more than the entry).
        let (name, id) = match name.cast::<PyString>() {
            Ok(text) => (text.to_cow()?.into_owned(), None),
            Err(_) => (String::new(), Some(name.extract::<usize>()?)),
        };
        let carried = if let Ok(text) = value.cast::<PyString>() {
            let text = text.to_cow()?.into_owned();
            if split::MODEL_FIELDS.contains(&field.as_str()) {
                bodies.push(text);
                Carried::BodyModel
            } else {
                materials.push(text);
                Carried::Id
            }
        } else {
            let v: Vec<f64> = value.extract()?;
            let n = v.len();
            numbers.extend(v);
            Carried::Numbers(n)
        };
        layout.push(LayoutEntry {
            object,
            name,
            id,
            field,
            carried,
        });
    }
    Ok((layout, numbers, materials, bodies))
}

impl Core {
    /// The plan's error as Python's: the call up's own, else an `MjcfError`.
    fn error(&mut self, message: String) -> PyErr {
        self.user
            .pending
            .take()
            .unwrap_or_else(|| mjcf_error(vec![message]))
    }
}

/// `lock`'s value, or an error where another call holds it (a second thread, or the
/// caller's derivation calling back).
fn hold<T>(lock: &Mutex<T>) -> PyResult<MutexGuard<'_, T>> {
    match lock.try_lock() {
        Ok(guard) => Ok(guard),
        Err(TryLockError::Poisoned(p)) => Ok(p.into_inner()),
        Err(TryLockError::WouldBlock) => Err(PyRuntimeError::new_err(
            "this PatchPlan is in use by another call",
        )),
    }
}

impl PyPatchPlan {
    /// Bytes held: the model and the scratch data.
    pub(crate) fn nbytes(&self) -> usize {
        self.nbytes
    }

    /// The model this plan patches.
    pub(crate) fn model(&self) -> &Py<PyAny> {
        &self.model
    }

    /// The plan of `model` (of structure `key`); `fixed` the statistics the document
    /// fixes (bits), at `values`.
    pub(crate) fn create(
        py: Python<'_>,
        mujoco: Bound<'_, PyAny>,
        model: Bound<'_, PyAny>,
        key: String,
        fixed: u32,
        values: Statistics,
    ) -> PyResult<Self> {
        let stat = model.getattr("stat")?;
        let user = UserModel {
            arrays: PyModelArrays::new(&model)?,
            center: Array::of(&stat.getattr("center")?, "stat.center", true)?,
            opt: model.getattr("opt")?.unbind(),
            stat: stat.unbind(),
            mujoco: mujoco.unbind(),
            model: model.clone().unbind(),
            pending: None,
        };
        let plan =
            split::PatchPlan::new(&user, &key, fixed, values).map_err(PyValueError::new_err)?;
        let data = plan.data.data.clone_ref(py);
        Ok(PyPatchPlan {
            nbytes: plan.nbytes(),
            core: Mutex::new(Core { user, plan }),
            fields: Mutex::new(None),
            model: model.unbind(),
            key,
            data,
            derivations: PyDict::new(py).unbind(),
            derived_at: AtomicI64::new(-1),
            source: Mutex::new(py.None()),
        })
    }

    /// Writes `entries` (a patch of any layout: resolved again where it is not the last
    /// one's) and what follows (`derive`, as `finish` takes it), then for a superset
    /// (`parked`) the variant's `stat.meaninertia`: the cache core's patch.
    pub(crate) fn patch(
        &self,
        py: Python<'_>,
        entries: &[PatchEntry],
        derive: Option<Bound<'_, PyAny>>,
        parked: Option<&[String]>,
    ) -> Result<(), PatchFailure<PyErr>> {
        let mut core = hold(&self.core).map_err(PatchFailure::Backend)?;
        if !core.plan.is_layout_of(entries) {
            self.new_fields(py, entries)
                .map_err(PatchFailure::Backend)?;
        }
        let r = match derive.filter(|d| !d.is_none()) {
            None => {
                let Core { user, plan } = &mut *core;
                plan.apply_with(user, entries, None)
            }
            Some(derive) => match self.derive_call(py, derive) {
                Ok(mut call) => {
                    let Core { user, plan } = &mut *core;
                    plan.apply_with(user, entries, Some(&mut call))
                }
                Err(e) => return Err(PatchFailure::Backend(e)),
            },
        };
        let r = r.and_then(|()| match parked {
            Some(parked) => {
                let Core { user, plan } = &mut *core;
                plan.variant_inertia(user, parked)
            }
            None => Ok(()),
        });
        r.map_err(|e| match core.user.pending.take() {
            Some(raised) => PatchFailure::Backend(raised),
            None => PatchFailure::NotThisStructure(e),
        })
    }

    /// A superset world's patch as `Superset.worlds` gives it: its numbers end to end
    /// (`numbers`, native-endian `f64` bytes) and its strings (material names and body
    /// models, in entry order), of the layout of `patch0` (resolved when it is not the
    /// patch this plan last resolved); then what follows (`derive`) and the world's
    /// `stat.meaninertia` (`parked`).
    pub(crate) fn patch_world(
        &self,
        py: Python<'_>,
        patch0: &Bound<'_, PyAny>,
        numbers: &[u8],
        strings: Vec<String>,
        derive: Option<Bound<'_, PyAny>>,
        parked: &[String],
    ) -> PyResult<()> {
        let mut core = hold(&self.core)?;
        if !hold(&self.source)?.is(patch0) {
            let (layout, _, _, bodies) = read(patch0)?;
            self.resolve_read(py, &mut core, patch0, layout, &bodies)?;
            *hold(&self.source)? = patch0.clone().unbind();
        }
        let values: Vec<f64> = numbers
            .chunks_exact(8)
            .map(|b| f64::from_ne_bytes(b.try_into().unwrap_or([0; 8])))
            .collect();
        let (mut materials, mut bodies) = (Vec::new(), Vec::new());
        let layout = core.plan.layout();
        let carried = layout
            .iter()
            .filter(|e| !matches!(e.carried, Carried::Numbers(_)));
        for (value, entry) in strings.into_iter().zip(carried) {
            match entry.carried {
                Carried::BodyModel => bodies.push(value),
                _ => materials.push(value),
            }
        }
        let patch = PatchValues {
            numbers: &values,
            materials: &materials,
            bodies: &bodies,
        };
        let Core { user, plan } = &mut *core;
        if let Err(e) = plan.write(user, patch) {
            return Err(core.error(e));
        }
        self.finish_with(py, &mut core, derive)?;
        let Core { user, plan } = &mut *core;
        match plan.variant_inertia(user, parked) {
            Ok(()) => Ok(()),
            Err(e) => Err(core.error(e)),
        }
    }

    /// `entries`' layout as ``(object, name or id, field)`` tuples: the fields a
    /// derivation reads (a new list object per layout).
    fn new_fields(&self, py: Python<'_>, entries: &[PatchEntry]) -> PyResult<()> {
        let fields = PyList::empty(py);
        for e in entries {
            let name = match e.id {
                Some(id) => id.into_pyobject(py)?.into_any(),
                None => PyString::new(py, &e.name).into_any(),
            };
            fields.append((e.object, name, e.field))?;
        }
        *hold(&self.fields)? = Some(fields.unbind());
        *hold(&self.source)? = py.None();
        Ok(())
    }

    /// `derive(model, data, fields)` as the split tier's plan calls a derivation (its
    /// Python error kept, raised in place of the plan's).
    fn derive_call<'py>(
        &self,
        py: Python<'py>,
        derive: Bound<'py, PyAny>,
    ) -> PyResult<impl FnMut(&mut UserModel, &mut UserData) -> Result<bool, String> + 'py> {
        let fields = hold(&self.fields)?
            .as_ref()
            .map_or_else(|| py.None(), |f| f.clone_ref(py).into_any());
        let data = self.data.clone_ref(py);
        Ok(
            move |m: &mut UserModel, _d: &mut UserData| -> Result<bool, String> {
                let r = derive
                    .call1((m.model.bind(py), data.bind(py), fields.bind(py)))
                    .and_then(|v| v.is_truthy());
                m.keep(r)
            },
        )
    }

    fn resolve_read(
        &self,
        py: Python<'_>,
        core: &mut Core,
        patch: &Bound<'_, PyAny>,
        layout: Vec<LayoutEntry>,
        bodies: &[String],
    ) -> PyResult<()> {
        let fields = PyList::empty(py);
        for entry in patch.try_iter()? {
            let entry = entry?;
            let triple = PyTuple::new(
                py,
                [entry.get_item(0)?, entry.get_item(1)?, entry.get_item(2)?],
            )?;
            fields.append(triple)?;
        }
        *hold(&self.fields)? = None;
        if let Err(e) = core.plan.resolve(&mut core.user, layout) {
            return Err(core.error(e));
        }
        core.plan.set_resolved_bodies(bodies);
        *hold(&self.fields)? = Some(fields.unbind());
        *hold(&self.source)? = py.None();
        Ok(())
    }

    fn finish_with(
        &self,
        py: Python<'_>,
        core: &mut Core,
        derive: Option<Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let r = match derive.filter(|d| !d.is_none()) {
            None => core.plan.finish(&mut core.user, None),
            Some(derive) => {
                let mut call = self.derive_call(py, derive)?;
                let Core { user, plan } = core;
                plan.finish(user, Some(&mut call))
            }
        };
        r.map_err(|e| core.error(e))
    }
}

#[pymethods]
impl PyPatchPlan {
    #[new]
    fn new(
        py: Python<'_>,
        mujoco: Bound<'_, PyAny>,
        model: Bound<'_, PyAny>,
        key: String,
        fixed: Vec<(String, Bound<'_, PyAny>)>,
    ) -> PyResult<Self> {
        let mut values = [0.0; 7];
        for (name, value) in &fixed {
            match STATISTIC_NAMES.iter().position(|s| s == name) {
                Some(4) => {
                    let center: Vec<f64> = value.extract()?;
                    if center.len() != 3 {
                        return Err(PyValueError::new_err("stat.center: 3 numbers"));
                    }
                    values[4..].copy_from_slice(&center);
                }
                Some(k) => values[k] = value.extract()?,
                None => return Err(PyValueError::new_err(format!("no statistic {name}"))),
            }
        }
        let mask = split::fixed_statistics_mask(fixed.iter().map(|(n, _)| n.as_str()));
        PyPatchPlan::create(py, mujoco, model, key, mask, values)
    }

    /// The layout last resolved, as ``(object, name, field)`` tuples: one list object per
    /// layout resolved (``None`` before the first).
    #[getter]
    fn fields(&self, py: Python<'_>) -> PyResult<Option<Py<PyList>>> {
        Ok(hold(&self.fields)?.as_ref().map(|f| f.clone_ref(py)))
    }

    /// The caller's patch count after its last derivation (-1: none yet).
    #[getter]
    fn derived_at(&self) -> i64 {
        self.derived_at.load(Ordering::Relaxed)
    }

    #[setter]
    fn set_derived_at(&self, value: i64) {
        self.derived_at.store(value, Ordering::Relaxed);
    }

    /// Where every entry of ``patch`` lands (the next :meth:`write` takes a patch of its
    /// layout); a body model ``patch`` carries is taken as what the model holds.
    fn resolve(&self, py: Python<'_>, patch: &Bound<'_, PyAny>) -> PyResult<()> {
        let (layout, _, _, bodies) = read(patch)?;
        let mut core = hold(&self.core)?;
        self.resolve_read(py, &mut core, patch, layout, &bodies)
    }

    /// Writes ``patch`` and what follows from it (:meth:`finish`), resolving its layout
    /// where it is not the last one's.
    #[pyo3(signature = (patch, derive=None))]
    fn apply(
        &self,
        py: Python<'_>,
        patch: &Bound<'_, PyAny>,
        derive: Option<Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let (layout, numbers, materials, bodies) = read(patch)?;
        let mut core = hold(&self.core)?;
        let resolved = hold(&self.fields)?.is_some();
        if !resolved || core.plan.layout() != layout.as_slice() {
            self.resolve_read(py, &mut core, patch, layout, &bodies)?;
        }
        let values = PatchValues {
            numbers: &numbers,
            materials: &materials,
            bodies: &bodies,
        };
        let Core { user, plan } = &mut *core;
        if let Err(e) = plan.write(user, values) {
            return Err(core.error(e));
        }
        self.finish_with(py, &mut core, derive)
    }

    /// Writes a patch of the resolved layout: its numbers end to end (``values``, a
    /// C-contiguous float64 array), the names of its materials in order, and the body
    /// models of its bodies' geoms.
    #[pyo3(signature = (values, materials, bodies=Vec::new()))]
    fn write(
        &self,
        values: &Bound<'_, PyAny>,
        materials: Vec<String>,
        bodies: Vec<String>,
    ) -> PyResult<()> {
        let values = Array::<f64>::of(values, "values", false)?;
        // SAFETY: the GIL is held and no Python code runs while the slice lives; the
        // values are not the model's.
        let numbers = unsafe { values.slice() };
        let patch = PatchValues {
            numbers,
            materials: &materials,
            bodies: &bodies,
        };
        let mut core = hold(&self.core)?;
        let Core { user, plan } = &mut *core;
        match plan.write(user, patch) {
            Ok(()) => Ok(()),
            Err(e) => Err(core.error(e)),
        }
    }

    /// What follows the values: ``mj_setConst`` (or ``derive(model, data, fields)``, which
    /// writes the same and says whether the data holds the kinematics at ``qpos0``), the
    /// compiler's statistics, and the statistics the document fixes.
    #[pyo3(signature = (derive=None))]
    fn finish(&self, py: Python<'_>, derive: Option<Bound<'_, PyAny>>) -> PyResult<()> {
        let mut core = hold(&self.core)?;
        self.finish_with(py, &mut core, derive)
    }

    /// The mean of the joint-space inertia's diagonal over ``dofs`` (in order, not
    /// empty), from the scratch data as :meth:`finish` left it: a superset world's
    /// ``stat.meaninertia``.
    fn mean_inertia(&self, dofs: Vec<usize>) -> PyResult<f64> {
        let mut core = hold(&self.core)?;
        let nv = core.user.size("nv").unwrap_or(0);
        if dofs.iter().any(|&d| d >= nv) {
            return Err(PyValueError::new_err("dofs: a dof the model does not have"));
        }
        let Core { user, plan } = &mut *core;
        plan.mean_inertia(user, &dofs)
            .map_err(PyValueError::new_err)
    }

    /// Superset: ``model.stat.meaninertia`` as the variant's own model has it, after
    /// :meth:`finish`: the mean of the mass matrix's diagonal over the dofs of what the
    /// variant places, the subtrees of the bodies named ``parked`` left out.
    fn variant_inertia(&self, parked: Vec<String>) -> PyResult<()> {
        let mut core = hold(&self.core)?;
        let Core { user, plan } = &mut *core;
        match plan.variant_inertia(user, &parked) {
            Ok(()) => Ok(()),
            Err(e) => Err(core.error(e)),
        }
    }

    /// How many body-model and unit-model entries the layout last resolved has.
    #[getter]
    fn body_models(&self) -> PyResult<usize> {
        Ok(hold(&self.core)?.plan.body_models())
    }

    /// How many body models and unit models this plan has compiled.
    #[getter]
    fn compiled_parts(&self) -> PyResult<u64> {
        Ok(hold(&self.core)?.plan.compiled_parts())
    }
}
