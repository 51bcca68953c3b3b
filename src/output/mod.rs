//! Where outputs go: files that are never partial or clobbered ([`write_atomic`],
//! [`OutputDir`]), asset files gathered under content-derived names so an output folder
//! can be moved ([`AssetStore`]), and a tar stream of a whole output folder
//! ([`TarWriter`]).

mod assets;
mod files;
mod tar;

pub use assets::AssetStore;
pub use files::{AtomicFile, OutputDir, write_atomic};
pub use tar::{PendingHeader, TarWriter, frame_text_member};
