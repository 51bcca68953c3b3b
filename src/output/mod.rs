//! Where outputs go: files that are never partial or clobbered ([`write_atomic`],
//! [`OutputDir`]).

mod files;

pub use files::{OutputDir, write_atomic};
