//! Relocatable asset files: every file a model refers to, copied once into `assets/`
//! under a name derived from its content, and referred to relatively, so that the output
//! folder can be moved or copied to another machine and still compile.
//!
//! Names are `assets/<hash>.<extension>`: the first 128 bits of the file's BLAKE3 hash in
//! hex, and the source's extension (MuJoCo picks a mesh or texture decoder by it). BLAKE3
//! is specified bit for bit and cryptographic, so the same file gets the same name on
//! every machine, in every run and every shard, and two different files never share one
//! (a fast non-cryptographic hash would let a crafted file stand in for another).
//!
//! The store knows files, not documents: rewriting a document's file references into these
//! names is [`Document::relocate_assets`](crate::Document::relocate_assets), in the
//! document tier.

use std::collections::{BTreeMap, HashMap};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use rayon::prelude::*;

use super::{OutputDir, TarWriter};
use crate::error::{Error, ErrorKind};

/// The folder of the output that asset files go to.
const ASSETS: &str = "assets";

/// How many hex digits of the hash name a file (128 bits).
const HASH_DIGITS: usize = 32;

/// Gathers the asset files of many documents, each once, under content-derived names.
///
/// One store is shared by every thread of a batch (`&self` everywhere): its lock is held
/// only to look up and record names, never while a file is read or hashed.
///
/// ```
/// use mjcf_forge::{AssetStore, Document, OutputDir};
/// let tmp = tempfile::tempdir()?;
/// std::fs::write(tmp.path().join("grid.png"), b"not really a png")?;
/// let mut doc = Document::from_str(
///     r#"<mujoco><compiler texturedir="."/><asset><texture file="grid.png" type="2d"/></asset></mujoco>"#,
///     tmp.path(),
/// )?;
/// let store = AssetStore::new();
/// doc.relocate_assets(&store)?;
/// let xml = doc.to_xml_string();
/// // Named after its file as MuJoCo would, now explicitly; the folder setting is gone.
/// assert!(xml.contains(r#"<texture file="assets/"#) && xml.contains(r#"name="grid""#));
/// assert!(!xml.contains("texturedir"));
/// let out = OutputDir::create(tmp.path().join("out"))?;
/// store.write_to_dir(&out)?;
/// out.finish()?;
/// assert_eq!(std::fs::read_dir(tmp.path().join("out/assets"))?.count(), 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Default)]
pub struct AssetStore {
    inner: Mutex<Inner>,
}

#[derive(Debug, Default)]
struct Inner {
    /// Source file -> its name in the output (`assets/<hash>.<ext>`).
    by_source: HashMap<PathBuf, String>,
    /// Name in the output -> where to copy it from and the hash it must still have. A
    /// sorted map: the order files are written in (and a tar stream's bytes) must not
    /// depend on which thread saw a file first.
    by_name: BTreeMap<String, Source>,
}

#[derive(Clone, Debug)]
struct Source {
    path: PathBuf,
    hash: blake3::Hash,
}

impl AssetStore {
    /// An empty store.
    pub fn new() -> AssetStore {
        AssetStore::default()
    }

    /// How many distinct files the store holds.
    pub fn len(&self) -> usize {
        self.lock().by_name.len()
    }

