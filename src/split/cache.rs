//! The model cache both faces run: a [`CacheCore`] keeps one compiled model per structure
//! (in a [`ModelStore`], its bound) and turns it into any variant of the structure by its
//! [`PatchPlan`](super::PatchPlan), over a [`CacheBackend`]: the face's MuJoCo (the linked C
//! library in `compiled/`, the user's `mujoco` in the Python package). The rules written
//! here once: a miss compiles and keeps; a superset's compile is then patched into the
//! variant (it parks every object as compiled); a patch that is not one of the structure
//! (a body's geoms that compile to another layout) compiles the variant instead, except
//! for a superset, which has no other structure; a caller's model is patched only when it
//! has the structure (its plan's key, or on first sight its [`Signature`]).
//!
//! ```
//! use mjcf_forge::split::{CacheBackend, CacheCore, CacheError, Held, PatchEntry, PatchFailure,
//!     Request, Signature, Statistics};
//!
//! // A backend whose "models" are counters: a compile gives 0, a patch adds one.
//! struct Counting;
//! struct Plan;
//! impl Held for Plan {
//!     fn nbytes(&self) -> usize {
//!         0
//!     }
//! }
//! impl CacheBackend for Counting {
//!     type Model = Box<u32>;
//!     type Plan = Plan;
//!     type Error = String;
//!     fn id(model: &Box<u32>) -> u64 {
//!         &**model as *const u32 as u64
//!     }
//!     fn signature(&self, _model: &Box<u32>) -> Option<Signature> {
//!         None
//!     }
//!     fn stat(&self, _model: &Box<u32>) -> Statistics {
//!         [0.0; 7]
//!     }
//!     fn plan(&mut self, _: &Box<u32>, _: &str, _: u32, _: Statistics) -> Result<Plan, String> {
//!         Ok(Plan)
//!     }
//!     fn patch(&mut self, _: &mut Plan, model: &mut Box<u32>, _: &Request<'_>, _: u64)
//!         -> Result<(), PatchFailure<String>> {
//!         **model += 1;
//!         Ok(())
//!     }
//! }
//!
//! let mut cache = CacheCore::new(4, None, false);
//! let request = Request { key: "a", entries: &[], parked: None, fixed: 0 };
//! let compile = || Ok::<_, String>(Box::new(0));
//! assert_eq!(**cache.model(&mut Counting, &request, compile)?, 0); // compiled
//! assert_eq!(**cache.model(&mut Counting, &request, compile)?, 1); // patched
//! assert_eq!((cache.compiles(), cache.patches()), (1, 1));
//! # Ok::<(), CacheError<String>>(())
//! ```

use std::collections::HashMap;

use super::{Held, ModelStore, PatchEntry, Signature, Statistics};

/// What a variant asks of a cache: its structure key, its patch, and for a superset the
/// root bodies of the objects it parks (whose dofs its `stat.meaninertia` leaves out).
pub struct Request<'a> {
    /// The structure key (the superset's for a superset).
    pub key: &'a str,
    /// The patch, of that structure.
    pub entries: &'a [PatchEntry],
    /// Superset: the root bodies parked; `None`: a model of the variant's own structure.
    pub parked: Option<&'a [String]>,
    /// The statistics the structure's document fixes (bits, as
    /// [`fixed_statistics_mask`](super::fixed_statistics_mask) gives them).
    pub fixed: u32,
}

/// Why a patch did not land.
#[derive(Debug)]
pub enum PatchFailure<E> {
    /// The values are not a patch of the model's structure (the plan's words).
    NotThisStructure(String),
    /// The backend failed: its own error.
    Backend(E),
}

/// Why a cache call failed.
#[derive(Debug)]
pub enum CacheError<E> {
    /// The backend failed (a compile, a call into MuJoCo): its own error.
    Backend(E),
    /// The caller's model has another structure: that of its plan (`found`), or, seen for
    /// the first time, a signature other than the structure's.
    OtherStructure {
        /// The structure key of the model's plan, if it has one.
        found: Option<String>,
    },
    /// The patch is not one of the structure, and no compile can stand in (a superset,
    /// a caller's model).
    NotThisStructure(String),
}

