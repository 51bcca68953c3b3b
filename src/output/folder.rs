//! A folder of many output files written from many threads ([`OutputDir`]), at little
//! more than the filesystem's own cost per file, never partial or clobbered.
//!
//! Each file goes through a temporary file and a rename (`atomic.rs`). What costs time
//! per file is kept out of the write path:
//! - [`OutputDir`] syncs once, in [`OutputDir::finish`], rather than once per file: a
//!   crash before that may lose files written since the last sync, but (the rename being
//!   the last step) never leaves a partial file under a final name;
//! - nothing is canonicalized or checked per file; a subfolder (`assets/`) is created
//!   the first time a write into it finds it missing;
//! - a folder made whole ([`OutputDir::create_new`], [`OutputDir::replace`]) is staged
//!   beside its destination and put in place by one rename.

use std::fs::File;
use std::io::Write;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::atomic::{AtomicFile, Sink, TEMP_PREFIX, TempFile, folder_of, write_error};
use crate::error::{Error, ErrorKind};

/// A folder that receives many output files, from many threads at once.
///
/// [`OutputDir::write`] takes `&self` and holds no lock: each file is its own temporary
/// file and rename, so threads only meet in the kernel. Files get the permissions of a
/// newly created file (an existing file of the same name is replaced, not written
/// through). [`OutputDir::finish`] syncs the filesystem once at the end.
///
/// ```
/// use mjcf_forge::OutputDir;
/// use rayon::prelude::*;
/// let tmp = tempfile::tempdir()?;
/// let dir = OutputDir::create(tmp.path().join("variants"))?;
/// (0..8).into_par_iter().try_for_each(|i| dir.write(&format!("{i:09}.xml"), b"<mujoco/>"))?;
/// dir.write("assets/cube.stl", b"solid")?;
/// dir.finish()?;
/// assert!(tmp.path().join("variants/000000007.xml").is_file());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct OutputDir {
    /// Where the files are written: the folder itself, or a staging folder beside it.
    path: PathBuf,
    /// Held open for the one sync at the end (and, on Linux, to create files in).
    handle: File,
    /// A folder written beside its destination and put in place whole by
    /// [`OutputDir::finish`] ([`OutputDir::create_new`], [`OutputDir::replace`]).
    staged: Option<Staged>,
    /// Set once unnamed temporary files turn out not to work here.
    #[cfg(target_os = "linux")]
    no_unnamed_files: std::sync::atomic::AtomicBool,
}

/// Where a staged folder goes at [`OutputDir::finish`], and how.
#[derive(Debug)]
struct Staged {
    /// The folder asked for: what messages name.
    destination: PathBuf,
    /// The folder the staging folder is renamed to (`destination`, links followed).
    target: PathBuf,
    /// Whether a folder that holds files there is replaced (else refused).
    replace: bool,
    /// Put in place: nothing to remove on drop.
    done: bool,
}

impl Drop for OutputDir {
    /// A staged folder that was never put in place (an error, a panic) is removed: the
    /// destination stays as it was.
    fn drop(&mut self) {
        if let Some(staged) = &self.staged
            && !staged.done
        {
            let _ = std::fs::remove_dir_all(&self.path);
        }
    }
}

impl OutputDir {
    /// Creates the folder (and its parents) if missing and opens it.
    ///
    /// ```
    /// let err = mjcf_forge::OutputDir::create("Cargo.toml/out").unwrap_err();
    /// assert!(err.to_string().starts_with("Cargo.toml/out: cannot create folder: "));
    /// ```
    pub fn create(path: impl AsRef<Path>) -> Result<OutputDir, Error> {
        let path = path.as_ref();
        let fail = |e: std::io::Error| {
            Error::bare(ErrorKind::Invalid(format!(
                "{}: cannot create folder: {e}",
                path.display()
            )))
        };
        std::fs::create_dir_all(path).map_err(fail)?;
        let handle = File::open(path).map_err(fail)?;
        Ok(OutputDir {
            path: path.to_path_buf(),
            handle,
            staged: None,
            #[cfg(target_os = "linux")]
            no_unnamed_files: std::sync::atomic::AtomicBool::new(false),
        })
    }

