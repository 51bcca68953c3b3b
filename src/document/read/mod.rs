//! Reading: the markup goes straight into the arena; `<include>` is expanded on the way.
//!
//! Two readers build the same document. [`Builder::parse_fast`] reads the markup that
//! well-formed MJCF uses (elements, attributes, comments, processing instructions,
//! character data without references) in one pass over the bytes, finding exactly what
//! quick-xml finds there. Anything else, and every error, sends the whole load through
//! [`Builder::parse`] on quick-xml's events, which handles all of XML and words the errors
//! with their positions. The tests of `load`, its `readers` fuzz target and the document
//! judge hold the two to the same output; the fast one is what makes loading several times
//! quicker.
//!
//! Entry points: [`read_file`] and [`read_str`] read a model as every load does (the fast
//! reader first, quick-xml's on any refusal); [`read_bytes_as_text`] can take quick-xml's
//! alone, so that the two can be compared.
//!
//! The files, by what they do:
//! - [`fast`]: the fast reader, one pass over the bytes;
//! - [`events`]: the full reader, on quick-xml's events;
//! - [`mod@include`]: `<include>` expanded (the file found, cycles refused) for either reader;
//! - [`builder`]: what both readers write through: the document's tables, names checked
//!   when first met, character data joined;
//! - [`tags`]: start tags and their attributes scanned from the bytes (by the fast reader,
//!   and by the full one within each tag quick-xml found);
//! - [`checks`]: what XML 1.0 allows (characters, names, references), and [`clip`] for
//!   quoting input in messages;
//! - [`bytes`]: the byte searches under the scanners, a word at a time;
//! - [`lines`]: byte offsets into line:col.

mod builder;
mod bytes;
mod checks;
mod events;
mod fast;
mod include;
mod lines;
mod tags;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::document::Document;
use crate::document::limits::{Limits, read_regular_file};
use crate::error::{Error, ErrorKind, Errors, Location};
use builder::Builder;

pub(crate) use checks::clip;

pub(crate) fn read_file(path: &Path, limits: &Limits) -> Result<Document, Errors> {
    let bytes = read_regular_file(path, limits.max_file_size).map_err(|reason| {
        Error::bare(ErrorKind::Io {
            path: path.to_path_buf(),
            reason,
        })
    })?;
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let dir = abs.parent().unwrap_or(Path::new(""));
    let display_dir = path.parent().unwrap_or(Path::new(""));
    read_bytes(
        &bytes,
        Arc::from(path),
        dir,
        display_dir,
        Main::File { abs: abs.clone() },
        limits,
    )
}

pub(crate) fn read_str(xml: &str, base_dir: &Path, limits: &Limits) -> Result<Document, Errors> {
    let name: Arc<Path> = Arc::from(Path::new("<string>"));
    if xml.len() as u64 > limits.max_file_size {
        return Err(Error::at(
            Location::new(name, 1, 1),
            ErrorKind::Invalid(format!(
                "text of {} bytes, more than the limit of {} (Limits::max_file_size)",
                xml.len(),
                limits.max_file_size
            )),
        )
        .into());
    }
    let dir = std::path::absolute(base_dir).unwrap_or_else(|_| base_dir.to_path_buf());
    read_bytes(xml.as_bytes(), name, &dir, base_dir, Main::Text, limits)
}

/// Reads `bytes` as the text `<string>` found in `dir`, through the fast reader first (as
/// every load does) with `fast`, through quick-xml's path alone without: the two must give
/// the same document or the same errors (the tests and the `readers` fuzz target).
pub(crate) fn read_bytes_as_text(
    bytes: &[u8],
    dir: &Path,
    limits: &Limits,
    fast: bool,
) -> Result<Document, Errors> {
    let name = Arc::from(Path::new("<string>"));
    read_bytes_with(bytes, name, dir, dir, Main::Text, limits, fast)
}

/// Where the main text came from: a file (which takes part in include cycles) or a string.
enum Main {
    File { abs: PathBuf },
    Text,
}

fn read_bytes(
    bytes: &[u8],
    name: Arc<Path>,
    dir: &Path,
    display_dir: &Path,
    main: Main,
    limits: &Limits,
) -> Result<Document, Errors> {
    read_bytes_with(bytes, name, dir, display_dir, main, limits, true)
}

fn read_bytes_with(
    bytes: &[u8],
    name: Arc<Path>,
    dir: &Path,
    display_dir: &Path,
    main: Main,
    limits: &Limits,
    try_fast: bool,
) -> Result<Document, Errors> {
    // NUL bytes that end a file (padding some exporters leave) are where MuJoCo's XML
    // parser stops reading, as a C string ends: they are not read either. A NUL before the
    // markup's end stays an error.
    let end = bytes.iter().rposition(|&b| b != 0).map_or(0, |i| i + 1);
    let bytes = &bytes[..end];
    let model_dir: Arc<Path> = Arc::from(dir);
    // Models are read by `Builder::parse_fast` when it can; anything outside what it handles
    // (and every error) sends the whole load, includes and all, through quick-xml.
    if let Some(src) = std::str::from_utf8(bytes).ok().filter(|_| try_fast) {
        let mut b = Builder::new(bytes.len(), &name, &model_dir, display_dir, &main, limits);
        if b.parse_fast(src, 0, None).is_some() {
            return b.finish();
        }
    }
    let mut b = Builder::new(bytes.len(), &name, &model_dir, display_dir, &main, limits);
    b.parse(bytes, 0, None)?;
    b.finish()
}
