//! Entry points for the fuzz targets in `fuzz/` and the differential tests: internals they
//! compare and the random documents they draw, not a supported API.

use std::path::Path;

pub use super::random_mjcf::{RandomScene, random_mjcf, random_mjcf_files, random_scene};

/// The outcome of loading `bytes` through the fast reader (falling back as every load does)
/// and through quick-xml's path alone, each as text (see `load::describe_load`): equal for
/// every input, or one of the readers is wrong.
pub fn read_both_ways(bytes: &[u8], base_dir: &str) -> (String, String) {
    let dir = Path::new(base_dir);
    (
        crate::document::load::describe_load(bytes, dir, true),
        crate::document::load::describe_load(bytes, dir, false),
    )
}