    /// A folder that appears whole, only at [`OutputDir::finish`], where there was none or
    /// an empty one: the files go into a staging folder beside it, renamed into place at
    /// the end, so what the folder holds is one run's output, never mixed with another's
    /// nor partial (an error or a kill before the end leaves the destination as it was;
    /// a staging folder a killed process leaves is named `.mjcf-forge-*`). A folder that
    /// already holds something is refused, here and (should it fill meanwhile) at the end.
    ///
    /// ```
    /// let tmp = tempfile::tempdir()?;
    /// let path = tmp.path().join("variants");
    /// let dir = mjcf_forge::OutputDir::create_new(&path)?;
    /// dir.write("000000000.xml", b"<mujoco/>")?;
    /// assert!(!path.exists(), "not there before finish");
    /// dir.finish()?;
    /// assert!(path.join("000000000.xml").is_file());
    /// let err = mjcf_forge::OutputDir::create_new(&path).unwrap_err();
    /// assert!(err.to_string().ends_with("the output folder is not empty (it holds '000000000.xml')"), "{err}");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn create_new(path: impl AsRef<Path>) -> Result<OutputDir, Error> {
        let path = path.as_ref();
        if let Some(entry) = first_entry(path)? {
            return Err(not_empty(path, &entry));
        }
        Self::staged(path, false)
    }

    /// Like [`OutputDir::create_new`], but a folder that holds files is replaced whole at
    /// [`OutputDir::finish`]: swapped with the staging folder in one step where the
    /// filesystem can (Linux `renameat2(RENAME_EXCHANGE)`; elsewhere two renames, between
    /// which the folder is briefly missing), then the old contents are removed. Until then
    /// the old folder stays as it was. A symbolic link to a folder is followed: its target
    /// is replaced, the link stays.
    ///
    /// ```
    /// let tmp = tempfile::tempdir()?;
    /// let path = tmp.path().join("variants");
    /// std::fs::create_dir(&path)?;
    /// std::fs::write(path.join("000000999.xml"), "a previous run's")?;
    /// let dir = mjcf_forge::OutputDir::replace(&path)?;
    /// dir.write("000000000.xml", b"<mujoco/>")?;
    /// assert!(path.join("000000999.xml").exists(), "the old folder stays until finish");
    /// dir.finish()?;
    /// let names: Vec<_> = std::fs::read_dir(&path)?.map(|e| e.unwrap().file_name()).collect();
    /// assert_eq!(names, ["000000000.xml"]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn replace(path: impl AsRef<Path>) -> Result<OutputDir, Error> {
        Self::staged(path.as_ref(), true)
    }

    /// A staging folder beside `destination` (links followed), for [`Self::create_new`]
    /// and [`Self::replace`].
    fn staged(destination: &Path, replace: bool) -> Result<OutputDir, Error> {
        let fail = |e: std::io::Error| {
            Error::bare(ErrorKind::Invalid(format!(
                "{}: cannot create folder: {e}",
                destination.display()
            )))
        };
        let target = match std::fs::metadata(destination) {
            Ok(m) if m.is_dir() => std::fs::canonicalize(destination).map_err(fail)?,
            Ok(_) => {
                return Err(fail(std::io::Error::new(
                    std::io::ErrorKind::NotADirectory,
                    "not a folder",
                )));
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => destination.to_path_buf(),
            Err(e) => return Err(fail(e)),
        };
        let name = target
            .file_name()
            .ok_or_else(|| fail(std::io::Error::other("not a folder name")))?;
        let parent = folder_of(&target);
        std::fs::create_dir_all(parent).map_err(fail)?;
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let pid = std::process::id();
        let staging = loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let mut staging_name = std::ffi::OsString::from(format!("{TEMP_PREFIX}{pid}-{n}-"));
            staging_name.push(name);
            let staging = parent.join(staging_name);
            match std::fs::create_dir(&staging) {
                Ok(()) => break staging,
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(fail(e)),
            }
        };
        let handle = match File::open(&staging) {
            Ok(handle) => handle,
            Err(e) => {
                let _ = std::fs::remove_dir(&staging);
                return Err(fail(e));
            }
        };
        Ok(OutputDir {
            path: staging,
            handle,
            staged: Some(Staged {
                destination: destination.to_path_buf(),
                target,
                replace,
                done: false,
            }),
            #[cfg(target_os = "linux")]
            no_unnamed_files: std::sync::atomic::AtomicBool::new(false),
        })
    }

    /// The folder the files are written into now: the output folder, or while a staged
    /// folder is written ([`OutputDir::create_new`], [`OutputDir::replace`]) the staging
    /// folder beside it (files written there keep their relative names when it moves).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The output folder as it was named, where the files are once [`OutputDir::finish`]
    /// has run: what messages name.
    pub fn destination(&self) -> &Path {
        self.staged.as_ref().map_or(&self.path, |s| &s.destination)
    }

    /// What messages call `relative_name`: its path in the output folder as named.
    fn shown(&self, relative_name: &str) -> PathBuf {
        self.destination().join(relative_name)
    }

    /// The final path of `relative_name`, after checking it stays inside the folder.
    fn final_path(&self, relative_name: &str) -> Result<PathBuf, Error> {
        let relative = Path::new(relative_name);
        let inside = !relative_name.is_empty()
            && relative
                .components()
                .all(|c| matches!(c, Component::Normal(_)));
        if !inside {
            return Err(Error::bare(ErrorKind::Write {
                path: self.destination().join(relative),
                reason: "not a file name inside the output folder".to_owned(),
            }));
        }
        Ok(self.path.join(relative))
    }

    /// Writes `bytes` as the file `relative_name` (which may name a subfolder:
    /// `assets/cube.stl`, created when missing), replacing it atomically. On any error
    /// nothing is left behind and the error names the final file.
    pub fn write(&self, relative_name: &str, bytes: &[u8]) -> Result<(), Error> {
        let path = self.final_path(relative_name)?;
        let fail = |e: std::io::Error| write_error(&self.shown(relative_name), &e);
        #[cfg(target_os = "linux")]
        if self.write_unnamed(relative_name, bytes).map_err(fail)? {
            return Ok(());
        }
        let folder = folder_of(&path);
        let mut tmp = match TempFile::create_in(folder) {
            Ok(tmp) => tmp,
            // The first file of a subfolder creates it; later ones find it.
            Err(e) if e.kind() == std::io::ErrorKind::NotFound && folder != self.path => {
                std::fs::create_dir_all(folder).map_err(fail)?;
                TempFile::create_in(folder).map_err(fail)?
            }
            Err(e) => return Err(fail(e)),
        };
        tmp.file.write_all(bytes).map_err(fail)?;
        tmp.persist(&path).map_err(fail)?;
        Ok(())
    }

    /// Linux: writes the file without a name (`O_TMPFILE`) and links it under its final
    /// name once complete: one directory entry per file, as a plain write makes, instead
    /// of a temporary one plus a rename; and a process killed mid-write leaves nothing at
    /// all (an unnamed file vanishes with it). `Ok(false)` when this cannot be done here
    /// (the name exists already, which a link cannot replace; a filesystem without
    /// `O_TMPFILE`; no `/proc`): the caller then writes through a named temporary file.
    #[cfg(target_os = "linux")]
    fn write_unnamed(&self, relative_name: &str, bytes: &[u8]) -> std::io::Result<bool> {
        use rustix::fs::{AtFlags, CWD, Mode, OFlags};
        use rustix::io::Errno;
        use std::os::fd::AsRawFd as _;
        if self.no_unnamed_files.load(Ordering::Relaxed) {
            return Ok(false);
        }
        let folder = match Path::new(relative_name).parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let open = || {
            rustix::fs::openat(
                &self.handle,
                folder,
                OFlags::WRONLY | OFlags::TMPFILE | OFlags::CLOEXEC,
                // The umask applies, as for any new file.
                Mode::from_raw_mode(0o666),
            )
        };
        let fd = match open() {
            Ok(fd) => fd,
            Err(Errno::NOENT) if folder != Path::new(".") => {
                std::fs::create_dir_all(self.path.join(folder))?;
                open()?
            }
            Err(Errno::OPNOTSUPP | Errno::ISDIR | Errno::INVAL) => {
                self.no_unnamed_files.store(true, Ordering::Relaxed);
                return Ok(false);
            }
            Err(e) => return Err(e.into()),
        };
        let mut file = File::from(fd);
        file.write_all(bytes)?;
        let fd_path = format!("/proc/self/fd/{}", file.as_raw_fd());
        match rustix::fs::linkat(
            CWD,
            fd_path.as_str(),
            &self.handle,
            relative_name,
            AtFlags::SYMLINK_FOLLOW,
        ) {
            Ok(()) => Ok(true),
            Err(Errno::EXIST) => Ok(false),
            Err(Errno::NOENT) => {
                // No /proc to name the file by.
                self.no_unnamed_files.store(true, Ordering::Relaxed);
                Ok(false)
            }
            Err(e) => Err(e.into()),
        }
    }

    /// Opens `relative_name` for writing as a stream (a manifest written line by line),
    /// put in place whole by [`AtomicFile::commit`]; synced with the rest by
    /// [`OutputDir::finish`].
    ///
    /// ```
    /// use std::io::Write as _;
    /// let tmp = tempfile::tempdir()?;
    /// let dir = mjcf_forge::OutputDir::create(tmp.path())?;
    /// let mut manifest = dir.create_file("manifest.jsonl")?;
    /// writeln!(manifest, "{{\"index\": 0}}")?;
    /// manifest.commit()?;
    /// dir.finish()?;
    /// assert_eq!(std::fs::read_to_string(tmp.path().join("manifest.jsonl"))?, "{\"index\": 0}\n");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn create_file(&self, relative_name: &str) -> Result<AtomicFile, Error> {
        let path = self.final_path(relative_name)?;
        let fail = |e: std::io::Error| write_error(&self.shown(relative_name), &e);
        let folder = folder_of(&path);
        let tmp = match TempFile::create_in(folder) {
            Ok(tmp) => tmp,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound && folder != self.path => {
                std::fs::create_dir_all(folder).map_err(fail)?;
                TempFile::create_in(folder).map_err(fail)?
            }
            Err(e) => return Err(fail(e)),
        };
        Ok(AtomicFile {
            path: self.shown(relative_name),
            sink: Sink::Temp {
                tmp,
                target: path,
                sync: false,
            },
        })
    }

    /// Whether `relative_name` is already there (a file written by an earlier run, or by
    /// another process sharing the folder).
    pub fn contains(&self, relative_name: &str) -> bool {
        self.final_path(relative_name)
            .is_ok_and(|p| std::fs::symlink_metadata(p).is_ok())
    }

    /// Makes everything written durable: one sync of the folder's filesystem, instead of
    /// one per file; then puts a staged folder in place ([`OutputDir::create_new`],
    /// [`OutputDir::replace`]).
    pub fn finish(mut self) -> Result<(), Error> {
        sync_filesystem(&self.handle).map_err(|e| write_error(self.destination(), &e))?;
        let Some(staged) = &self.staged else {
            return Ok(());
        };
        let fail = |e: std::io::Error| write_error(&staged.destination, &e);
        let old = if staged.replace {
            swap_in(&self.path, &staged.target).map_err(fail)?
        } else {
            match std::fs::rename(&self.path, &staged.target) {
                Ok(()) => None,
                // Renaming over a folder succeeds only when it is empty.
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::DirectoryNotEmpty | std::io::ErrorKind::AlreadyExists
                    ) =>
                {
                    let entry = first_entry(&staged.target)?.unwrap_or_default();
                    return Err(not_empty(&staged.destination, &entry));
                }
                Err(e) => return Err(fail(e)),
            }
        };
        // The rename is durable once the parent folder is synced.
        if let Ok(parent) = File::open(folder_of(&staged.target)) {
            parent.sync_all().map_err(fail)?;
        }
        if let Some(staged) = &mut self.staged {
            staged.done = true;
        }
        // The previous run's folder, now under a staging name: best effort, the new
        // output is in place whatever happens to it.
        if let Some(old) = old {
            let _ = std::fs::remove_dir_all(old);
        }
        Ok(())
    }
}

