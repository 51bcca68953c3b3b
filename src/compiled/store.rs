//! The mechanism both model caches of the C face share: compiled models and their plans in
//! the split tier's `ModelStore` (by structure key, least recently used out past a count
//! and a byte bound: the rule the Python face's caches keep too), each patched by the split
//! tier's `PatchPlan`, with each structure's signature and fixed statistics.
//! [`super::ModelCache`] (a scene's variants) and [`super::DocumentCache`] (any document)
//! sit on it.
//!
//! The C side (`patch.c`) is compiled against the linked MuJoCo's headers, as the FFI's
//! shim is; arrays are found by name through MuJoCo's X-macro table, so no Rust copy of
//! `mjModel`'s layout is needed. Models come from the FFI ([`crate::mujoco`]), which hands
//! over the raw model, its serial number and the writable pointer through `pub(crate)` items.

use std::collections::HashMap;

use super::arrays::Arrays;
use super::sys::{mjf_patch_names, mjf_patch_size, mjf_patch_size_name};
use crate::mujoco::CompiledModel;
use crate::split::{
    Held, ModelStore, PatchEntry, PatchModel, PatchPlan, Signature, SignatureSource,
};

/// How to patch one model: the split tier's [`PatchPlan`] over the linked MuJoCo.
pub(super) struct Plan(pub(super) PatchPlan<CompiledModel>);

impl Held for Plan {
    fn nbytes(&self) -> usize {
        self.0.nbytes()
    }
}

/// The linked MuJoCo's model as the split tier's [`Signature`] reads it.
impl SignatureSource for CompiledModel {
    fn sizes(&self) -> Vec<(String, i64)> {
        let raw = self.raw();
        let mut sizes = Vec::new();
        for i in 0.. {
            // SAFETY: a static NUL-terminated name, or null past the last size.
            let name = unsafe { mjf_patch_size_name(i) };
            if name.is_null() {
                break;
            }
            // SAFETY: as above.
            let name = unsafe { std::ffi::CStr::from_ptr(name) }.to_string_lossy();
            // SAFETY: the model is live; `i` names one of its sizes.
            sizes.push((name.into_owned(), unsafe { mjf_patch_size(raw, i) }));
        }
        sizes
    }

    fn names_buffer(&self) -> Vec<u8> {
        let mut len = 0i64;
        // SAFETY: the model is live; its names buffer holds `len` bytes.
        let p = unsafe { mjf_patch_names(self.raw(), &mut len) };
        if p.is_null() || len <= 0 {
            return Vec::new();
        }
        // SAFETY: as above.
        unsafe { std::slice::from_raw_parts(p.cast::<u8>(), len as usize) }.to_vec()
    }

    fn array_bytes(&self, name: &str) -> Vec<u8> {
        let raw = std::ptr::from_ref(self.raw()).cast_mut();
        let Ok((p, elem, count)) = Arrays(raw).find(name) else {
            return Vec::new();
        };
        if p.is_null() {
            return Vec::new();
        }
        // SAFETY: MuJoCo's array holds `count` elements of `elem` bytes.
        unsafe { std::slice::from_raw_parts(p.cast::<u8>(), elem * count) }.to_vec()
    }
}

/// Compiled models by structure key and plans by model serial, in the split tier's
/// [`ModelStore`] (its bound), with what the caches know of each structure.
pub(super) struct Store {
    kept: ModelStore<CompiledModel, Plan>,
    pub(super) signatures: HashMap<String, Signature>,
    /// Per structure, the statistics its `<statistic>` fixes (bits as `keep_fixed` takes
    /// them) and the values MuJoCo compiled.
    stats: HashMap<String, (u32, [f64; 7])>,
    pub(super) compiles: u64,
    pub(super) patches: u64,
}

/// A model's serial: its id in the store.
fn serial(m: &CompiledModel) -> u64 {
    m.serial()
}

/// What a model holds beyond its plan's count (the plan counts the model).
fn no_bytes(_: &CompiledModel) -> usize {
    0
}

