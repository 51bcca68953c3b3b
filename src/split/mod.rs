//! The split tier: a model as a *structure key* and a *patch*.
//!
//! Two documents (or two variants of a scene) with the same structure key compile to
//! models that differ only in the patched values and what MuJoCo's `mj_setConst` derives
//! from them, so a model cache compiles one model per key and patches it into each
//! ([`crate::compiled`]). The rules say which attribute lands in which compiled field,
//! exactly; whatever no rule can write exactly goes into the key.
//!
//! ```
//! use mjcf_forge::Document;
//! use mjcf_forge::split::split_document;
//!
//! let red = Document::from_str(
//!     r#"<mujoco><worldbody><geom name="g" size="0.1" rgba="1 0 0 1"/></worldbody></mujoco>"#,
//!     ".",
//! )?;
//! let blue = Document::from_str(
//!     r#"<mujoco><worldbody><geom name="g" size="0.1" rgba="0 0 1 1"/></worldbody></mujoco>"#,
//!     ".",
//! )?;
//! let (a, b) = (split_document(&red), split_document(&blue));
//! assert_eq!(a.structure_key, b.structure_key);
//! assert_ne!(a.entries, b.entries);
//! # Ok::<(), mjcf_forge::Errors>(())
//! ```
//!
//! Files: `rules.rs` (the attribute-to-field rules, [`PATCHABLE`], the patch entry types),
//! `targets.rs` (the `mjModel` array each entry writes, the arrays no patch changes, the
//! arrays that tell structures apart: the one copy the model caches of both faces read),
//! `landing.rs` (where each patch entry lands in a compiled model and how its numbers are
//! written, for both faces), `plan.rs` (one model patched in place: the patch plan both
//! faces' caches run, over their own MuJoCo), `store.rs` (the models and plans a cache
//! keeps, and the bound on them), `cache.rs` (the model cache both faces run over their
//! MuJoCo: misses, patches, a caller's model checked), `disk.rs` (compiled models kept across processes, by structure,
//! MuJoCo and file contents), `documents.rs` (the document cache
//! both faces run: per-thread pools of models given out, snapshots, `into`, one compile per
//! structure across threads), `signature.rs` (what tells one structure's compiled model
//! from another's), `document.rs` (any document split by reading it), `body_model.rs` (a body's geoms as a
//! model of their own, for what MuJoCo derives from their sizes), `body_copy.rs` (that
//! model's compile copied into a structure's model, for both faces), `geom_masses.rs` (a
//! body's mass properties from its geoms' densities or masses, at patch cost; with
//! `crate::document::rotation`, the compiler's rotations and eigen-decomposition, and `volumes.rs`, its
//! bounding-volume trees), `statistics.rs` (the
//! compiler's statistics at `qpos0`, computed over a model's arrays for both faces),
//! `trees/` (what `mj_setConst` derives for a superset world, tree by tree), `worlds.rs`
//! (which arrays a superset's worlds keep a row of, for both faces). The scene tier reads its
//! drawn variants through the same rules (`scene/patch.rs`).
//!
//! May use: the document tier and `crate::error`. Knows nothing of scenes or of MuJoCo
//! itself: the faces' caches bring theirs (`CacheBackend`, `PatchModel`).

mod body_copy;
mod body_model;
mod cache;
mod disk;
mod document;
mod documents;
mod geom_masses;
mod landing;
mod plan;
mod rules;
mod signature;
mod statistics;
mod store;
mod targets;
mod trees;
mod volumes;
mod worlds;

pub use body_copy::{
    MasslessFrame, ModelArrays, ModelArraysMut, body_model_writes, copy_body_model, massless_frames,
};
pub use cache::{CacheBackend, CacheCore, CacheError, PatchFailure, Request};
pub use disk::{
    DEFAULT_STORE_BYTES, DiskStore, STORE_MB_VAR, STORE_VAR, StoreEntry, StoreError, StoreKey,
    Stored, load_or_compile,
};
pub use document::{
    DocumentPatch, PATCHABLE_OPTIONS, SplitOptions, split_document, split_document_with,
};
pub use documents::{Compiled, DocumentBackend, DocumentCore, POOL, Refused, Step};
pub use geom_masses::{
    BodyMass, FRAME_FLAGS, GeomMass, body_frame_flag, body_mass, frame_flag, write_frame_flags,
    write_geom_masses,
};
pub use landing::{ArrayMut, Carried, Landing, ModelLayout, Run, land};
pub use plan::{Derive, LayoutEntry, PatchModel, PatchPlan, PatchValues};
pub use rules::{PATCHABLE, PatchEntry, PatchValue};
pub use signature::{Signature, SignatureSource};
pub use statistics::{
    STATISTIC_NAMES, StatArrays, Statistics, fixed_statistics, fixed_statistics_mask, keep_fixed,
    mean_inertia, statistics,
};
pub use store::{Held, ModelStore};
pub use targets::{
    BODY_MODELS_KEPT, BULK_PREFIXES, BULK_SIZES, DOF_FIELDS, GEOM_FACTORS, JOINT_TYPES,
    LAYOUTS_KEPT, MASS_DERIVED, MODEL_FIELDS, PATCH_OBJECTS, PatchObject, QPOS_FIELDS,
    SET_CONST_DERIVED, SIGNATURE_ARRAYS, SIGNATURE_SKIPPED_SIZES, STATIC_PREFIXES, joint_widths,
    target_array,
};
pub use trees::{Derivations, FROM_GEOMS, TreeDerivation, TreeModel};
pub use volumes::{Volume, VolumeNode, bounding_volumes};
pub use worlds::WorldRows;

/// A problem of this tier's, in words ([`ErrorKind::Patch`](crate::ErrorKind::Patch)):
/// what the public functions return for their own refusals and for the words of the traits
/// the faces implement.
pub(crate) fn patch_error(message: impl Into<String>) -> crate::Error {
    crate::Error::bare(crate::ErrorKind::Patch(message.into()))
}

pub(crate) use body_model::{UnitCache, body_model_entries, carried_by, unit_model_entries};
pub(crate) use rules::{
    Rules, discarded, dropped, entry, free_joint, massless, normalized, numbers, setting,
};