/// The error for an output folder that already holds something (`entry`, one of them).
fn not_empty(path: &Path, entry: &str) -> Error {
    Error::bare(ErrorKind::Invalid(format!(
        "{}: the output folder is not empty (it holds '{entry}')",
        path.display()
    )))
}

/// The first entry of `path` in the folder's own order (any one will do), `None` for an
/// empty folder or none at all (or a path that cannot be a folder: creating it reports
/// that).
fn first_entry(path: &Path) -> Result<Option<String>, Error> {
    let fail = |e: std::io::Error| {
        Error::bare(ErrorKind::Invalid(format!(
            "{}: cannot read folder: {e}",
            path.display()
        )))
    };
    let entries = match std::fs::read_dir(path) {
        Ok(entries) => entries,
        // Nothing there to mix with; making the folder says what is wrong with the path.
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
            ) =>
        {
            return Ok(None);
        }
        Err(e) => return Err(fail(e)),
    };
    match entries.into_iter().next() {
        Some(entry) => Ok(Some(
            entry
                .map_err(fail)?
                .file_name()
                .to_string_lossy()
                .into_owned(),
        )),
        None => Ok(None),
    }
}

/// Puts the folder `staging` where `target` is, replacing whatever folder is there; the
/// replaced folder's new name (to remove) when there was one. One atomic exchange on
/// Linux; elsewhere, or where the filesystem cannot exchange, the old folder is renamed
/// aside first.
fn swap_in(staging: &Path, target: &Path) -> std::io::Result<Option<PathBuf>> {
    #[cfg(target_os = "linux")]
    {
        use rustix::fs::{CWD, RenameFlags, renameat_with};
        use rustix::io::Errno;
        match renameat_with(CWD, staging, CWD, target, RenameFlags::EXCHANGE) {
            // The staging name now holds the old folder.
            Ok(()) => return Ok(Some(staging.to_path_buf())),
            Err(Errno::NOENT) if !target.exists() => {
                std::fs::rename(staging, target)?;
                return Ok(None);
            }
            Err(Errno::INVAL | Errno::NOSYS | Errno::OPNOTSUPP) => {}
            Err(e) => return Err(e.into()),
        }
    }
    let mut aside = staging.as_os_str().to_owned();
    aside.push(".old");
    let aside = PathBuf::from(aside);
    match std::fs::rename(target, &aside) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            std::fs::rename(staging, target)?;
            return Ok(None);
        }
        Err(e) => return Err(e),
    }
    if let Err(e) = std::fs::rename(staging, target) {
        // Put the old folder back: the destination stays as it was.
        let _ = std::fs::rename(&aside, target);
        return Err(e);
    }
    Ok(Some(aside))
}

