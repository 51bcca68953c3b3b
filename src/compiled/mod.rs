//! The compiled tier: MuJoCo models made at patch cost (builds with the cargo feature
//! `mujoco`).
//!
//! [`ModelCache`] compiles each structure of a [`Scene`](crate::scene::Scene) once and
//! turns that model into any variant of the structure by writing the variant's patch into
//! its arrays; [`DocumentCache`] does the same for any [`Document`](crate::Document),
//! finding its structure and patch by reading it
//! ([`split_document`](crate::split::split_document)). Both keep their models in one
//! mechanism (`store.rs`: models by structure key, least recently used out, and how a
//! model is patched). This tier is where whatever hands compiled models to simulators
//! belongs: model caches, and the per-world arrays batched simulators take.
//!
//! May use: the scene tier (variants, their patches, the superset, document splits), the
//! MuJoCo FFI (`crate::mujoco`: compiling, and the raw model through its `pub(crate)`
//! items) and the tiers below them. Sits above both; only the faces (CLI, Python) use it.
//!
//! ```no_run
//! use mjcf_forge::compiled::ModelCache;
//! use mjcf_forge::scene::Scene;
//!
//! let scene = Scene::demo().unwrap();
//! let mut cache = ModelCache::new(&scene, 8, None);
//! println!("{} bodies", cache.model(0).unwrap().sizes().nbody);
//! ```

// The caches write into MuJoCo's models through their own C (`patch.c`, which `build.rs`
// compiles against the linked MuJoCo's headers), as the FFI tier does.
#![allow(unsafe_code)]

mod arrays;
mod cache;
mod document;
mod linked;
mod statistics;
mod store;
mod sys;
mod worlds;

pub use cache::ModelCache;

/// An error of this tier's API: one problem of `kind`, at no place in a file.
fn bare(kind: crate::ErrorKind) -> crate::Errors {
    crate::Errors(vec![crate::Error {
        location: None,
        kind,
    }])
}

/// A problem of this tier's own, in words (`ErrorKind::Invalid`).
fn internal(message: String) -> crate::Errors {
    bare(crate::ErrorKind::Invalid(message))
}
pub use document::DocumentCache;
pub use worlds::{Dtype, WorldArrays, WorldField, WorldStatistics};
