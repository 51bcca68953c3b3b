//! The compiled tier: a scene's variants as MuJoCo models, made at patch cost (builds with
//! the cargo feature `mujoco`).
//!
//! [`ModelCache`] compiles each structure of a [`Scene`](crate::scene::Scene) once and
//! turns that model into any variant of the structure by writing the variant's patch into
//! its arrays. This tier is where whatever hands compiled variants to simulators belongs:
//! model caches, and the per-world arrays batched simulators take.
//!
//! May use: the scene tier (variants, their patches, the superset), the MuJoCo FFI
//! (`crate::mujoco`: compiling, and the raw model through its `pub(crate)` items) and the
//! tiers below them. Sits above both; only the faces (CLI, Python) use it.
//!
//! ```no_run
//! use mjcf_forge::compiled::ModelCache;
//! use mjcf_forge::scene::Scene;
//!
//! let scene = Scene::demo().unwrap();
//! let mut cache = ModelCache::new(&scene, 8, None);
//! println!("{} bodies", cache.model(0).unwrap().sizes().nbody);
//! ```

// The cache writes into MuJoCo's models through its own C (`patch.c`, which `build.rs`
// compiles against the linked MuJoCo's headers), as the FFI tier does.
#![allow(unsafe_code)]

mod cache;

pub use cache::ModelCache;