#[cfg(target_os = "linux")]
fn sync_filesystem(handle: &File) -> std::io::Result<()> {
    rustix::fs::syncfs(handle).map_err(std::io::Error::from)
}

/// Elsewhere: syncing the folder at least makes its renames durable.
#[cfg(not(target_os = "linux"))]
fn sync_filesystem(handle: &File) -> std::io::Result<()> {
    handle.sync_all()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::atomic::tests::listing;
    use crate::output::write_atomic;

    #[cfg(unix)]
    #[test]
    fn outputs_get_a_new_files_permissions_or_keep_the_replaced_ones() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        let fresh = dir.path().join("fresh");
        std::fs::write(&fresh, b"").unwrap();
        let out = dir.path().join("out.xml");
        write_atomic(&out, b"<mujoco/>").unwrap();
        assert_eq!(mode(&out), mode(&fresh));
        std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&out, b"<mujoco/>").unwrap();
        assert_eq!(mode(&out), 0o640);

        let outputs = OutputDir::create(dir.path().join("d")).unwrap();
        outputs.write("a/b.xml", b"x").unwrap();
        assert_eq!(mode(&dir.path().join("d/a/b.xml")), mode(&fresh));
    }

    #[test]
    fn errors_name_the_final_file_and_leave_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let err = write_atomic(dir.path(), b"x").unwrap_err().to_string();
        assert_eq!(
            err,
            format!("cannot write '{}': is a folder", dir.path().display())
        );
        let missing = dir.path().join("no/out.xml");
        let err = write_atomic(&missing, b"x").unwrap_err().to_string();
        assert_eq!(
            err,
            format!(
                "cannot write '{}': No such file or directory (os error 2)",
                missing.display()
            )
        );
        let outputs = OutputDir::create(dir.path().join("d")).unwrap();
        std::fs::create_dir(dir.path().join("d/taken")).unwrap();
        let err = outputs.write("taken", b"x").unwrap_err().to_string();
        assert!(
            err.starts_with(&format!(
                "cannot write '{}': ",
                dir.path().join("d/taken").display()
            )),
            "{err}"
        );
        for bad in ["", "../x", "/etc/x", "a/../../x", "./"] {
            let err = outputs.write(bad, b"x").unwrap_err().to_string();
            assert!(
                err.ends_with("not a file name inside the output folder"),
                "{bad}: {err}"
            );
        }
        assert_eq!(listing(&dir.path().join("d")), ["taken"]);
        assert!(listing(&dir.path().join("d/taken")).is_empty());
    }

    /// A second run into the same folder replaces the first one's files (a link cannot
    /// replace a name, so this takes the rename path) and leaves nothing else.

    #[test]
    fn a_rerun_replaces_files_atomically() {
        let dir = tempfile::tempdir().unwrap();
        for round in ["one", "two"] {
            let outputs = OutputDir::create(dir.path()).unwrap();
            outputs.write("a.xml", round.as_bytes()).unwrap();
            outputs.write("assets/b.bin", round.as_bytes()).unwrap();
            outputs.finish().unwrap();
            assert_eq!(
                std::fs::read(dir.path().join("a.xml")).unwrap(),
                round.as_bytes()
            );
            assert_eq!(
                std::fs::read(dir.path().join("assets/b.bin")).unwrap(),
                round.as_bytes()
            );
        }
        assert_eq!(listing(dir.path()), ["a.xml", "assets"]);
        assert_eq!(listing(&dir.path().join("assets")), ["b.bin"]);
    }

    /// A stream dropped before its commit (an error half way through a tar archive)
    /// leaves the old file as it was and no temporary file.

    #[test]
    fn an_uncommitted_stream_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("shard.tar");
        std::fs::write(&path, b"old").unwrap();
        let mut file = AtomicFile::create(&path).unwrap();
        file.write_all(b"half").unwrap();
        drop(file);
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        let outputs = OutputDir::create(dir.path()).unwrap();
        let mut manifest = outputs.create_file("sub/manifest.jsonl").unwrap();
        manifest.write_all(b"{}").unwrap();
        drop(manifest);
        assert_eq!(listing(dir.path()), ["shard.tar", "sub"]);
        assert!(listing(&dir.path().join("sub")).is_empty());
        let mut manifest = outputs.create_file("sub/manifest.jsonl").unwrap();
        manifest.write_all(b"{}\n").unwrap();
        assert_eq!(manifest.path(), dir.path().join("sub/manifest.jsonl"));
        manifest.commit().unwrap();
        assert_eq!(listing(&dir.path().join("sub")), ["manifest.jsonl"]);
    }

    #[test]
    fn many_threads_write_one_folder() {
        use rayon::prelude::*;
        let dir = tempfile::tempdir().unwrap();
        let outputs = OutputDir::create(dir.path()).unwrap();
        (0..200u32)
            .into_par_iter()
            .try_for_each(|i| {
                let name = if i % 2 == 0 {
                    format!("{i:09}.xml")
                } else {
                    format!("assets/{i:09}.bin")
                };
                outputs.write(&name, format!("{i}").as_bytes())
            })
            .unwrap();
        assert!(outputs.contains("assets/000000199.bin"));
        outputs.finish().unwrap();
        assert_eq!(listing(dir.path()).len(), 101);
        assert_eq!(listing(&dir.path().join("assets")).len(), 100);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("000000198.xml")).unwrap(),
            "198"
        );
    }
}