/// What a cache needs of a MuJoCo beyond a compile (which each call takes: the faces
/// compile text, documents, supersets): a model's id, signature and statistics, and its
/// patch plan made and run.
pub trait CacheBackend {
    /// A compiled model, as the cache keeps it.
    type Model;
    /// How one model is patched (the face's [`PatchPlan`](super::PatchPlan)).
    type Plan: Held;
    /// The backend's error.
    type Error;
    /// A model's id, unique while the model lives.
    fn id(model: &Self::Model) -> u64;
    /// What a model holds beyond its plan's bytes (0 where the plan counts the model).
    fn model_bytes(_model: &Self::Model) -> usize {
        0
    }
    /// What tells the model's structure from another's (`None`: this backend's caller
    /// models are not checked).
    fn signature(&self, model: &Self::Model) -> Option<Signature>;
    /// The model's statistics as they stand.
    fn stat(&self, model: &Self::Model) -> Statistics;
    /// The plan of `model`, of structure `key`; `fixed` the statistics its document fixes
    /// (bits), at `values`.
    fn plan(
        &mut self,
        model: &Self::Model,
        key: &str,
        fixed: u32,
        values: Statistics,
    ) -> Result<Self::Plan, Self::Error>;
    /// `request`'s patch written into `model` by its plan, and for a superset the
    /// variant's `stat.meaninertia`; `patches`: the cache's count of patches before this one.
    fn patch(
        &mut self,
        plan: &mut Self::Plan,
        model: &mut Self::Model,
        request: &Request<'_>,
        patches: u64,
    ) -> Result<(), PatchFailure<Self::Error>>;
}

/// A plan the cache keeps, with the structure key of its model.
struct Kept<P> {
    key: String,
    plan: P,
}

impl<P: Held> Held for Kept<P> {
    fn nbytes(&self) -> usize {
        self.plan.nbytes()
    }
}

/// One compiled model per structure, patched per variant, bounded (see the module).
pub struct CacheCore<B: CacheBackend> {
    store: ModelStore<B::Model, Kept<B::Plan>>,
    /// Signatures and compiled statistics of the structures seen, kept past eviction.
    seen: HashMap<String, (Option<Signature>, Statistics)>,
    superset: bool,
    compiles: u64,
    patches: u64,
}

impl<B: CacheBackend> CacheCore<B> {
    /// A cache of at most `max_models` models (at least one) and, when given, about
    /// `max_bytes` of models and scratch data; `superset`: every variant a patch of one
    /// compiled model.
    pub fn new(max_models: usize, max_bytes: Option<usize>, superset: bool) -> Self {
        CacheCore {
            store: ModelStore::new(max_models, max_bytes),
            seen: HashMap::new(),
            superset,
            compiles: 0,
            patches: 0,
        }
    }

    /// Models compiled so far (misses).
    pub fn compiles(&self) -> u64 {
        self.compiles
    }

    /// Patches applied so far.
    pub fn patches(&self) -> u64 {
        self.patches
    }

    /// Counts a patch the caller applied through a plan of this cache
    /// ([`CacheCore::plan_for`]).
    pub fn count_patch(&mut self) {
        self.patches += 1;
    }

    /// How many models it holds.
    pub fn len(&self) -> usize {
        self.store.len()
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.store.is_empty()
    }

    /// Bytes held: every plan's (model and scratch data) and every model's own.
    pub fn nbytes(&self) -> usize {
        self.store.nbytes(B::model_bytes)
    }

    /// The models, least recently used first.
    pub fn models(&self) -> impl Iterator<Item = &B::Model> {
        self.store.models().map(|(_, m)| m)
    }

    /// The plan kept for `model`, if any (no reordering).
    pub fn plan_of(&self, model: &B::Model) -> Option<&B::Plan> {
        self.store.peek_plan(B::id(model)).map(|k| &k.plan)
    }

    /// The variant `request` asks for: the cached model of its structure patched in place,
    /// or on a miss the variant compiled (`compile`) and kept. The model stays the cache's.
    pub fn model(
        &mut self,
        backend: &mut B,
        request: &Request<'_>,
        mut compile: impl FnMut() -> Result<B::Model, B::Error>,
    ) -> Result<&B::Model, CacheError<B::Error>> {
        if self.store.touch(request.key).is_none() {
            self.compile(backend, request, &mut compile)?;
            if !self.superset {
                return self.last();
            }
        }
        match self.patch_last(backend, request) {
            Ok(()) => {}
            // Compiled instead, in place of the cached model (which stays when the
            // compile fails: the cache is then as it was).
            Err(PatchFailure::NotThisStructure(_)) if !self.superset => {
                self.compile(backend, request, &mut compile)?;
            }
            Err(PatchFailure::NotThisStructure(m)) => return Err(CacheError::NotThisStructure(m)),
            Err(PatchFailure::Backend(e)) => return Err(CacheError::Backend(e)),
        }
        self.store.trim(B::id, B::model_bytes);
        self.last()
    }

