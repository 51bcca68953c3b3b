//! Where outputs go: files that are never partial or clobbered ([`write_atomic`],
//! [`OutputDir`]), asset files gathered under content-derived names so an output folder
//! can be moved ([`AssetStore`]), a tar stream of a whole output folder
//! ([`TarWriter`]), and things made in parallel but consumed in order, in bounded memory
//! ([`for_each_ordered`]).
//!
//! The bottom tier, below whatever writes: it may use `crate::error` only and knows no
//! documents (the document tier rewrites a document's file references with an
//! [`AssetStore`]; the batch tier and the command line drive the rest).

mod assets;
mod atomic;
mod folder;
mod ordered;
mod tar;

pub use assets::AssetStore;
pub use atomic::{AtomicFile, write_atomic};
pub use folder::OutputDir;
pub use ordered::for_each_ordered;
pub use tar::{PendingHeader, TarWriter, frame_text_member};
