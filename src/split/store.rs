//! What both faces' model caches keep, and the one rule that bounds it: a [`ModelStore`]
//! of models by structure key (least recently used first) and of patch plans by model
//! (the cache's own models' and its callers'), bounded by a count and about a number of
//! bytes. The cache cores keep it: [`CacheCore`](super::CacheCore) models and their
//! plans, [`DocumentCore`](super::DocumentCore) structures, each counting its own bytes.
//!
//! ```
//! use mjcf_forge::split::{Held, ModelStore};
//!
//! struct Plan(usize);
//! impl Held for Plan {
//!     fn nbytes(&self) -> usize {
//!         self.0
//!     }
//! }
//! // Two models at most; a model is its own id here.
//! let mut store: ModelStore<u64, Plan> = ModelStore::new(2, None);
//! for (key, id) in [("a", 1), ("b", 2), ("c", 3)] {
//!     store.insert(key, id);
//!     store.add_plan(id, Plan(10));
//!     store.trim(|m| *m, |_| 0);
//! }
//! assert!(store.touch("a").is_none()); // the least recently used went first
//! assert_eq!((store.len(), store.nbytes(|_| 0)), (2, 20));
//! // Plans of callers' models (not cached): as many as models are allowed, oldest out.
//! for caller in [10, 11, 12] {
//!     store.add_plan(caller, Plan(1));
//! }
//! store.trim(|m| *m, |_| 0);
//! assert!(store.peek_plan(10).is_none() && store.peek_plan(12).is_some());
//! assert_eq!(store.nbytes(|_| 0), 22);
//! ```

/// Something a store keeps that holds memory.
pub trait Held {
    /// The bytes it holds.
    fn nbytes(&self) -> usize;
}

/// Models by structure key and plans by model id, least recently used first, bounded.
pub struct ModelStore<M, P> {
    entries: Vec<(String, M)>,
    plans: Vec<(u64, P)>,
    max_models: usize,
    max_bytes: Option<usize>,
}

impl<M, P: Held> ModelStore<M, P> {
    /// A store of at most `max_models` models (at least one) and their plans, and as many
    /// plans of other models; when given, about `max_bytes` in all (the most recent model
    /// always stays).
    pub fn new(max_models: usize, max_bytes: Option<usize>) -> Self {
        ModelStore {
            entries: Vec::new(),
            plans: Vec::new(),
            max_models: max_models.max(1),
            max_bytes,
        }
    }

    /// How many models it holds.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether it holds no model.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The model of structure `key`, which becomes the most recent.
    pub fn touch(&mut self, key: &str) -> Option<&mut M> {
        let at = self.entries.iter().position(|(k, _)| k == key)?;
        let entry = self.entries.remove(at);
        self.entries.push(entry);
        self.entries.last_mut().map(|(_, m)| m)
    }

    /// Keeps `model` as the most recent, of structure `key` (in place of one it held).
    pub fn insert(&mut self, key: &str, model: M) {
        self.entries.retain(|(k, _)| k != key);
        self.entries.push((key.to_string(), model));
    }

    /// The model of structure `key`, taken out with its plan (`id`: a model's id).
    pub fn remove(&mut self, key: &str, id: impl Fn(&M) -> u64) -> Option<M> {
        let at = self.entries.iter().position(|(k, _)| k == key)?;
        let (_, gone) = self.entries.remove(at);
        let gone_id = id(&gone);
        self.plans.retain(|(i, _)| *i != gone_id);
        Some(gone)
    }

    /// The most recent model.
    pub fn last(&self) -> Option<&M> {
        self.entries.last().map(|(_, m)| m)
    }

    /// The most recent model, to patch.
    pub fn last_mut(&mut self) -> Option<&mut M> {
        self.entries.last_mut().map(|(_, m)| m)
    }

    /// The most recent model and the plan of the model of id `id` (which becomes the most
    /// recent plan), borrowed at once.
    pub fn last_and_plan(&mut self, id: u64) -> Option<(&mut M, &mut P)> {
        let at = self.plans.iter().position(|(i, _)| *i == id)?;
        let entry = self.plans.remove(at);
        self.plans.push(entry);
        let plan = self.plans.last_mut().map(|(_, p)| p)?;
        let model = self.entries.last_mut().map(|(_, m)| m)?;
        Some((model, plan))
    }

    /// The models, least recently used first.
    pub fn models(&self) -> impl Iterator<Item = (&str, &M)> {
        self.entries.iter().map(|(k, m)| (k.as_str(), m))
    }

    /// The plan of the model of id `id`, which becomes the most recent plan.
    pub fn plan(&mut self, id: u64) -> Option<&mut P> {
        let at = self.plans.iter().position(|(i, _)| *i == id)?;
        let entry = self.plans.remove(at);
        self.plans.push(entry);
        self.plans.last_mut().map(|(_, p)| p)
    }

    /// The plan of the model of id `id`, as it stands (no reordering).
    pub fn peek_plan(&self, id: u64) -> Option<&P> {
        self.plans.iter().find(|(i, _)| *i == id).map(|(_, p)| p)
    }

    /// Keeps `plan`, of the model of id `id`, as the most recent plan.
    pub fn add_plan(&mut self, id: u64, plan: P) {
        self.plans.retain(|(i, _)| *i != id);
        self.plans.push((id, plan));
    }

    /// Bytes held: every plan's, and every model's own (`model_bytes`: what a model holds
    /// beyond its plan's count, 0 where its plan counts it).
    pub fn nbytes(&self, model_bytes: impl Fn(&M) -> usize) -> usize {
        self.plans.iter().map(|(_, p)| p.nbytes()).sum::<usize>()
            + self
                .entries
                .iter()
                .map(|(_, m)| model_bytes(m))
                .sum::<usize>()
    }

    /// The bound: the least recently used models out (with their plans) while there are
    /// more than `max_models` or more than `max_bytes` are held, the most recent one
    /// always kept; then the least recently used plans of other models (callers') beyond
    /// `max_models` of them. Returns the keys of the models dropped.
    pub fn trim(
        &mut self,
        id: impl Fn(&M) -> u64,
        model_bytes: impl Fn(&M) -> usize,
    ) -> Vec<String> {
        let mut dropped = Vec::new();
        while self.entries.len() > 1
            && (self.entries.len() > self.max_models
                || self
                    .max_bytes
                    .is_some_and(|b| self.nbytes(&model_bytes) > b))
        {
            let (key, gone) = self.entries.remove(0);
            let gone_id = id(&gone);
            self.plans.retain(|(i, _)| *i != gone_id);
            dropped.push(key);
        }
        let cached: Vec<u64> = self.entries.iter().map(|(_, m)| id(m)).collect();
        let mut extra = self
            .plans
            .iter()
            .filter(|(i, _)| !cached.contains(i))
            .count();
        let max = self.max_models;
        self.plans.retain(|(i, _)| {
            if extra > max && !cached.contains(i) {
                extra -= 1;
                false
            } else {
                true
            }
        });
        dropped
    }
}
