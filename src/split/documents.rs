//! The document cache both faces run: a [`DocumentCore`] keeps per structure the models it
//! has given out (per thread, a few each) with a snapshot of the structure's values as
//! compiled, and turns one of them into any document of the structure by its patch, over
//! a [`DocumentBackend`]: the face's MuJoCo (the linked C library in `compiled/document.rs`,
//! the user's `mujoco` in the Python package's `DocumentCache`).
//!
//! The rules written here once:
//! - a model is *held* while anyone but the cache holds it (the backend says: a simulation
//!   made on it, one of its arrays); a held model is never patched again, except one the
//!   caller hands back (`into`), which is patched itself;
//! - otherwise a free model of the calling thread's is patched, else a copy of one of the
//!   structure's models (made once, kept in the thread's pool; beyond [`POOL`] models the
//!   pool forgets its oldest held ones, whose holders keep them);
//! - before each patch the backend writes the snapshot back (what a caller changed in a
//!   model it was given does not outlive the next call);
//! - a miss compiles: one thread compiles a structure, the others asking for it wait
//!   ([`Step::Wait`]) and then copy its model; the compile runs outside the face's lock;
//! - a patch that is not one of the structure compiles the document in its place (the
//!   structure is replaced); a compile whose layout the model cannot take is the answer
//!   and nothing is kept;
//! - the structures are bounded by count and bytes (the split tier's [`ModelStore`]).
//!
//! ```
//! use mjcf_forge::split::{CacheError, Compiled, DocumentBackend, DocumentCore, Held,
//!     PatchFailure, Request, Step};
//!
//! // A backend whose "models" are counters: a compile gives 0, a patch adds one.
//! struct Counting;
//! struct Counter(u32);
//! impl Held for Counter {
//!     fn nbytes(&self) -> usize {
//!         4
//!     }
//! }
//! impl DocumentBackend for Counting {
//!     type Model = u32;
//!     type Working = Counter;
//!     type Snapshot = Counter;
//!     type Error = String;
//!     fn id(model: &u32) -> u64 {
//!         u64::from(*model)
//!     }
//!     fn model(working: &Counter) -> &u32 {
//!         &working.0
//!     }
//!     fn snapshot(&mut self, _: &u32) -> Result<Counter, String> {
//!         Ok(Counter(0))
//!     }
//!     fn working(&mut self, model: u32, _: &Counter, _: &Request<'_>)
//!         -> Result<Counter, (u32, PatchFailure<String>)> {
//!         Ok(Counter(model))
//!     }
//!     fn held(&self, _: &Counter) -> bool {
//!         false
//!     }
//!     fn copy(&mut self, working: &Counter) -> Result<u32, String> {
//!         Ok(working.0)
//!     }
//!     fn patch(&mut self, working: &mut Counter, _: &Counter, _: &Request<'_>)
//!         -> Result<(), PatchFailure<String>> {
//!         working.0 += 1;
//!         Ok(())
//!     }
//! }
//!
//! let mut cache = DocumentCore::new(4, None);
//! let request = Request { key: "a", entries: &[], parked: None, fixed: 0 };
//! assert!(matches!(cache.model(&mut Counting, &request, &[])?, Step::Compile { replace: false }));
//! let kept = cache.compiled(&mut Counting, &request, Ok(0), false, false)?;
//! assert!(matches!(kept, Compiled::Kept));
//! assert_eq!(cache.given(), Some(&0));
//! assert!(matches!(cache.model(&mut Counting, &request, &[])?, Step::Ready));
//! assert_eq!(cache.given(), Some(&1)); // patched
//! assert_eq!((cache.compiles(), cache.patches()), (1, 1));
//! # Ok::<(), CacheError<String>>(())
//! ```

use std::sync::atomic::{AtomicU64, Ordering};

use super::{CacheError, Held, ModelStore, PatchFailure, Request};

/// Models of one structure a thread's pool keeps beyond held ones: one to patch while a
/// simulation made on the previous one is still alive (robosuite makes its next
/// simulation before it drops the last), and room for a few environments in one process.
pub const POOL: usize = 4;

