//! The contact sheet's rules, without a renderer: what both faces draw the same way, the
//! command line over the linked MuJoCo (`preview/`, feature `mujoco`) and Python over the
//! user's `mujoco` package (`python/mjcf_forge/_preview.py`, through the extension).
//!
//! - `layout.rs`: [`Layout`] (where each cell is), [`GAP`], [`GAP_COLOR`];
//! - `image.rs`: [`Image`] (RGB pixels) and its PNG encoding;
//! - `label.rs`: [`draw_label`], a cell's index in bitmap digits, and [`label_scale`];
//! - `camera.rs`: [`FreeCamera::framing`], the free camera that frames a model's bodies,
//!   over the values a face reads from its MuJoCo ([`FramedGeom`]);
//! - `geoms.rs`: [`Geoms`], which geoms are drawn, as the geom groups and group flags a
//!   face sets ([`GeomChoice`]).
//!
//! May use: the error type and the output tier (atomic writes). Builds without MuJoCo.
//!
//! ```
//! use mjcf_forge::sheet::{GAP_COLOR, Image, Layout, draw_label, label_scale};
//!
//! let layout = Layout::new(3, 40, 30, None);
//! let mut sheet = Image::new(layout.width(), layout.height(), GAP_COLOR);
//! for k in 0..3 {
//!     let mut cell = Image::new(40, 30, [200, 200, 200]);
//!     draw_label(&mut cell, &k.to_string(), label_scale(40, 30));
//!     let (x, y) = layout.cell_origin(k);
//!     sheet.blit(&cell, x, y);
//! }
//! assert_eq!(sheet.pixel(41, 0), GAP_COLOR);
//! assert_eq!(&sheet.to_png()?[1..4], b"PNG");
//! # Ok::<(), mjcf_forge::Error>(())
//! ```

mod camera;
mod geoms;
mod image;
mod label;
mod layout;

pub use camera::{FramedGeom, FreeCamera};
pub use geoms::{GeomChoice, Geoms};
pub use image::Image;
pub use label::{draw_label, label_scale};
pub use layout::{GAP, GAP_COLOR, Layout};
