//! Single output files that are never partial or clobbered ([`write_atomic`],
//! [`AtomicFile`]), and the temporary file both they and [`super::OutputDir`] write
//! through.
//!
//! Every output is written to a temporary file in the folder it ends up in and renamed over
//! its final name, so a reader (or a crash) sees the old file or the new one, never a part
//! of it. The temporary file is created with mode `0666` and the kernel applies the umask,
//! so it gets exactly the permissions of a newly created file without reading the umask
//! (which the standard library cannot do) or probing with a file per output.
//!
//! A single output ([`write_atomic`]) follows what users expect of `-o PATH`: a symlink is
//! written through (the link stays a link), a FIFO or device (`-o /dev/null`,
//! `-o /dev/stdout`) is written to directly and never replaced by a regular file, and a
//! regular file is replaced atomically keeping its permissions.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, ErrorKind};

/// Prefix of temporary files, so that one left by a killed process is recognisable.
pub(super) const TEMP_PREFIX: &str = ".mjcf-forge-";

/// How many symbolic links [`write_atomic`] follows before giving up (Linux's limit).
const MAX_LINKS: usize = 40;

pub(super) fn write_error(path: &Path, e: &std::io::Error) -> Error {
    Error::bare(ErrorKind::Write {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })
}

/// A temporary file next to an output, removed on drop unless renamed into place: any
/// error (or a panic) between its creation and [`TempFile::persist`] leaves nothing.
///
/// Written here rather than with `tempfile`, whose errors name the temporary file (users
/// never asked for it; ours name the output) and whose names cost a random draw each: a
/// name from the process id and a counter is unique among live processes, and one left
/// by a dead process is stepped over.
#[derive(Debug)]
pub(super) struct TempFile {
    path: PathBuf,
    pub(super) file: File,
    persisted: bool,
}