/// What a document cache needs of a MuJoCo beyond a compile (which the face runs, outside
/// its lock): a model's id, the structure's snapshot, a model made ready to patch (its
/// plan, its views of what the snapshot restores), whether anyone else holds it, a copy
/// of it, and its patch.
pub trait DocumentBackend {
    /// A compiled model, as the cache gives it.
    type Model;
    /// One model of a structure with what patches it (its plan, scratch data, views).
    type Working: Held;
    /// A structure's values as compiled: what is written back before each patch, and the
    /// statistics its document fixes.
    type Snapshot: Held;
    /// The backend's error.
    type Error;
    /// A model's id, unique while the model lives.
    fn id(model: &Self::Model) -> u64;
    /// The model of `working`.
    fn model(working: &Self::Working) -> &Self::Model;
    /// The snapshot of `model`, just compiled.
    fn snapshot(&mut self, model: &Self::Model) -> Result<Self::Snapshot, Self::Error>;
    /// `model` (compiled, or a copy of one of the structure's) made ready to patch: the
    /// snapshot written back, then its plan for `request`'s layout. A layout the model
    /// cannot take gives the model back with [`PatchFailure::NotThisStructure`].
    fn working(
        &mut self,
        model: Self::Model,
        snapshot: &Self::Snapshot,
        request: &Request<'_>,
    ) -> Result<Self::Working, Refused<Self::Model, Self::Error>>;
    /// Whether anyone but the cache holds `working`'s model.
    fn held(&self, working: &Self::Working) -> bool;
    /// A copy of `working`'s model.
    fn copy(&mut self, working: &Self::Working) -> Result<Self::Model, Self::Error>;
    /// `request`'s patch written into `working`'s model, the snapshot written back first.
    fn patch(
        &mut self,
        working: &mut Self::Working,
        snapshot: &Self::Snapshot,
        request: &Request<'_>,
    ) -> Result<(), PatchFailure<Self::Error>>;
}

/// A model given back by [`DocumentBackend::working`], with why it was not made ready.
pub type Refused<M, E> = (M, PatchFailure<E>);

/// What a [`DocumentCore::model`] call asks of its face next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// The document's model is ready: [`DocumentCore::given`].
    Ready,
    /// Compile the document (outside the face's lock), then [`DocumentCore::compiled`];
    /// `replace`: the structure's cached models could not take the patch.
    Compile {
        /// Whether the compile stands in for a failed patch (no other thread waits on it).
        replace: bool,
    },
    /// Another thread compiles the structure: wait until [`DocumentCore::compiling`] says
    /// it is done, then ask again.
    Wait,
}

/// What [`DocumentCore::compiled`] made of a model.
#[derive(Debug)]
pub enum Compiled<M> {
    /// Kept as its structure's model, which is the document's: [`DocumentCore::given`].
    Kept,
    /// Not kept (the model cannot take its structure's layout): this model is the answer.
    Alone(M),
    /// A model of the structure from the store, kept: ask again ([`DocumentCore::model`]),
    /// which patches it into the document.
    Stored,
    /// A model from the store that cannot take the layout: compile the document (without
    /// the store) and hand that in with `replace`.
    Refused,
}

/// A compiled structure: its snapshot, and per thread the models it was given.
struct Structure<B: DocumentBackend> {
    snapshot: B::Snapshot,
    pools: Vec<(u64, Vec<B::Working>)>,
}

impl<B: DocumentBackend> Held for Structure<B> {
    fn nbytes(&self) -> usize {
        self.snapshot.nbytes() + self.workings().map(Held::nbytes).sum::<usize>()
    }
}

impl<B: DocumentBackend> Structure<B> {
    fn workings(&self) -> impl Iterator<Item = &B::Working> {
        self.pools.iter().flat_map(|(_, pool)| pool)
    }

    /// Where the first model whose id is among `ids` sits (pool, index).
    fn find(&self, ids: &[u64]) -> Option<(usize, usize)> {
        self.pools.iter().enumerate().find_map(|(p, (_, pool))| {
            let i = pool
                .iter()
                .position(|w| ids.contains(&B::id(B::model(w))))?;
            Some((p, i))
        })
    }

    /// A model of thread `me` that no one but the cache holds.
    fn free(&self, backend: &B, me: u64) -> Option<(usize, usize)> {
        let p = self.pools.iter().position(|(t, _)| *t == me)?;
        let i = self.pools[p].1.iter().position(|w| !backend.held(w))?;
        Some((p, i))
    }

    /// Adds `working` to thread `me`'s pool (see [`POOL`]); where it sits.
    fn keep(&mut self, backend: &B, me: u64, working: B::Working) -> (usize, usize) {
        let p = match self.pools.iter().position(|(t, _)| *t == me) {
            Some(p) => p,
            None => {
                self.pools.push((me, Vec::new()));
                self.pools.len() - 1
            }
        };
        let pool = &mut self.pools[p].1;
        pool.push(working);
        let newest = pool.len() - 1;
        let mut extra = pool.len().saturating_sub(POOL);
        let mut i = 0;
        pool.retain(|w| {
            let forget = extra > 0 && i != newest && backend.held(w);
            i += 1;
            extra -= usize::from(forget);
            !forget
        });
        (p, pool.len() - 1)
    }
}