    /// Whether the store holds no file.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every file of the store: its name in the output (`assets/...`) and its source, in
    /// name order.
    pub fn files(&self) -> Vec<(String, PathBuf)> {
        self.lock()
            .by_name
            .iter()
            .map(|(name, s)| (name.clone(), s.path.clone()))
            .collect()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Inner> {
        // A panic elsewhere cannot leave the maps half-updated (each update is one insert),
        // so a poisoned lock still holds good data.
        self.inner.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Records one file (for a randomizer that picks texture or mesh files) and returns
    /// the name to write in the document: `assets/<hash>.<ext>`. The file is read and
    /// hashed once per store, however often it is asked for.
    ///
    /// ```
    /// let tmp = tempfile::tempdir()?;
    /// let file = tmp.path().join("cube.obj");
    /// std::fs::write(&file, b"v 0 0 0")?;
    /// let store = mjcf_forge::AssetStore::new();
    /// let name = store.relocate_file(&file)?;
    /// assert_eq!(name, "assets/f992f1321acdd7fef55c54a953930d6b.obj");
    /// assert_eq!(store.relocate_file(&file)?, name);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn relocate_file(&self, absolute: &Path) -> Result<String, Error> {
        if let Some(name) = self.lock().by_source.get(absolute) {
            return Ok(name.clone());
        }
        let hash = hash_file(absolute)?;
        let mut name = format!("{ASSETS}/{}", &hash.to_hex()[..HASH_DIGITS]);
        if let Some(ext) = absolute.extension() {
            name.push('.');
            name.push_str(&ext.to_string_lossy());
        }
        let mut inner = self.lock();
        inner.by_source.insert(absolute.to_path_buf(), name.clone());
        inner.by_name.entry(name.clone()).or_insert(Source {
            path: absolute.to_path_buf(),
            hash,
        });
        Ok(name)
    }

    /// Copies every file into `dir` (`dir/assets/...`), each once, in parallel. A file
    /// already present under its content name is skipped (another shard, or an earlier
    /// run, wrote those very bytes); the others are written atomically, so shards sharing
    /// a folder never see a partial file nor clobber each other's.
    pub fn write_to_dir(&self, dir: &OutputDir) -> Result<(), Error> {
        let files: Vec<(String, Source)> = self
            .lock()
            .by_name
            .iter()
            .map(|(n, s)| (n.clone(), s.clone()))
            .collect();
        let results: Vec<Result<(), Error>> = files
            .par_iter()
            .map(|(name, source)| {
                if dir.contains(name) {
                    return Ok(());
                }
                let mut file = dir.create_file(name)?;
                let path = file.path().to_path_buf();
                source.copy_to(&mut file, &path)?;
                file.commit()
            })
            .collect();
        // The first failure in name order, whatever thread met it first.
        results.into_iter().collect()
    }

    /// Appends every file to a tar stream as `assets/<hash>.<ext>`, in name order (so the
    /// same store gives the same bytes).
    ///
    /// ```
    /// let tmp = tempfile::tempdir()?;
    /// let file = tmp.path().join("cube.obj");
    /// std::fs::write(&file, b"v 0 0 0")?;
    /// let store = mjcf_forge::AssetStore::new();
    /// store.relocate_file(&file)?;
    /// let mut tar = mjcf_forge::TarWriter::new(Vec::new(), "shard.tar");
    /// store.write_to_tar(&mut tar)?;
    /// let bytes = tar.finish()?;
    /// assert!(bytes.starts_with(b"assets/f992f1321acdd7fef55c54a953930d6b.obj\0"));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn write_to_tar<W: Write>(&self, tar: &mut TarWriter<W>) -> Result<(), Error> {
        let files: Vec<(String, Source)> = self
            .lock()
            .by_name
            .iter()
            .map(|(n, s)| (n.clone(), s.clone()))
            .collect();
        for (name, source) in files {
            let size = std::fs::metadata(&source.path)
                .map_err(|e| read_error(&source.path, e.to_string()))?
                .len();
            let tar_name = tar.name().to_path_buf();
            tar.append_with(&name, size, |out| source.copy_to(out, &tar_name))?;
        }
        Ok(())
    }
}

impl Source {
    /// Copies the file into `out` block by block (an asset is never whole in memory) and
    /// checks it against the hash that named it: a file changed since it was recorded
    /// would otherwise be written under another content's name. Returns the byte count.
    /// `out_name` is what a write error names.
    fn copy_to(&self, out: &mut dyn Write, out_name: &Path) -> Result<u64, Error> {
        use std::io::Read as _;
        let mut file = open_regular_file(&self.path)?;
        let mut hasher = blake3::Hasher::new();
        let mut buf = vec![0u8; 1 << 16];
        let mut total = 0u64;
        loop {
            let n = match file.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(read_error(&self.path, e.to_string())),
            };
            hasher.update(&buf[..n]);
            out.write_all(&buf[..n]).map_err(|e| {
                Error::bare(ErrorKind::Write {
                    path: out_name.to_path_buf(),
                    reason: e.to_string(),
                })
            })?;
            total += n as u64;
        }
        if hasher.finalize() != self.hash {
            return Err(read_error(
                &self.path,
                "the file changed while the output was being written",
            ));
        }
        Ok(total)
    }
}

