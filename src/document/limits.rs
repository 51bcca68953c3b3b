//! Bounds on what a load accepts, so that no input (hostile or broken) can exhaust the stack,
//! memory or time: every bound exceeded is an error with a position, never an abort.

use std::io::Read;
use std::path::Path;

/// Bounds on the input a [`crate::Document`] is read from. The defaults are far above
/// anything a real model needs (MuJoCo itself refuses elements nested 500 deep in one file)
/// and far below what would exhaust a worker thread's stack or the machine's memory.
///
/// ```
/// use mjcf_forge::{Document, Limits};
/// let strict = Limits { max_depth: 3, ..Limits::default() };
/// let deep = "<mujoco><worldbody><body><body/></body></worldbody></mujoco>";
/// let err = Document::from_str_with(deep, ".", &strict).unwrap_err();
/// assert_eq!(
///     err.to_string(),
///     "<string>:1:26: element nesting deeper than 3 levels (Limits::max_depth)"
/// );
/// assert!(Document::from_str(deep, ".").is_ok());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Deepest element nesting in the document with its includes expanded (the root
    /// `<mujoco>` is level 1). MuJoCo's XML parser stops at 500 levels per file; every model
    /// of the corpora stays under 30.
    pub max_depth: u32,
    /// Longest chain of files including each other (the main file is level 0).
    pub max_include_depth: u32,
    /// Largest file read: the main file, included files, meshes read for offsets, skins.
    pub max_file_size: u64,
    /// Most attributes on one element (MJCF's widest element has about 60).
    pub max_attributes: u32,
    /// Longest element or attribute name, in bytes.
    pub max_name_len: u32,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            max_depth: 1000,
            max_include_depth: 100,
            max_file_size: 1 << 30,
            max_attributes: 1000,
            max_name_len: 1000,
        }
    }
}

/// Reads a whole file if it is a regular file of at most `max` bytes; otherwise the reason,
/// in words. The type is checked before the file is opened: opening a FIFO would block until
/// a writer comes, and a device like `/dev/zero` never ends.
pub(crate) fn read_regular_file(path: &Path, max: u64) -> Result<Vec<u8>, String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err(format!("not a regular file ({})", file_type_name(&meta)));
    }
    if meta.len() > max {
        return Err(too_big(meta.len(), max));
    }
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    // The file may have grown since `metadata`: read at most one byte past the limit.
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > max {
        return Err(too_big(bytes.len() as u64, max));
    }
    Ok(bytes)
}

fn too_big(len: u64, max: u64) -> String {
    format!("{len} bytes, more than the limit of {max} (Limits::max_file_size)")
}

fn file_type_name(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a file"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_within_the_limit_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("f.xml");
        std::fs::write(&file, b"12345").unwrap();
        assert_eq!(read_regular_file(&file, 5).unwrap(), b"12345");
        assert_eq!(
            read_regular_file(&file, 4).unwrap_err(),
            "5 bytes, more than the limit of 4 (Limits::max_file_size)"
        );
        assert_eq!(
            read_regular_file(dir.path(), 100).unwrap_err(),
            "not a regular file (a directory)"
        );
        #[cfg(unix)]
        assert_eq!(
            read_regular_file(Path::new("/dev/zero"), 100).unwrap_err(),
            "not a regular file (a character device)"
        );
    }
}