/// No plan: the document cache's store keeps structures only.
struct NoPlan;

impl Held for NoPlan {
    fn nbytes(&self) -> usize {
        0
    }
}

/// This thread's number, for the per-thread pools.
fn thread() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    thread_local! {
        static ID: u64 = NEXT.fetch_add(1, Ordering::Relaxed);
    }
    ID.with(|id| *id)
}

/// Compiled models of documents per structure, patched per document (see the module).
pub struct DocumentCore<B: DocumentBackend> {
    store: ModelStore<Structure<B>, NoPlan>,
    /// Structures a thread is compiling.
    compiling: Vec<String>,
    /// The model the last call gave: its structure, pool and index.
    given: Option<(String, usize, usize)>,
    compiles: u64,
    loads: u64,
    patches: u64,
}

impl<B: DocumentBackend> DocumentCore<B> {
    /// A cache of at most `max_models` structures (at least one) and, when given, about
    /// `max_bytes` of models, scratch data and snapshots.
    pub fn new(max_models: usize, max_bytes: Option<usize>) -> Self {
        DocumentCore {
            store: ModelStore::new(max_models, max_bytes),
            compiling: Vec::new(),
            given: None,
            compiles: 0,
            loads: 0,
            patches: 0,
        }
    }

    /// Misses so far: models compiled, or loaded from a store.
    pub fn compiles(&self) -> u64 {
        self.compiles
    }

    /// Of the misses, the models loaded from a store ([`super::DiskStore`]).
    pub fn loads(&self) -> u64 {
        self.loads
    }

    /// Patches applied so far (hits).
    pub fn patches(&self) -> u64 {
        self.patches
    }

    /// How many structures it holds.
    pub fn len(&self) -> usize {
        self.store.len()
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.store.is_empty()
    }

    /// Bytes held: every model and its scratch data, and every structure's snapshot.
    pub fn nbytes(&self) -> usize {
        self.store.nbytes(Structure::<B>::nbytes)
    }

    /// Whether a thread is compiling structure `key` (a waiter asks again once not).
    pub fn compiling(&self, key: &str) -> bool {
        self.compiling.iter().any(|k| k == key)
    }

    /// How many models the calling thread's pool of structure `key` holds.
    pub fn pool_len(&self, key: &str) -> usize {
        let me = thread();
        self.structure(key)
            .and_then(|s| s.pools.iter().find(|(t, _)| *t == me))
            .map_or(0, |(_, pool)| pool.len())
    }

    /// The model the last [`DocumentCore::model`] or [`DocumentCore::compiled`] call
    /// made ready.
    pub fn given(&self) -> Option<&B::Model> {
        let (key, p, i) = self.given.as_ref()?;
        let pool = &self.structure(key)?.pools.get(*p)?.1;
        pool.get(*i).map(B::model)
    }

    fn structure(&self, key: &str) -> Option<&Structure<B>> {
        self.store.models().find(|(k, _)| *k == key).map(|(_, s)| s)
    }

    /// The document `request` stands for: its structure's model patched ([`Step::Ready`]),
    /// or what the face does first. `into`: ids of models the caller hands back, one of
    /// which is patched itself when it is of the structure.
    pub fn model(
        &mut self,
        backend: &mut B,
        request: &Request<'_>,
        into: &[u64],
    ) -> Result<Step, CacheError<B::Error>> {
        self.given = None;
        let key = request.key;
        let me = thread();
        let Some(structure) = self.store.touch(key) else {
            if self.compiling(key) {
                return Ok(Step::Wait);
            }
            self.compiling.push(key.to_string());
            return Ok(Step::Compile { replace: false });
        };
        let found = (!into.is_empty())
            .then(|| structure.find(into))
            .flatten()
            .or_else(|| structure.free(backend, me));
        let (p, i) = match found {
            Some(at) => at,
            None => {
                // A copy of one of the structure's models (what the snapshot restores is
                // written back before its first patch; the bulk data is never written).
                let Some(other) = structure.workings().next() else {
                    return Err(CacheError::NotThisStructure(format!(
                        "structure {key} has no model to copy"
                    )));
                };
                let copy = backend.copy(other).map_err(CacheError::Backend)?;
                let working = match backend.working(copy, &structure.snapshot, request) {
                    Ok(w) => w,
                    Err((_, PatchFailure::Backend(e))) => return Err(CacheError::Backend(e)),
                    Err((_, PatchFailure::NotThisStructure(m))) => {
                        return Err(CacheError::NotThisStructure(m));
                    }
                };
                let at = structure.keep(backend, me, working);
                self.store.trim(|_| 0, Structure::<B>::nbytes);
                at
            }
        };
        let Some(structure) = self.store.touch(key) else {
            return Err(CacheError::NotThisStructure(format!(
                "structure {key} is gone"
            )));
        };
        let Structure { snapshot, pools } = structure;
        match backend.patch(&mut pools[p].1[i], snapshot, request) {
            Ok(()) => {
                self.patches += 1;
                self.given = Some((key.to_string(), p, i));
                Ok(Step::Ready)
            }
            // A value the model cannot take (a material that does not exist, a body's geoms
            // that compile to another layout): MuJoCo's own verdict follows. The model is
            // whole again after its next patch, which writes every entry of the structure.
            Err(PatchFailure::NotThisStructure(_)) => Ok(Step::Compile { replace: true }),
            Err(PatchFailure::Backend(e)) => Err(CacheError::Backend(e)),
        }
    }