impl TempFile {
    /// A new temporary file in `folder`, with the permissions a new file there gets.
    pub(super) fn create_in(folder: &Path) -> std::io::Result<TempFile> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let pid = std::process::id();
        loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let path = folder.join(format!("{TEMP_PREFIX}{pid}-{n}"));
            let mut options = std::fs::OpenOptions::new();
            options.write(true).create_new(true);
            #[cfg(unix)]
            {
                use std::os::unix::fs::OpenOptionsExt;
                // The umask applies to the mode given at creation, as for any new file.
                options.mode(0o666);
            }
            match options.open(&path) {
                Ok(file) => {
                    return Ok(TempFile {
                        path,
                        file,
                        persisted: false,
                    });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// Renames the file over `target`.
    pub(super) fn persist(mut self, target: &Path) -> std::io::Result<()> {
        std::fs::rename(&self.path, target)?;
        self.persisted = true;
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.persisted {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// The folder of `path` for a temporary file next to it.
pub(super) fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Writes `bytes` to the output `path` as users expect of `-o PATH`, never leaving a
/// partial or clobbered file:
/// - a regular file (or a new one) is replaced atomically: a temporary file in the same
///   folder, synced, then renamed over it; a replaced file's permissions are kept;
/// - a symbolic link is followed to its target, which is replaced (the link stays);
/// - a FIFO, a device (`/dev/null`) or another special file is written to directly,
///   never replaced; `/dev/stdout` and `/dev/stderr` (and their `/dev/fd`,
///   `/proc/self/fd` names) are the process's own streams, whatever they are.
///
/// Errors name `path`, never the temporary file.
///
/// ```
/// let dir = tempfile::tempdir()?;
/// let out = dir.path().join("model.xml");
/// mjcf_forge::write_atomic(&out, b"<mujoco/>")?;
/// assert_eq!(std::fs::read(&out)?, b"<mujoco/>");
/// mjcf_forge::write_atomic(std::path::Path::new("/dev/null"), b"<mujoco/>")?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes).map_err(|e| write_error(path, &e))?;
    file.commit()
}

/// An output written as a stream (a tar archive, a manifest) under the rules of
/// [`write_atomic`]: a regular file appears under its name, whole, only at
/// [`AtomicFile::commit`]; dropped without it (any error, a panic), nothing is left and
/// an old file stays as it was. Symlinks are written through; FIFOs, devices and
/// standard streams are written to as the bytes come.
///
/// ```
/// use std::io::Write as _;
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("shard.tar");
/// let mut file = mjcf_forge::output::AtomicFile::create(&path)?;
/// file.write_all(b"first part, ")?;
/// assert!(!path.exists(), "not there before commit");
/// file.write_all(b"second part")?;
/// file.commit()?;
/// assert_eq!(std::fs::read(&path)?, b"first part, second part");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct AtomicFile {
    /// The name asked for: what messages say.
    pub(super) path: PathBuf,
    pub(super) sink: Sink,
}

#[derive(Debug)]
pub(super) enum Sink {
    /// A FIFO, a device, or the process's own standard output or error.
    Direct(File),
    Temp {
        tmp: TempFile,
        /// The file the rename replaces (the path with symlinks followed).
        target: PathBuf,
        /// Sync before the rename: a single output, not one of an [`OutputDir`] (which
        /// syncs once for all in [`OutputDir::finish`]).
        sync: bool,
    },
}

impl AtomicFile {
    /// Opens the output `path` (see [`write_atomic`] for what each kind of path means).
    pub fn create(path: impl AsRef<Path>) -> Result<AtomicFile, Error> {
        let path = path.as_ref();
        let fail = |e: std::io::Error| write_error(path, &e);
        let target = match follow_links(path).map_err(fail)? {
            Target::Stream(stream) => {
                return Ok(AtomicFile {
                    path: path.to_path_buf(),
                    sink: Sink::Direct(stream.unbuffered().map_err(fail)?),
                });
            }
            Target::Path(target) => target,
        };
        let old_permissions = match std::fs::metadata(&target) {
            Ok(m) if m.is_dir() => {
                return Err(fail(std::io::Error::new(
                    std::io::ErrorKind::IsADirectory,
                    "is a folder",
                )));
            }
            Ok(m) if !m.is_file() => {
                // A FIFO or a device: its reader or driver takes the bytes as they come.
                let file = std::fs::OpenOptions::new()
                    .write(true)
                    .open(&target)
                    .map_err(fail)?;
                return Ok(AtomicFile {
                    path: path.to_path_buf(),
                    sink: Sink::Direct(file),
                });
            }
            Ok(m) => Some(m.permissions()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(fail(e)),
        };
        let tmp = TempFile::create_in(folder_of(&target)).map_err(fail)?;
        if let Some(permissions) = old_permissions {
            tmp.file.set_permissions(permissions).map_err(fail)?;
        }
        Ok(AtomicFile {
            path: path.to_path_buf(),
            sink: Sink::Temp {
                tmp,
                target,
                sync: true,
            },
        })
    }

    /// The output's name, as asked for.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes the output and, for a regular file, puts it in place.
    pub fn commit(self) -> Result<(), Error> {
        let fail = |e: std::io::Error| write_error(&self.path, &e);
        match self.sink {
            Sink::Direct(mut file) => file.flush().map_err(fail),
            Sink::Temp { tmp, target, sync } => {
                if sync {
                    // The rename must not reach the disk before the data does.
                    tmp.file.sync_all().map_err(fail)?;
                }
                tmp.persist(&target).map_err(fail)
            }
        }
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut self.sink {
            Sink::Direct(file) => file.write(buf),
            Sink::Temp { tmp, .. } => tmp.file.write(buf),
        }
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::Direct(file) => file.write_all(buf),
            Sink::Temp { tmp, .. } => tmp.file.write_all(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::Direct(file) => file.flush(),
            Sink::Temp { tmp, .. } => tmp.file.flush(),
        }
    }
}

/// The process's standard output or error.
#[derive(Clone, Copy, Debug)]
enum StdStream {
    Out,
    Err,
}

impl StdStream {
    /// The stream's own file description, without the standard library's buffer (a line
    /// buffer for standard output, which scans every block written for its last newline):
    /// whatever that buffer holds is flushed first, and the output goes on where it ends.
    fn unbuffered(self) -> std::io::Result<File> {
        use std::os::fd::AsFd as _;
        let fd = match self {
            StdStream::Out => {
                let out = std::io::stdout();
                out.lock().flush()?;
                out.as_fd().try_clone_to_owned()?
            }
            StdStream::Err => std::io::stderr().as_fd().try_clone_to_owned()?,
        };
        Ok(File::from(fd))
    }
}

/// What writing to a path changes.
enum Target {
    /// The process's own standard output or error.
    Stream(StdStream),
    /// This file (possibly missing, for a dangling link or a new output).
    Path(PathBuf),
}

/// The process's own standard output or error when `path` names it. Opening
/// `/dev/stdout` anew would start at offset 0 of a redirected file (overwriting what the
/// shell wrote before it) or, followed to that file, replace it; writing to the inherited
/// stream is what `-o /dev/stdout` means.
fn standard_stream(path: &Path) -> Option<StdStream> {
    match path.to_str()? {
        "/dev/stdout" | "/dev/fd/1" | "/proc/self/fd/1" => Some(StdStream::Out),
        "/dev/stderr" | "/dev/fd/2" | "/proc/self/fd/2" => Some(StdStream::Err),
        _ => None,
    }
}

/// `path` with symbolic links followed as far as they lead on disk. A link the kernel
/// makes for an open pipe or socket (`/proc/self/fd/N` reads `pipe:[1234]`) is not a path:
/// the link itself is returned, and opening it reaches the right object.
fn follow_links(path: &Path) -> std::io::Result<Target> {
    let mut current = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        if let Some(stream) = standard_stream(&current) {
            return Ok(Target::Stream(stream));
        }
        match std::fs::symlink_metadata(&current) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&current)?;
                if !is_plain_path(&link) {
                    return Ok(Target::Path(current));
                }
                // An absolute link replaces the folder; a relative one is read from it.
                current = folder_of(&current).join(&link);
            }
            _ => return Ok(Target::Path(current)),
        }
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        "too many levels of symbolic links",
    ))
}