impl Store {
    /// A store of at most `max_models` models (at least one) and, when given, about
    /// `max_bytes` of models and scratch data.
    pub(super) fn new(max_models: usize, max_bytes: Option<usize>) -> Store {
        Store {
            kept: ModelStore::new(max_models, max_bytes),
            signatures: HashMap::new(),
            stats: HashMap::new(),
            compiles: 0,
            patches: 0,
        }
    }

    /// How many models are cached.
    pub(super) fn len(&self) -> usize {
        self.kept.len()
    }

    /// Whether a model of structure `key` is cached; if so it becomes the most recent.
    pub(super) fn touch(&mut self, key: &str) -> bool {
        self.kept.touch(key).is_some()
    }

    /// Keeps `model`, just compiled for structure `key`, as the most recent model: its
    /// signature, its statistics (`fixed`: the bits of those its `<statistic>` sets) and
    /// its plan, whose bytes count from now on.
    pub(super) fn insert(
        &mut self,
        key: &str,
        model: CompiledModel,
        fixed: u32,
    ) -> Result<(), String> {
        self.compiles += 1;
        let stat = model.stat();
        self.stats.insert(key.to_string(), (fixed, stat));
        self.signatures
            .insert(key.to_string(), Signature::of(&model));
        let plan = PatchPlan::new(&model, key, fixed, stat)?;
        self.kept.add_plan(model.serial(), Plan(plan));
        self.kept.insert(key, model);
        self.trim();
        Ok(())
    }

    /// Drops the model of structure `key`, if cached, with its plan.
    pub(super) fn remove(&mut self, key: &str) {
        self.kept.remove(key, serial);
    }

    /// The most recent model.
    pub(super) fn last(&self) -> Option<&CompiledModel> {
        self.kept.last()
    }

    /// The structure key of the plan of `model`, if it has one.
    pub(super) fn plan_key(&self, model: &CompiledModel) -> Option<&str> {
        self.kept
            .peek_plan(model.serial())
            .map(|p| p.0.key.as_str())
    }

    /// Calls `f` with the plan of `model` (of structure `key`; `None`: the most recent
    /// cached model) and the model, the plan made on first sight; the plan becomes the
    /// most recent.
    pub(super) fn with_plan<R>(
        &mut self,
        outside: Option<&mut CompiledModel>,
        key: &str,
        f: impl FnOnce(&mut PatchPlan<CompiledModel>, &mut CompiledModel) -> Result<R, String>,
    ) -> Result<R, String> {
        let id = match &outside {
            Some(m) => m.serial(),
            None => self.kept.last().map(serial).ok_or("no model to patch")?,
        };
        if self.kept.peek_plan(id).is_none() {
            let (fixed, stat) = self.stats.get(key).copied().unwrap_or_default();
            let model = match &outside {
                Some(m) => &**m,
                None => self.kept.last().ok_or("no model to patch")?,
            };
            let plan = PatchPlan::new(model, key, fixed, stat)?;
            self.kept.add_plan(id, Plan(plan));
        }
        match outside {
            Some(model) => {
                let plan = self.kept.plan(id).ok_or("the plan is gone")?;
                f(&mut plan.0, model)
            }
            None => {
                let (model, plan) = self.kept.last_and_plan(id).ok_or("the plan is gone")?;
                f(&mut plan.0, model)
            }
        }
    }

    /// Patches the most recent model (of structure `key`) with `entries`.
    pub(super) fn patch_last(&mut self, key: &str, entries: &[PatchEntry]) -> Result<(), String> {
        self.with_plan(None, key, |plan, model| plan.apply(model, entries))?;
        self.patches += 1;
        Ok(())
    }

    /// Drops the least recently used models beyond the bounds.
    pub(super) fn trim(&mut self) {
        self.kept.trim(serial, no_bytes);
    }

    /// Bytes held: the cached models and every plan's scratch data.
    pub(super) fn nbytes(&self) -> usize {
        self.kept.nbytes(no_bytes)
    }
}
