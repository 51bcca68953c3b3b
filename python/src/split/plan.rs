//! `PatchPlan`: one of the user's `MjModel`s patched in place by the split tier's patch
//! plan ([`mjcf_forge::split::PatchPlan`], the one implementation both faces' caches run),
//! over the user's `mujoco` (`user_model.rs`), with a superset's tree-by-tree derivation
//! ([`mjcf_forge::split::Derivations`]). The package's model caches (`CacheCore`,
//! `_doc_cache.py`) hold one per model they patch.

use std::sync::{Mutex, MutexGuard, TryLockError};

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyString;

use super::arrays::Array;
use super::user_model::UserModel;
use crate::errors::mjcf_error;
use mjcf_forge::Error;
use mjcf_forge::split::{
    self, Carried, Derivations, LayoutEntry, PatchEntry, PatchFailure, PatchModel, PatchValues,
    STATISTIC_NAMES, Statistics,
};

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
    /// The world patch the layout was last resolved from (`patch_world`).
    source: Mutex<Py<PyAny>>,
}

/// The user's model, the split tier's plan over it, and a superset's tree-by-tree
/// derivations.
struct Core {
    user: UserModel,
    plan: split::PatchPlan<UserModel>,
    trees: Derivations<UserModel>,
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
    fn error(&mut self, error: Error) -> PyErr {
        self.user
            .pending
            .take()
            .unwrap_or_else(|| mjcf_error(vec![error.to_string()]))
    }

    /// What follows the values: `mj_setConst`, or for a superset world (`parked`: the
    /// objects it parks, by root body) with `by_tree` the tree-by-tree derivation where
    /// its layout allows; then for a superset the world's `stat.meaninertia`. Whether the
    /// derivation ran tree by tree.
    fn finish(&mut self, parked: Option<&[String]>, by_tree: bool) -> Result<bool, Error> {
        let Core { user, plan, trees } = self;
        trees.finish(plan, user, parked, by_tree)
    }
}

