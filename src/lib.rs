//! mjcf-forge: an arena-allocated MJCF (MuJoCo XML) document engine.
//!
//! The crate is built in tiers, one folder each, every tier using only those below it:
//!
//! | tier | what it is |
//! | --- | --- |
//! | `error.rs` | the one error type, `file:line:col` with the include chain |
//! | `output/` | atomic files, the content-named asset store, tar, the ordered pipeline |
//! | `document/` | one model in an arena: read, inline defaults, prefix, validate, write |
//! | `mujoco/` | the MuJoCo FFI (builds with the `mujoco` feature): compile, inertias |
//! | `model/` | instances with a prefix, merging, geometry and placement offsets |
//! | `split/` | a model as a structure key and a patch: what a model cache patches |
//! | `scene/` | the batch tier: a scene file in, seeded variants out |
//! | `compiled/` | compiled variants at patch cost (builds with the `mujoco` feature) |
//! | `sheet/` | contact sheets' rules without a renderer: layout, image and PNG, labels, camera |
//! | `preview/` | contact sheets of variants, drawn by MuJoCo's renderer (`mujoco` feature) |
//!
//! The faces sit on top: the command line (`src/main.rs`, `src/cli/`) and the Python
//! package (`python/`), both through the public API only.
//!
//! The document tier: [`Document::load`] reads a model exactly as MuJoCo reads it
//! (`<include>` expanded, default classes inlined into explicit attributes, file references
//! absolute) into an arena with interned names, so that cloning, renaming and merging are
//! flat passes. Writing is deterministic.
//!
//! ```
//! use mjcf_forge::Document;
//! let doc = Document::from_str(
//!     r#"<mujoco><default><joint damping="2"/></default>
//!        <worldbody><body><joint name="hinge"/><geom size="0.1"/></body></worldbody></mujoco>"#,
//!     ".",
//! )?;
//! assert_eq!(
//!     doc.to_xml_string(),
//!     r#"<mujoco><worldbody><body><joint name="hinge" damping="2"/><geom size="0.1"/></body></worldbody></mujoco>"#
//! );
//! # Ok::<(), mjcf_forge::Errors>(())
//! ```
#![cfg_attr(not(mjcf_mujoco), forbid(unsafe_code))]
// The tiers that call into MuJoCo's C, `mujoco` (the FFI), `compiled` (the model cache)
// and `preview` (the renderer), opt back in; everything else stays safe.
#![cfg_attr(mjcf_mujoco, deny(unsafe_code))]
#![warn(missing_docs)]

// The tiers (see the table above); each `mod.rs` says what its tier may use.
#[cfg(mjcf_mujoco)]
pub mod compiled;
#[cfg(doctest)]
mod doc_pages;
mod document;
mod error;
mod model;
#[cfg(mjcf_mujoco)]
pub mod mujoco;
pub mod output;
#[cfg(mjcf_mujoco)]
pub mod preview;
pub mod scene;
pub mod sheet;
pub mod split;

/// Entry points for the fuzz targets in `fuzz/`: internals they compare, not a supported API.
#[doc(hidden)]
pub use document::fuzzing;
pub use document::import::NodeMap;
pub use document::inertia::{CompiledInertia, InertiaCompiler};
pub use document::limits::Limits;
pub use document::load_cache::LoadCache;
pub use document::tree::Node;
pub use document::urdf::{UrdfActuators, UrdfImporter, UrdfOptions};
pub use document::vocab;
pub use document::{Document, Section};
pub use error::{Error, ErrorKind, Errors, Interpenetration, Location, Warning};
pub use model::geometry;
pub use model::sort;
pub use model::{
    MergeOptions, MergePart, MergeReport, MujocoModel, Offsets, XmlModel, XmlModelOptions,
};
pub use output::{
    AssetStore, OutputDir, PendingHeader, TarWriter, frame_text_member, write_atomic,
};
