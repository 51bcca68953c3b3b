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

use super::arrays::Arrays;
use super::sys::{mjf_patch_names, mjf_patch_size, mjf_patch_size_name};
use crate::mujoco::CompiledModel;
use crate::split::{PatchEntry, PatchModel, PatchPlan, SIGNATURE_ARRAYS, SIGNATURE_SKIPPED_SIZES};

/// How to patch one model: the split tier's [`PatchPlan`] over the linked MuJoCo, by the
/// model's serial.
pub(super) struct Plan {
    pub(super) serial: u64,
    pub(super) plan: PatchPlan<CompiledModel>,
}

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
        state.stats.insert(key.to_string(), (fixed, model.stat()));
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
        self.plans.iter().map(|p| p.plan.nbytes()).sum()
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
        let (fixed, stat) = self.stats.get(key).copied().unwrap_or_default();
        self.plans.push(Plan {
            serial: model.serial(),
            plan: PatchPlan::new(model, key, fixed, stat)?,
        });
        Ok(self.plans.len() - 1)
    }

    /// Writes `entries` into `model` (of structure `key`) and what follows from them;
    /// its plan becomes the most recent.
    pub(super) fn patch_model(
        &mut self,
        model: &mut CompiledModel,
        key: &str,
        entries: &[PatchEntry],
    ) -> Result<(), String> {
        let at = self.plan_of(model, key)?;
        let mut plan = self.plans.remove(at);
        let result = plan.plan.apply(model, entries);
        self.plans.push(plan);
        result?;
        self.patches += 1;
        Ok(())
    }

    /// The plan of `model`, if it has one.
    pub(super) fn plan_mut(&mut self, model: &CompiledModel) -> Option<&mut Plan> {
        self.plans.iter_mut().find(|p| p.serial == model.serial())
    }
}
