//! The mechanism both model caches share: compiled models kept by structure key, least
//! recently used out past a count and a byte bound, and how one model is patched in place
//! (its plan: scratch data for `mj_setConst`, and where each entry of the structure's patch
//! lands, resolved once). [`super::ModelCache`] (a scene's variants) and
//! [`super::DocumentCache`] (any document) sit on it.
//!
//! The C side (`patch.c`) is compiled against the linked MuJoCo's headers, as the FFI's
//! shim is; arrays are found by name through MuJoCo's X-macro table, so no Rust copy of
//! `mjModel`'s layout is needed. Models come from the FFI ([`crate::mujoco`]), which hands
//! over the raw model, its serial number and the writable pointer through `pub(crate)` items.

use std::collections::HashMap;
use std::ffi::CString;
use std::ptr::NonNull;

use super::arrays::{Arrays, array_mut};
use super::body_models::BodyModels;
use super::sys::{
    RawData, mjf_patch_delete_data, mjf_patch_get_stat, mjf_patch_make_data, mjf_patch_name2id,
    mjf_patch_names, mjf_patch_nbytes, mjf_patch_option, mjf_patch_size, mjf_patch_size_name,
};
use crate::mujoco::{CompiledModel, MjModel};
use crate::split::{
    Carried, Landing, PatchEntry, PatchValue, Run, SIGNATURE_ARRAYS, SIGNATURE_SKIPPED_SIZES, land,
};

/// Scratch mjData for `mj_setConst` (which overwrites the qpos of the data it is given).
pub(super) struct Scratch(pub(super) NonNull<RawData>);

// SAFETY: exclusively owned heap data without thread affinity.
unsafe impl Send for Scratch {}

impl Scratch {
    fn new(model: &CompiledModel) -> Result<Scratch, String> {
        // SAFETY: the model is live.
        let d = unsafe { mjf_patch_make_data(model.raw()) };
        NonNull::new(d)
            .map(Scratch)
            .ok_or_else(|| "MuJoCo could not allocate mjData for the model".to_string())
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        // SAFETY: made by mj_makeData, owned here alone.
        unsafe { mjf_patch_delete_data(self.0.as_ptr()) }
    }
}

/// Where one patch entry lands ([`land`], the rule both faces share), with its array found
/// once: its start, element size and count (an option: its `mjOption` field's; a body
/// model: none).
pub(super) struct Target {
    landing: Landing,
    ptr: *mut u8,
    elem: usize,
    count: usize,
}

/// How to patch one model: its structure key, scratch data and resolved targets.
pub(super) struct Plan {
    pub(super) serial: u64,
    pub(super) key: String,
    pub(super) scratch: Scratch,
    fields: Vec<(&'static str, String, Option<usize>, &'static str)>,
    targets: Vec<Target>,
    /// The body models of its bodies compiled so far.
    body_models: BodyModels,
    nbytes: usize,
}

// SAFETY: the raw pointers point into the model the plan belongs to, which is only
// written through `&mut` of that model.
unsafe impl Send for Plan {}

/// What a structure is, to refuse a model of another: every size of its model but
/// [`SIGNATURE_SKIPPED_SIZES`](crate::split::SIGNATURE_SKIPPED_SIZES), its names buffer and
/// the integer arrays [`SIGNATURE_ARRAYS`](crate::split::SIGNATURE_ARRAYS) (the Python
/// caches take the same, from their own MuJoCo).
#[derive(PartialEq)]
pub(super) struct Signature {
    sizes: Vec<i64>,
    names: Vec<u8>,
    arrays: Vec<Vec<u8>>,
}