fn read_error(path: &Path, reason: impl Into<String>) -> Error {
    Error::bare(ErrorKind::Io {
        path: path.to_path_buf(),
        reason: reason.into(),
    })
}

/// Opens `path` if it is a regular file: a FIFO would block forever and a device such as
/// `/dev/zero` never ends. Opened without blocking (a FIFO without a writer would block
/// the open itself), then checked on the open file, so nothing can swap it in between.
fn open_regular_file(path: &Path) -> Result<std::fs::File, Error> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // No effect on the regular files that pass the check below.
        options.custom_flags(rustix::fs::OFlags::NONBLOCK.bits() as i32);
    }
    let file = options
        .open(path)
        .map_err(|e| read_error(path, e.to_string()))?;
    let meta = file
        .metadata()
        .map_err(|e| read_error(path, e.to_string()))?;
    if !meta.is_file() {
        return Err(read_error(path, "not a regular file"));
    }
    Ok(file)
}

fn hash_file(path: &Path) -> Result<blake3::Hash, Error> {
    let file = open_regular_file(path)?;
    let mut hasher = blake3::Hasher::new();
    hasher
        .update_reader(file)
        .map_err(|e| read_error(path, e.to_string()))?;
    Ok(hasher.finalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names are standard BLAKE3 (the specification's vector for the empty input), so
    /// any other implementation, on any machine, gives the same names.
    #[test]
    fn names_are_standard_blake3_with_the_source_extension() {
        let tmp = tempfile::tempdir().unwrap();
        let empty = tmp.path().join("empty.STL");
        std::fs::write(&empty, "").unwrap();
        let store = AssetStore::new();
        assert_eq!(
            store.relocate_file(&empty).unwrap(),
            "assets/af1349b9f5f9a1a6a0404dea36dcc949.STL"
        );
        let bare = tmp.path().join("noext");
        std::fs::write(&bare, "").unwrap();
        assert_eq!(
            store.relocate_file(&bare).unwrap(),
            "assets/af1349b9f5f9a1a6a0404dea36dcc949"
        );
    }

    /// A FIFO without a writer would block a plain open forever.
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_at_once() {
        let tmp = tempfile::tempdir().unwrap();
        let fifo = tmp.path().join("mesh.stl");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let err = AssetStore::new().relocate_file(&fifo).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!("cannot read '{}': not a regular file", fifo.display())
        );
    }

    #[test]
    fn a_file_changed_after_it_was_named_is_not_copied() {
        let tmp = tempfile::tempdir().unwrap();
        let file = tmp.path().join("a.stl");
        std::fs::write(&file, "one").unwrap();
        let store = AssetStore::new();
        store.relocate_file(&file).unwrap();
        std::fs::write(&file, "two").unwrap();
        let out = OutputDir::create(tmp.path().join("out")).unwrap();
        let err = store.write_to_dir(&out).unwrap_err().to_string();
        let expected = format!(
            "cannot read '{}': the file changed while the output was being written",
            file.display()
        );
        assert_eq!(err, expected);
        // Nothing under the content name, and no temporary file either.
        let left: Vec<_> = std::fs::read_dir(tmp.path().join("out/assets"))
            .map(|d| d.map(|e| e.unwrap().file_name()).collect())
            .unwrap_or_default();
        assert!(left.is_empty(), "{left:?}");
        // The same for a tar stream.
        let mut tar = TarWriter::new(Vec::new(), "t.tar");
        assert_eq!(
            store.write_to_tar(&mut tar).unwrap_err().to_string(),
            expected
        );
    }
}