/// Whether a link's text looks like a file path (kernel-made links read `pipe:[N]`,
/// `socket:[N]`, `anon_inode:[...]`).
fn is_plain_path(link: &Path) -> bool {
    let text = link.as_os_str().as_encoded_bytes();
    !(text.ends_with(b"]") && text.contains(&b':') && !text.contains(&b'/'))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    pub(in crate::output) fn listing(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_is_written_through_and_stays_a_link() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("target.xml");
        std::fs::write(&target, b"old").unwrap();
        let link = dir.path().join("link.xml");
        std::os::unix::fs::symlink("target.xml", &link).unwrap();
        // A link to a link, and a dangling link whose target gets created.
        let link2 = dir.path().join("link2.xml");
        std::os::unix::fs::symlink(&link, &link2).unwrap();
        write_atomic(&link2, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        assert!(std::fs::symlink_metadata(&link2).unwrap().is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        let dangling = dir.path().join("dangling.xml");
        std::os::unix::fs::symlink("made.xml", &dangling).unwrap();
        write_atomic(&dangling, b"made").unwrap();
        assert_eq!(std::fs::read(dir.path().join("made.xml")).unwrap(), b"made");
        assert!(std::fs::symlink_metadata(&dangling).unwrap().is_symlink());
        assert_eq!(
            listing(dir.path()),
            [
                "dangling.xml",
                "link.xml",
                "link2.xml",
                "made.xml",
                "target.xml"
            ]
        );
        // A loop is an error naming the path asked for.
        let a = dir.path().join("loop_a");
        std::os::unix::fs::symlink("loop_b", &a).unwrap();
        std::os::unix::fs::symlink("loop_a", dir.path().join("loop_b")).unwrap();
        let err = write_atomic(&a, b"x").unwrap_err().to_string();
        assert_eq!(
            err,
            format!(
                "cannot write '{}': too many levels of symbolic links",
                a.display()
            )
        );
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_device_is_written_to_not_replaced() {
        write_atomic(Path::new("/dev/null"), b"<mujoco/>").unwrap();
        let m = std::fs::metadata("/dev/null").unwrap();
        assert!(!m.is_file(), "/dev/null became a regular file");
        // A symlink to the device, as /dev/stdout is to a terminal.
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("null");
        std::os::unix::fs::symlink("/dev/null", &link).unwrap();
        write_atomic(&link, b"x").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        assert_eq!(listing(dir.path()), ["null"]);
    }
}
