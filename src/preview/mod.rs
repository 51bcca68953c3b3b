//! The preview tier: contact sheets of a scene's variants, drawn by MuJoCo's own renderer
//! (builds with the cargo feature `mujoco`).
//!
//! [`contact_sheet`] compiles variants of a [`Scene`](crate::scene::Scene) and renders
//! each into one cell of a grid [`Image`], labelled with its index; [`segment_cells`]
//! draws the same cells as segmentation (the geom of every pixel), which the tests check
//! against the placed objects. The rules that need no renderer (the layout, the image and
//! its PNG, the labels, the free camera's framing, the geom sets) are the sheet tier's
//! (`crate::sheet`), which Python's `Scene.preview` runs too; this tier reads their inputs
//! from the linked MuJoCo and draws. [`Renderer`] is the piece below: a headless OpenGL context
//! (EGL, else OSMesa, opened at run time) in which MuJoCo (`mjv_updateScene`,
//! `mjr_render`, `mjr_overlay`) draws one compiled model from a [`Camera`].
//!
//! - `render.c`: the C side (the GL context; MuJoCo's renderer), compiled by `build.rs`
//!   against the linked MuJoCo's headers, as the FFI's shim is;
//! - `sys.rs`: its declarations; `render.rs`: [`Renderer`], [`Camera`];
//! - `sheet.rs`: [`contact_sheet`], [`segment_cells`].
//!
//! May use: the sheet tier (its rules), the scene tier (variants), the MuJoCo FFI
//! (compiling, the raw model through its `pub(crate)` items) and the tiers below them. Sits above both; only the faces use it.
//!
//! ```no_run
//! use mjcf_forge::preview::{SheetOptions, contact_sheet};
//! use mjcf_forge::scene::Scene;
//!
//! let scene = Scene::demo()?;
//! let indices: Vec<u64> = (0..16).collect();
//! let sheet = contact_sheet(&scene, &indices, &SheetOptions::default())?;
//! sheet.image.write_png(std::path::Path::new("sheet.png"))?;
//! # Ok::<(), mjcf_forge::Errors>(())
//! ```

// The renderer calls into MuJoCo and OpenGL through its own C (`render.c`), as the FFI does.
#![allow(unsafe_code)]

mod render;
mod sheet;
mod sys;

pub use crate::sheet::{GAP, GAP_COLOR, Geoms, Image, Layout};
pub use render::{Camera, MAX_SIDE, Renderer};
pub use sheet::{Sheet, SheetOptions, contact_sheet, segment_cells};