impl Signature {
    pub(super) fn of(m: &CompiledModel) -> Signature {
        let raw = std::ptr::from_ref(m.raw()).cast_mut();
        let arrays = SIGNATURE_ARRAYS
            .iter()
            .map(|name| {
                let Ok((p, elem, count)) = Arrays(raw).find(name) else {
                    return Vec::new();
                };
                if p.is_null() {
                    return Vec::new();
                }
                // SAFETY: MuJoCo's array holds `count` elements of `elem` bytes.
                unsafe { std::slice::from_raw_parts(p.cast::<u8>(), elem * count) }.to_vec()
            })
            .collect();
        let mut sizes = Vec::new();
        for i in 0.. {
            // SAFETY: a static NUL-terminated name, or null past the last size.
            let name = unsafe { mjf_patch_size_name(i) };
            if name.is_null() {
                break;
            }
            // SAFETY: as above.
            let name = unsafe { std::ffi::CStr::from_ptr(name) }.to_string_lossy();
            if !SIGNATURE_SKIPPED_SIZES.contains(&name.as_ref()) {
                // SAFETY: the model is live; `i` names one of its sizes.
                sizes.push(unsafe { mjf_patch_size(raw, i) });
            }
        }
        let mut len = 0i64;
        // SAFETY: the model is live; its names buffer holds `len` bytes.
        let p = unsafe { mjf_patch_names(raw, &mut len) };
        let names = if p.is_null() || len <= 0 {
            Vec::new()
        } else {
            // SAFETY: as above.
            unsafe { std::slice::from_raw_parts(p.cast::<u8>(), len as usize) }.to_vec()
        };
        Signature {
            sizes,
            names,
            arrays,
        }
    }
}

/// Compiled models by structure key, least recently used first, and the state that
/// patches them.
pub(super) struct Store {
    pub(super) entries: Vec<(String, CompiledModel)>,
    pub(super) state: State,
}

impl Store {
    /// A store of at most `max_models` models (at least one) and, when given, about
    /// `max_bytes` of models and scratch data.
    pub(super) fn new(max_models: usize, max_bytes: Option<usize>) -> Store {
        Store {
            entries: Vec::new(),
            state: State {
                max_models: max_models.max(1),
                max_bytes,
                plans: Vec::new(),
                signatures: HashMap::new(),
                stats: HashMap::new(),
                compiles: 0,
                patches: 0,
            },
        }
    }

    /// Whether a model of structure `key` is cached; if so it becomes the most recent.
    pub(super) fn touch(&mut self, key: &str) -> bool {
        match self.entries.iter().position(|(k, _)| k == key) {
            Some(at) => {
                let entry = self.entries.remove(at);
                self.entries.push(entry);
                true
            }
            None => false,
        }
    }

    /// Keeps `model`, just compiled for structure `key`, as the most recent model: its
    /// signature, its statistics (`fixed`: the bits of those its `<statistic>` sets, as
    /// `mjf_patch_finish` takes them) and its plan, whose bytes count from now on.
    pub(super) fn insert(
        &mut self,
        key: &str,
        model: CompiledModel,
        fixed: u32,
    ) -> Result<(), String> {
        let state = &mut self.state;
        state.compiles += 1;
        let mut stat = [0.0; 7];
        // SAFETY: the model is live; `stat` holds 7 values.
        unsafe { mjf_patch_get_stat(model.raw(), stat.as_mut_ptr()) };
        state.stats.insert(key.to_string(), (fixed, stat));
        state
            .signatures
            .insert(key.to_string(), Signature::of(&model));
        state.plan_of(&model, key)?;
        self.entries.push((key.to_string(), model));
        self.state.trim(&mut self.entries);
        Ok(())
    }

    /// Drops the model of structure `key`, if cached, with its plan.
    pub(super) fn remove(&mut self, key: &str) {
        if let Some(at) = self.entries.iter().position(|(k, _)| k == key) {
            let (_, gone) = self.entries.remove(at);
            self.state.plans.retain(|p| p.serial != gone.serial());
        }
    }

    /// The most recent model.
    pub(super) fn last(&self) -> Option<&CompiledModel> {
        self.entries.last().map(|(_, m)| m)
    }

    /// Patches the most recent model (of structure `key`) with `entries`.
    pub(super) fn patch_last(&mut self, key: &str, entries: &[PatchEntry]) -> Result<(), String> {
        let Some((_, model)) = self.entries.last_mut() else {
            return Err("no model to patch".to_string());
        };
        self.state.patch_model(model, key, entries)
    }

    /// Drops the least recently used models beyond the bounds.
    pub(super) fn trim(&mut self) {
        self.state.trim(&mut self.entries);
    }

    /// Bytes held: the cached models and every plan's scratch data.
    pub(super) fn nbytes(&self) -> usize {
        self.state.nbytes()
    }
}