    /// The face's compile of `request`'s document (as [`Step::Compile`] asked; `replace`
    /// as it said), kept as its structure's model ([`Compiled::Kept`]: the document's
    /// model is [`DocumentCore::given`]); or, where the model cannot take the structure's
    /// layout, the model itself, kept nowhere ([`Compiled::Alone`]). `stored`: the model
    /// is one of the structure's from a store ([`super::load_or_compile`]), not the
    /// document's compile ([`Compiled::Stored`], [`Compiled::Refused`]). Ends the compile
    /// that other threads wait on, failed or not.
    pub fn compiled(
        &mut self,
        backend: &mut B,
        request: &Request<'_>,
        model: Result<B::Model, B::Error>,
        replace: bool,
        stored: bool,
    ) -> Result<Compiled<B::Model>, CacheError<B::Error>> {
        let key = request.key;
        self.given = None;
        if !replace {
            self.compiling.retain(|k| k != key);
        }
        let model = model.map_err(CacheError::Backend)?;
        self.compiles += 1;
        self.loads += u64::from(stored);
        let snapshot = backend.snapshot(&model).map_err(CacheError::Backend)?;
        let working = match backend.working(model, &snapshot, request) {
            Ok(w) => w,
            // A stored model that cannot take the layout is no answer: the document's own
            // compile is.
            Err((_, PatchFailure::NotThisStructure(_))) if stored => return Ok(Compiled::Refused),
            // A layout this model cannot take (an element the split names that the compile
            // does not have): the compile is the answer, and nothing is kept.
            Err((model, PatchFailure::NotThisStructure(_))) => return Ok(Compiled::Alone(model)),
            Err((_, PatchFailure::Backend(e))) => return Err(CacheError::Backend(e)),
        };
        let mut structure = Structure::<B> {
            snapshot,
            pools: Vec::new(),
        };
        let (p, i) = structure.keep(backend, thread(), working);
        self.store.insert(key, structure);
        self.store.trim(|_| 0, Structure::<B>::nbytes);
        if stored {
            return Ok(Compiled::Stored);
        }
        self.given = Some((key.to_string(), p, i));
        Ok(Compiled::Kept)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Models are numbered; `refuse`: layouts no model takes; `held`: ids someone holds.
    #[derive(Default)]
    struct Numbered {
        next: u32,
        refuse: bool,
        held: Vec<u32>,
        restored: u32,
    }

    struct W(u32);

    impl Held for W {
        fn nbytes(&self) -> usize {
            10
        }
    }

    impl DocumentBackend for Numbered {
        type Model = u32;
        type Working = W;
        type Snapshot = W;
        type Error = String;
        fn id(model: &u32) -> u64 {
            u64::from(*model)
        }
        fn model(working: &W) -> &u32 {
            &working.0
        }
        fn snapshot(&mut self, _: &u32) -> Result<W, String> {
            Ok(W(0))
        }
        fn working(
            &mut self,
            model: u32,
            _: &W,
            _: &Request<'_>,
        ) -> Result<W, (u32, PatchFailure<String>)> {
            if self.refuse {
                return Err((model, PatchFailure::NotThisStructure("no".into())));
            }
            Ok(W(model))
        }
        fn held(&self, working: &W) -> bool {
            self.held.contains(&working.0)
        }
        fn copy(&mut self, _: &W) -> Result<u32, String> {
            self.next += 1;
            Ok(self.next)
        }
        fn patch(&mut self, _: &mut W, _: &W, _: &Request<'_>) -> Result<(), PatchFailure<String>> {
            self.restored += 1;
            Ok(())
        }
    }

    fn request(key: &str) -> Request<'_> {
        Request {
            key,
            entries: &[],
            parked: None,
            fixed: 0,
        }
    }

