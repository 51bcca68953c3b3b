//! What both model caches of the C face run: the split tier's cache core ([`CacheCore`]:
//! models by structure key, least recently used out past a count and a byte bound; misses,
//! patches and a caller's model checked: the rules the Python face's `ModelCache` runs
//! too) over the linked MuJoCo, each model patched by the split tier's `PatchPlan`.
//! [`super::ModelCache`] (a scene's variants) and [`super::DocumentCache`] (any document)
//! sit on it.
//!
//! The C side (`patch.c`) is compiled against the linked MuJoCo's headers, as the FFI's
//! shim is; arrays are found by name through MuJoCo's X-macro table, so no Rust copy of
//! `mjModel`'s layout is needed. Models come from the FFI ([`crate::mujoco`]), which hands
//! over the raw model, its serial number and the writable pointer through `pub(crate)` items.

use super::arrays::Arrays;
use super::sys::{mjf_patch_names, mjf_patch_size, mjf_patch_size_name};
use super::{bare, internal};
use crate::mujoco::CompiledModel;
use crate::split::{
    CacheBackend, CacheCore, CacheError, Derivations, Held, PatchFailure, PatchModel, PatchPlan,
    Request, Signature, SignatureSource, Statistics,
};
use crate::{ErrorKind, Errors};

/// How to patch one model: the split tier's [`PatchPlan`] over the linked MuJoCo, and a
/// superset's tree-by-tree derivations ([`Derivations`]).
pub(super) struct Plan {
    plan: PatchPlan<CompiledModel>,
    trees: Derivations<CompiledModel>,
}

impl Plan {
    /// Where every entry of `entries` lands in `model` (see `PatchPlan::resolve_patch`).
    pub(super) fn resolve(
        &mut self,
        model: &mut CompiledModel,
        entries: &[crate::split::PatchEntry],
    ) -> Result<(), crate::Error> {
        self.plan.resolve_patch(model, entries)
    }
}

impl Held for Plan {
    fn nbytes(&self) -> usize {
        self.plan.nbytes()
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

/// The linked MuJoCo as the split tier's cache core runs it ([`CacheBackend`]): compiled
/// models by serial, their [`PatchPlan`]s, each patch's failure the structure's (a patch
/// that does not land compiles the variant, as the core's rule says).
#[derive(Debug)]
pub(super) struct Linked {
    /// Whether a superset's patches derive tree by tree where their layout allows.
    pub(super) by_tree: bool,
    /// Superset patches derived tree by tree so far.
    pub(super) derived: u64,
}

impl Default for Linked {
    fn default() -> Self {
        Linked {
            by_tree: true,
            derived: 0,
        }
    }
}

/// The cache core over the linked MuJoCo, as both caches of this face keep it.
pub(super) type Core = CacheCore<Linked>;

impl CacheBackend for Linked {
    type Model = CompiledModel;
    type Plan = Plan;
    type Error = Errors;

    fn id(model: &CompiledModel) -> u64 {
        model.serial()
    }

    fn signature(&self, model: &CompiledModel) -> Option<Signature> {
        Some(Signature::of(model))
    }

    fn stat(&self, model: &CompiledModel) -> Statistics {
        model.stat()
    }

    fn plan(
        &mut self,
        model: &CompiledModel,
        key: &str,
        fixed: u32,
        values: Statistics,
    ) -> Result<Plan, Errors> {
        let plan = PatchPlan::new(model, key, fixed, values).map_err(Errors::from)?;
        Ok(Plan {
            plan,
            trees: Derivations::default(),
        })
    }

    fn patch(
        &mut self,
        plan: &mut Plan,
        model: &mut CompiledModel,
        request: &Request<'_>,
        _patches: u64,
    ) -> Result<(), PatchFailure<Errors>> {
        let Plan { plan, trees } = plan;
        let r = plan
            .write_patch(model, request.entries)
            .and_then(|()| trees.finish(plan, model, request.parked, self.by_tree));
        let derived = r.map_err(|e| PatchFailure::NotThisStructure(e.to_string()))?;
        self.derived += u64::from(derived);
        Ok(())
    }
}

/// The core's error as this face's: an [`ErrorKind::OtherStructure`] names the variant
/// (`variant`, `key`); the others are the backend's or the plan's words.
pub(super) fn cache_error(e: CacheError<Errors>, variant: u64, key: &str) -> Errors {
    match e {
        CacheError::Backend(e) => e,
        CacheError::OtherStructure { found } => bare(ErrorKind::OtherStructure {
            variant,
            key: key.to_string(),
            found,
        }),
        CacheError::NotThisStructure(m) => internal(m),
    }
}