    /// Patches `model`, a model of `request`'s structure, in place; a model of another
    /// structure is refused (`compile`: the structure's compile, on its first sight).
    pub fn apply(
        &mut self,
        backend: &mut B,
        request: &Request<'_>,
        model: &mut B::Model,
        mut compile: impl FnMut() -> Result<B::Model, B::Error>,
    ) -> Result<(), CacheError<B::Error>> {
        let patches = self.patches;
        let kept = self.plan_entry(backend, request, model, &mut compile, true)?;
        let r = backend.patch(&mut kept.plan, model, request, patches);
        self.patched(r)?;
        self.store.trim(B::id, B::model_bytes);
        Ok(())
    }

    /// The plan of `model` (of `request`'s structure, not checked: the caller's own copy
    /// of a model of this cache), made on first sight (`compile`: the structure's compile,
    /// if never seen); the caller patches through it and counts the patch.
    pub fn plan_for(
        &mut self,
        backend: &mut B,
        request: &Request<'_>,
        model: &B::Model,
        mut compile: impl FnMut() -> Result<B::Model, B::Error>,
    ) -> Result<&mut B::Plan, CacheError<B::Error>> {
        let kept = self.plan_entry(backend, request, model, &mut compile, false)?;
        Ok(&mut kept.plan)
    }

    fn plan_entry(
        &mut self,
        backend: &mut B,
        request: &Request<'_>,
        model: &B::Model,
        compile: &mut dyn FnMut() -> Result<B::Model, B::Error>,
        check: bool,
    ) -> Result<&mut Kept<B::Plan>, CacheError<B::Error>> {
        let (id, key) = (B::id(model), request.key);
        match self.store.peek_plan(id).map(|k| k.key.as_str()) {
            Some(found) if found != key => {
                return Err(CacheError::OtherStructure {
                    found: Some(found.to_string()),
                });
            }
            Some(_) => {}
            None => {
                if !self.seen.contains_key(key) {
                    // The structure's first sight: its compile (kept) says what it is.
                    self.compile(backend, request, compile)?;
                }
                let (signature, stat) = &self.seen[key];
                if check && signature.is_some() && *signature != backend.signature(model) {
                    return Err(CacheError::OtherStructure { found: None });
                }
                let plan = backend
                    .plan(model, key, request.fixed, *stat)
                    .map_err(CacheError::Backend)?;
                let key = key.to_string();
                self.store.add_plan(id, Kept { key, plan });
            }
        }
        self.store
            .plan(id)
            .ok_or_else(|| CacheError::NotThisStructure("the plan is gone".into()))
    }

    /// Compiles `request`'s structure (`compile`) and keeps it as the most recent model,
    /// with its signature, statistics and plan; a superset's compile is not yet any
    /// variant's.
    fn compile(
        &mut self,
        backend: &mut B,
        request: &Request<'_>,
        compile: &mut dyn FnMut() -> Result<B::Model, B::Error>,
    ) -> Result<(), CacheError<B::Error>> {
        let key = request.key;
        let model = compile().map_err(CacheError::Backend)?;
        self.compiles += 1;
        let stat = backend.stat(&model);
        self.seen
            .insert(key.to_string(), (backend.signature(&model), stat));
        let plan = backend
            .plan(&model, key, request.fixed, stat)
            .map_err(CacheError::Backend)?;
        self.store.remove(key, B::id);
        let key_owned = key.to_string();
        self.store.add_plan(
            B::id(&model),
            Kept {
                key: key_owned,
                plan,
            },
        );
        self.store.insert(key, model);
        self.store.trim(B::id, B::model_bytes);
        Ok(())
    }

    /// Patches the most recent model for `request`.
    fn patch_last(
        &mut self,
        backend: &mut B,
        request: &Request<'_>,
    ) -> Result<(), PatchFailure<B::Error>> {
        let id = self.store.last().map(B::id);
        let gone = || PatchFailure::NotThisStructure("the cache holds no model".into());
        let (model, kept) = self
            .store
            .last_and_plan(id.ok_or_else(gone)?)
            .ok_or_else(gone)?;
        backend.patch(&mut kept.plan, model, request, self.patches)?;
        self.patches += 1;
        Ok(())
    }

    /// A patch's failure as the cache's; counts it where it landed.
    fn patched(
        &mut self,
        r: Result<(), PatchFailure<B::Error>>,
    ) -> Result<(), CacheError<B::Error>> {
        match r {
            Ok(()) => {
                self.patches += 1;
                Ok(())
            }
            Err(PatchFailure::NotThisStructure(m)) => Err(CacheError::NotThisStructure(m)),
            Err(PatchFailure::Backend(e)) => Err(CacheError::Backend(e)),
        }
    }

    /// The model the last call gave or kept.
    pub fn last(&self) -> Result<&B::Model, CacheError<B::Error>> {
        self.store
            .last()
            .ok_or_else(|| CacheError::NotThisStructure("the cache holds no model".into()))
    }
}
