//! The model tier: instances of documents in a scene, and what joins them.
//!
//! - [`instance`]: [`XmlModel`], one instance of a model with its own name prefix and the
//!   semantic lists robot-learning code asks for (robosuite's `MujocoModel` vocabulary);
//! - [`sort`]: robosuite's element sort (`sort_elements`), the one the lists above and the
//!   Python package's `MujocoXMLModel` run, each with its rules;
//! - [`merge`]: one document merged into another (into the world or a named body), with
//!   asset de-duplication and the conversions that keep each part's physics;
//! - [`geometry`]: frames, mesh vertices and bounds, computed as MuJoCo's compiler does,
//!   for placement offsets.
//!
//! May use: the document tier, `crate::error`, and the MuJoCo FFI (`crate::mujoco`, in
//! builds with MuJoCo: a part's inertias compiled alone). Knows nothing of scenes, the
//! compiled-model cache or the faces above.

pub mod geometry;
pub(crate) mod instance;
pub(crate) mod merge;
pub mod sort;

pub use instance::{MujocoModel, Offsets, XmlModel, XmlModelOptions};
pub use merge::{MergeOptions, MergePart, MergeReport};
