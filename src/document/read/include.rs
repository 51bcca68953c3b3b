//! `<include>` expansion: the named file found where MuJoCo finds it, refused when it closes
//! a cycle or comes a second time, and read in the include's place by the reader that met it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::builder::Builder;
use crate::document::limits::read_regular_file;
use crate::document::paths::join_by_name;
use crate::document::tree::Node;
use crate::document::{SourceFile, Span};
use crate::error::{Error, ErrorKind, Errors};

/// How many files deep includes are read on one stack (see [`Builder::expand_include`]):
/// each level takes about 2.5 KiB of stack in a release build and 11 KiB unoptimised.
const INCLUDES_PER_STACK: u32 = 32;

/// The stack of a thread that reads the next [`INCLUDES_PER_STACK`] levels of includes.
const INCLUDE_STACK: usize = 4 << 20;

impl Builder {
    /// Where the file an `<include>` in source file `includer` names is: the path to read
    /// and the path to show. MuJoCo (3.17.0 and 4.0.0 alike, with the main file named by an
    /// absolute path) looks beside the main file first and, when nothing is there, beside
    /// the file that holds the `<include>` (the folder it was read from, which may itself
    /// have been found either way). "Nothing is there" is a failed `stat`: a folder or an
    /// unreadable file beside the main file is taken, and then refused. Paths are joined
    /// and `..` is resolved by name, before the file system sees them, as MuJoCo does.
    fn find_included(&self, file: &str, includer: u32) -> Result<(PathBuf, PathBuf), ErrorKind> {
        let beside_main = join_by_name(&self.doc.model_dir, file);
        let shown_beside_main = self.display_dir.join(file);
        let from = &self.files[includer as usize];
        let beside_includer = join_by_name(&from.dir, file);
        // The main file's own includes (and absolute names) have one place to look.
        if beside_includer == beside_main || std::fs::metadata(&beside_main).is_ok() {
            return Ok((beside_main, shown_beside_main));
        }
        let shown_beside_includer = match from.included_at {
            Some(_) => from.path.parent().unwrap_or(Path::new("")).join(file),
            None => self.display_dir.join(file),
        };
        match std::fs::metadata(&beside_includer) {
            Ok(_) => Ok((beside_includer, shown_beside_includer)),
            Err(err) => Err(ErrorKind::IncludeNotFound {
                beside_main: shown_beside_main,
                beside_includer: shown_beside_includer,
                reason: err.to_string(),
            }),
        }
    }

    /// Reads the file an `<include>` (read into the detached `node`) names, in its place
    /// under `host`. With `fast`, the file is read by [`Builder::parse_fast`], and `Ok(false)`
    /// means it was not in that reader's reach (the load then starts over with quick-xml).
    /// `host_depth` is the depth of `host` (see [`Limits::max_depth`]).
    ///
    /// Reading an included file recurses (on include depth only), so that depth is checked
    /// before anything else: a chain of includes cannot exhaust the stack.
    ///
    /// [`Limits::max_depth`]: crate::document::limits::Limits::max_depth
    pub(super) fn expand_include(
        &mut self,
        node: Node,
        span: Span,
        host: Node,
        host_depth: u32,
        fast: bool,
    ) -> Result<bool, Errors> {
        // Built only for a message: it walks the include chain.
        let here = |b: &Builder| b.loc(span.file, span.line, span.col);
        if self.include_depth >= self.limits.max_include_depth {
            let msg = format!(
                "includes nested deeper than {} files (Limits::max_include_depth)",
                self.limits.max_include_depth
            );
            return Err(Error::at(here(self), ErrorKind::Invalid(msg)).into());
        }
        let Some(file) = self.doc.attr(node, "file").map(str::to_owned) else {
            return Err(Error::at(here(self), ErrorKind::IncludeWithoutFile).into());
        };
        let (full, path) = self
            .find_included(&file, span.file)
            .map_err(|kind| Error::at(here(self), kind))?;
        let canonical = std::fs::canonicalize(&full).map_err(|err| {
            Error::at(
                here(self),
                ErrorKind::Io {
                    path: path.clone(),
                    reason: err.to_string(),
                },
            )
        })?;
        if let Some(abs) = self.main_to_canonicalize.take() {
            // The main file heads the chain (only the main file is read when the first
            // include is met).
            let main = std::fs::canonicalize(&*self.files[0].path).unwrap_or(abs);
            self.chain.insert(0, main.clone());
            self.seen_set.insert(main);
        }
        // A file in the chain has been seen: the chain is searched only then (it is as long
        // as the includes are deep, and a lookup per include would make chains quadratic).
        if self.seen_set.contains(&canonical) {
            if let Some(i) = self.chain.iter().position(|p| *p == canonical) {
                let mut chain = self.chain_display[i..].to_vec();
                chain.push(path);
                return Err(Error::at(here(self), ErrorKind::IncludeCycle { chain }).into());
            }
            return Err(Error::at(here(self), ErrorKind::IncludedTwice(path)).into());
        }
        let bytes = read_regular_file(&full, self.limits.max_file_size).map_err(|reason| {
            Error::at(
                here(self),
                ErrorKind::Io {
                    path: path.clone(),
                    reason,
                },
            )
        })?;
        let index = self.files.len() as u32;
        self.files.push(SourceFile {
            path: Arc::from(path.as_path()),
            dir: Arc::from(full.parent().unwrap_or(Path::new("/"))),
            included_at: Some(span),
        });
        self.chain.push(canonical.clone());
        self.chain_display.push(path.clone());
        self.seen_set.insert(canonical);
        let saved_base = std::mem::replace(&mut self.depth_base, host_depth);
        self.include_depth += 1;
        let read = |b: &mut Builder| -> Result<Option<usize>, Errors> {
            Ok(if fast {
                std::str::from_utf8(&bytes)
                    .ok()
                    .and_then(|src| b.parse_fast(src, index, Some(host)))
            } else {
                Some(b.parse(&bytes, index, Some(host))?)
            })
        };
        // Reading an included file recurses. Every `INCLUDES_PER_STACK` files deep, the
        // rest of the chain is read on a thread of its own with a stack of known size, so
        // that no `max_include_depth` can make the caller's stack (a rayon worker's, say)
        // the real bound.
        let inserted = if self.include_depth.is_multiple_of(INCLUDES_PER_STACK) {
            let at = here(self);
            std::thread::scope(|scope| {
                match std::thread::Builder::new()
                    .stack_size(INCLUDE_STACK)
                    .spawn_scoped(scope, || read(self))
                {
                    Ok(reader) => reader
                        .join()
                        .unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
                    Err(e) => {
                        let why = format!("cannot start a thread to read deeper includes: {e}");
                        Err(Error::at(at, ErrorKind::Invalid(why)).into())
                    }
                }
            })?
        } else {
            read(self)?
        };
        // (After an error the builder is dropped: nothing to restore on that path.)
        self.include_depth -= 1;
        self.depth_base = saved_base;
        let Some(inserted) = inserted else {
            return Ok(false);
        };
        self.chain.pop();
        self.chain_display.pop();
        if inserted == 0 {
            return Err(Error::at(here(self), ErrorKind::EmptyInclude(path)).into());
        }
        Ok(true)
    }
}