    fn ready(core: &mut DocumentCore<Numbered>, b: &mut Numbered, key: &str, into: &[u64]) -> u32 {
        let r = request(key);
        match core.model(b, &r, into).unwrap() {
            Step::Ready => *core.given().unwrap(),
            Step::Compile { replace } => {
                b.next += 1;
                let m = b.next;
                match core.compiled(b, &r, Ok(m), replace, false).unwrap() {
                    Compiled::Alone(m) => m,
                    _ => *core.given().unwrap(),
                }
            }
            Step::Wait => panic!("no other thread compiles"),
        }
    }

    #[test]
    fn held_models_are_not_patched_but_copied_and_handed_back_ones_are() {
        let (mut core, mut b) = (DocumentCore::new(4, None), Numbered::default());
        assert_eq!(ready(&mut core, &mut b, "a", &[]), 1);
        assert_eq!(ready(&mut core, &mut b, "a", &[]), 1);
        b.held.push(1);
        assert_eq!(ready(&mut core, &mut b, "a", &[]), 2); // a copy
        assert_eq!(ready(&mut core, &mut b, "a", &[1]), 1); // handed back
        b.held.extend(2..=8);
        for k in 3..=8 {
            assert_eq!(ready(&mut core, &mut b, "a", &[]), k);
        }
        // Beyond POOL, the oldest held models are forgotten (their holders keep them).
        assert_eq!(core.pool_len("a"), POOL);
        assert_eq!((core.compiles(), core.patches()), (1, 9));
    }

    #[test]
    fn a_second_asker_waits_for_the_compile_and_a_refused_layout_keeps_nothing() {
        let (mut core, mut b) = (DocumentCore::new(4, None), Numbered::default());
        let r = request("a");
        assert_eq!(
            core.model(&mut b, &r, &[]).unwrap(),
            Step::Compile { replace: false }
        );
        assert_eq!(core.model(&mut b, &r, &[]).unwrap(), Step::Wait);
        assert!(core.compiling("a"));
        // The compile failed: the waiters are let go, and the next asker compiles.
        assert!(
            core.compiled(&mut b, &r, Err("bad".into()), false, false)
                .is_err()
        );
        assert!(!core.compiling("a") && core.is_empty());
        b.refuse = true;
        assert_eq!(ready(&mut core, &mut b, "a", &[]), 1);
        assert_eq!(ready(&mut core, &mut b, "a", &[]), 2);
        assert!(core.is_empty());
        assert_eq!((core.compiles(), core.patches()), (2, 0));
    }

    #[test]
    fn a_stored_model_is_kept_and_patched_and_a_refused_one_is_compiled() {
        let (mut core, mut b) = (DocumentCore::new(4, None), Numbered::default());
        let r = request("a");
        assert_eq!(
            core.model(&mut b, &r, &[]).unwrap(),
            Step::Compile { replace: false }
        );
        let stored = core.compiled(&mut b, &r, Ok(7), false, true).unwrap();
        assert!(matches!(stored, Compiled::Stored) && core.given().is_none());
        assert_eq!(core.model(&mut b, &r, &[]).unwrap(), Step::Ready);
        assert_eq!(
            (core.given(), core.compiles(), core.loads(), core.patches()),
            (Some(&7), 1, 1, 1)
        );
        // A store's model whose layout is refused is no answer.
        let (mut core, mut b) = (
            DocumentCore::new(4, None),
            Numbered {
                refuse: true,
                ..Default::default()
            },
        );
        core.model(&mut b, &r, &[]).unwrap();
        assert!(matches!(
            core.compiled(&mut b, &r, Ok(7), false, true).unwrap(),
            Compiled::Refused
        ));
        assert!(matches!(
            core.compiled(&mut b, &r, Ok(8), true, false).unwrap(),
            Compiled::Alone(8)
        ));
    }

    #[test]
    fn structures_are_bounded_least_recently_used_out() {
        let (mut core, mut b) = (DocumentCore::new(2, None), Numbered::default());
        for key in ["a", "b", "a", "c"] {
            ready(&mut core, &mut b, key, &[]);
        }
        assert_eq!(core.len(), 2);
        assert!(core.structure("b").is_none() && core.structure("a").is_some());
        assert_eq!(core.nbytes(), 2 * 20);
    }
}