/// `lock`'s value, or an error where another call holds it (a second thread).
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
        let user = UserModel::new(mujoco, model.clone())?;
        let plan = split::PatchPlan::new(&user, &key, fixed, values)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let data = plan.data.data.clone_ref(py);
        Ok(PyPatchPlan {
            nbytes: plan.nbytes(),
            core: Mutex::new(Core {
                user,
                plan,
                trees: Derivations::default(),
            }),
            model: model.unbind(),
            key,
            data,
            source: Mutex::new(py.None()),
        })
    }

    /// Writes `entries` (a patch of any layout: resolved again where it is not the last
    /// one's) and what follows (`Core::finish`): the cache core's patch. Whether it was
    /// derived tree by tree.
    pub(crate) fn patch(
        &self,
        entries: &[PatchEntry],
        parked: Option<&[String]>,
        by_tree: bool,
    ) -> Result<bool, PatchFailure<PyErr>> {
        let mut core = hold(&self.core).map_err(PatchFailure::Backend)?;
        let r = {
            let Core { user, plan, .. } = &mut *core;
            plan.write_patch(user, entries)
        };
        let r = r.and_then(|()| core.finish(parked, by_tree));
        r.map_err(|e| match core.user.pending.take() {
            Some(raised) => PatchFailure::Backend(raised),
            None => PatchFailure::NotThisStructure(e.to_string()),
        })
    }

    /// Where every entry of `entries` lands (the document cache's check that a model
    /// takes its structure's layout).
    pub(crate) fn resolve_entries(
        &self,
        entries: &[PatchEntry],
    ) -> Result<(), PatchFailure<PyErr>> {
        let mut core = hold(&self.core).map_err(PatchFailure::Backend)?;
        let Core { user, plan, .. } = &mut *core;
        let r = plan.resolve_patch(user, entries);
        r.map_err(|e| match core.user.pending.take() {
            Some(raised) => PatchFailure::Backend(raised),
            None => PatchFailure::NotThisStructure(e.to_string()),
        })
    }

    /// A superset world's patch as `Superset.worlds` gives it: its numbers end to end
    /// (`numbers`, native-endian `f64` bytes) and its strings (material names and body
    /// models, in entry order), of the layout of `patch0` (resolved when it is not the
    /// patch this plan last resolved); then what follows (`Core::finish`, `parked` the
    /// world's parked roots). Whether it was derived tree by tree.
    pub(crate) fn patch_world(
        &self,
        patch0: &Bound<'_, PyAny>,
        numbers: &[u8],
        strings: Vec<String>,
        parked: &[String],
        by_tree: bool,
    ) -> PyResult<bool> {
        let mut core = hold(&self.core)?;
        if !hold(&self.source)?.is(patch0) {
            let (layout, _, _, bodies) = read(patch0)?;
            self.resolve_read(&mut core, layout, &bodies)?;
            *hold(&self.source)? = patch0.clone().unbind();
        }
        let values: Vec<f64> = numbers
            .chunks_exact(8)
            .map(|b| f64::from_ne_bytes(b.try_into().unwrap_or([0; 8])))
            .collect();
        let (mut materials, mut bodies) = (Vec::new(), Vec::new());
        let carried = core
            .plan
            .layout()
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
        let r = {
            let Core { user, plan, .. } = &mut *core;
            plan.write(user, patch)
        };
        match r.and_then(|()| core.finish(Some(parked), by_tree)) {
            Ok(derived) => Ok(derived),
            Err(e) => Err(core.error(e)),
        }
    }

    fn resolve_read(
        &self,
        core: &mut Core,
        layout: Vec<LayoutEntry>,
        bodies: &[String],
    ) -> PyResult<()> {
        if let Err(e) = core.plan.resolve(&mut core.user, layout) {
            return Err(core.error(e));
        }
        core.plan.set_resolved_bodies(bodies);
        *hold(&self.source)? = Python::attach(|py| py.None());
        Ok(())
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

    /// Where every entry of ``patch`` lands (the next :meth:`write` takes a patch of its
    /// layout); a body model ``patch`` carries is taken as what the model holds.
    fn resolve(&self, patch: &Bound<'_, PyAny>) -> PyResult<()> {
        let (layout, _, _, bodies) = read(patch)?;
        let mut core = hold(&self.core)?;
        self.resolve_read(&mut core, layout, &bodies)
    }

    /// Writes ``patch`` and what follows from it (:meth:`finish`), resolving its layout
    /// where it is not the last one's.
    fn apply(&self, patch: &Bound<'_, PyAny>) -> PyResult<()> {
        let (layout, numbers, materials, bodies) = read(patch)?;
        let mut core = hold(&self.core)?;
        if core.plan.layout() != layout.as_slice() {
            self.resolve_read(&mut core, layout, &bodies)?;
        }
        let values = PatchValues {
            numbers: &numbers,
            materials: &materials,
            bodies: &bodies,
        };
        let r = {
            let Core { user, plan, .. } = &mut *core;
            plan.write(user, values)
        };
        match r.and_then(|()| core.finish(None, false)) {
            Ok(_) => Ok(()),
            Err(e) => Err(core.error(e)),
        }
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
        let Core { user, plan, .. } = &mut *core;
        match plan.write(user, patch) {
            Ok(()) => Ok(()),
            Err(e) => Err(core.error(e)),
        }
    }

    /// What follows the values: ``mj_setConst``, the compiler's statistics, and the
    /// statistics the document fixes.
    fn finish(&self) -> PyResult<()> {
        let mut core = hold(&self.core)?;
        match core.finish(None, false) {
            Ok(_) => Ok(()),
            Err(e) => Err(core.error(e)),
        }
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
        let Core { user, plan, .. } = &mut *core;
        plan.mean_inertia(user, &dofs)
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Superset: ``model.stat.meaninertia`` as the variant's own model has it, after
    /// :meth:`finish`: the mean of the mass matrix's diagonal over the dofs of what the
    /// variant places, the subtrees of the bodies named ``parked`` left out.
    fn variant_inertia(&self, parked: Vec<String>) -> PyResult<()> {
        let mut core = hold(&self.core)?;
        let Core { user, plan, .. } = &mut *core;
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

    /// Superset patches of this plan derived tree by tree (not by ``mj_setConst``).
    #[getter]
    fn by_tree(&self) -> PyResult<u64> {
        Ok(hold(&self.core)?.trees.by_tree)
    }
}