/// Everything but the cached models (so that a cached model and the plans can be borrowed
/// at once).
pub(super) struct State {
    max_models: usize,
    max_bytes: Option<usize>,
    /// Plans by model serial (cached models' and callers'), least recently used first.
    pub(super) plans: Vec<Plan>,
    pub(super) signatures: HashMap<String, Signature>,
    /// Per structure, the statistics its `<statistic>` fixes (bits as `mjf_patch_finish`
    /// takes them) and the values MuJoCo compiled.
    stats: HashMap<String, (u32, [f64; 7])>,
    pub(super) compiles: u64,
    pub(super) patches: u64,
}

impl State {
    pub(super) fn nbytes(&self) -> usize {
        self.plans.iter().map(|p| p.nbytes).sum()
    }

    /// Drops the least recently used models (and plans) beyond the bounds.
    pub(super) fn trim(&mut self, entries: &mut Vec<(String, CompiledModel)>) {
        while entries.len() > 1
            && (entries.len() > self.max_models
                || self.max_bytes.is_some_and(|b| self.nbytes() > b))
        {
            let (_, gone) = entries.remove(0);
            self.plans.retain(|p| p.serial != gone.serial());
        }
        // Plans of callers' models: as many as cached models are allowed.
        let cached: Vec<u64> = entries.iter().map(|(_, m)| m.serial()).collect();
        let mut extra = self
            .plans
            .iter()
            .filter(|p| !cached.contains(&p.serial))
            .count();
        self.plans.retain(|p| {
            if extra > self.max_models && !cached.contains(&p.serial) {
                extra -= 1;
                false
            } else {
                true
            }
        });
    }

    /// The index of `model`'s plan, made on first sight.
    fn plan_of(&mut self, model: &CompiledModel, key: &str) -> Result<usize, String> {
        if let Some(at) = self.plans.iter().position(|p| p.serial == model.serial()) {
            return Ok(at);
        }
        let scratch = Scratch::new(model)?;
        // SAFETY: model and data are live.
        let nbytes = unsafe { mjf_patch_nbytes(model.raw(), scratch.0.as_ptr()) };
        self.plans.push(Plan {
            serial: model.serial(),
            key: key.to_string(),
            scratch,
            fields: Vec::new(),
            targets: Vec::new(),
            body_models: BodyModels::of(model)?,
            nbytes: usize::try_from(nbytes).unwrap_or(0),
        });
        Ok(self.plans.len() - 1)
    }

    pub(super) fn patch_model(
        &mut self,
        model: &mut CompiledModel,
        key: &str,
        entries: &[PatchEntry],
    ) -> Result<(), String> {
        let at = self.plan_of(model, key)?;
        let plan = &mut self.plans[at];
        let same =
            plan.fields.len() == entries.len()
                && plan.fields.iter().zip(entries).all(|(f, e)| {
                    f.0 == e.object && f.1 == e.name && f.2 == e.id && f.3 == e.field
                });
        if !same {
            plan.targets = resolve(model, entries)?;
            plan.fields = entries
                .iter()
                .map(|e| (e.object, e.name.clone(), e.id, e.field))
                .collect();
        }
        let ptr = model.as_mut_ptr();
        for (t, e) in plan.targets.iter().zip(entries) {
            match (&t.landing, &e.value) {
                (Landing::BodyModel { body }, PatchValue::BodyModel(xml)) if e.field == "geoms" => {
                    plan.body_models.write(ptr, *body, xml)?
                }
                (Landing::BodyModel { .. }, PatchValue::BodyModel(xml)) => {
                    plan.body_models.unit(xml)?
                }
                (Landing::GeomFactors { body, .. }, PatchValue::Numbers(factors)) => plan
                    .body_models
                    .write_masses(ptr, *body, &e.name, factors)?,
                _ => write(ptr, t, &e.value)?,
            }
        }
        let (fixed, stat) = self.stats.get(key).copied().unwrap_or_default();
        // SAFETY: the model and its scratch data are live and of one structure.
        unsafe { super::statistics::finish(ptr, plan.scratch.0.as_ptr(), fixed, &stat) };
        let plan = self.plans.remove(at);
        self.plans.push(plan);
        self.patches += 1;
        Ok(())
    }
}

/// Writes one entry's value at its target (not a body model: its plan writes those).
fn write(model: *mut MjModel, t: &Target, value: &PatchValue) -> Result<(), String> {
    let (run, option);
    let run = match &t.landing {
        Landing::Numbers(r) => r,
        Landing::Option { field, n } => {
            option = Run {
                array: field.clone(),
                offset: 0,
                n: *n,
                runs: 1,
                stride: 0,
                int: false,
                id: false,
            };
            run = &option;
            run
        }
        Landing::BodyModel { .. } | Landing::GeomFactors { .. } => {
            return Err("a body model is written by its plan".into());
        }
    };
    // SAFETY: `ptr` is the start of the live model's array (or option field) of `count`
    // elements of `elem` bytes, found by `resolve`; nothing else views it meanwhile.
    let whole = unsafe { array_mut(t.ptr, t.elem, t.count, run.int) };
    match value {
        PatchValue::Numbers(v) => run.write(whole, v),
        PatchValue::Id { object, name } => {
            let kind = CString::new(*object).map_err(|e| e.to_string())?;
            let c = CString::new(name.as_str()).map_err(|e| e.to_string())?;
            // SAFETY: the model is live; both strings are NUL-terminated.
            let id = unsafe { mjf_patch_name2id(model, kind.as_ptr(), c.as_ptr()) };
            let id = usize::try_from(id).map_err(|_| format!("no {object} named '{name}'"))?;
            run.write_id(whole, id)
        }
        PatchValue::BodyModel(_) => Err("a body model is written by its plan".into()),
    }
}

/// Where every entry lands in `model`: [`land`], with ids found by the linked MuJoCo.
fn resolve(model: &mut CompiledModel, entries: &[PatchEntry]) -> Result<Vec<Target>, String> {
    let arrays = Arrays(model.as_mut_ptr());
    let mut out = Vec::with_capacity(entries.len());
    for e in entries {
        let id = match (e.object, e.id) {
            ("option", _) => None,
            (_, Some(id)) => Some(id),
            (object, None) => {
                let kind = CString::new(object).map_err(|x| x.to_string())?;
                let name = CString::new(e.name.as_str()).map_err(|x| x.to_string())?;
                // SAFETY: the model is live; both strings are NUL-terminated.
                let id = unsafe { mjf_patch_name2id(arrays.0, kind.as_ptr(), name.as_ptr()) };
                Some(usize::try_from(id).map_err(|_| {
                    format!(
                        "the patch names {} '{}', which the compiled model does not have",
                        e.object, e.name
                    )
                })?)
            }
        };
        let carried = match &e.value {
            PatchValue::Numbers(v) => Carried::Numbers(v.len()),
            PatchValue::Id { .. } => Carried::Id,
            PatchValue::BodyModel(_) => Carried::BodyModel,
        };
        let landing = land(e.object, id, e.field, carried, &arrays)
            .map_err(|x| format!("{} '{}': {x}", e.object, e.name))?;
        let (ptr, elem, count) = match &landing {
            Landing::Numbers(run) => arrays.find(&run.array)?,
            Landing::Option { field, n } => option_field(arrays.0, field, *n)?,
            Landing::BodyModel { .. } | Landing::GeomFactors { .. } => (std::ptr::null_mut(), 0, 0),
        };
        out.push(Target {
            landing,
            ptr,
            elem,
            count,
        });
    }
    Ok(out)
}

/// The `mjOption` field `field` of `n` numbers: its address, element size and count.
fn option_field(
    model: *mut MjModel,
    field: &str,
    n: usize,
) -> Result<(*mut u8, usize, usize), String> {
    let c = CString::new(field).map_err(|x| x.to_string())?;
    let (mut elem, mut count) = (0usize, 0usize);
    // SAFETY: the model is live; `c` is NUL-terminated.
    let p = unsafe { mjf_patch_option(model, c.as_ptr(), &mut elem, &mut count) };
    if p.is_null() || elem != std::mem::size_of::<f64>() || count != n {
        return Err(format!(
            "this MuJoCo's mjOption has no field {field} of {n}"
        ));
    }
    Ok((p.cast(), elem, count))
}
