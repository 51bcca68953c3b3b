//! Compiled models kept across processes: a [`DiskStore`] holds one file per compiled
//! structure, named by a [`StoreKey`] (the structure key, the MuJoCo that compiled it, and
//! the bytes of every file the model reads), so a structure compiled once on a machine is a
//! load for any later process, and a changed mesh, texture or include is a miss, never a
//! stale model. What a face stores is its MuJoCo's own binary model (`mj_saveModel`), which
//! loads to the model the compile gave; the store only keeps bytes.
//!
//! The rules: an entry is written whole to a temporary file and renamed into place, so a
//! reader never sees half of one and processes racing on one structure each write a whole
//! entry (the last rename wins; every one holds the same model); every entry carries its key
//! and a BLAKE3 hash of its bytes, checked on each read: a truncated or corrupt entry is
//! reported ([`StoreError::Corrupt`]), removed, and never loaded; the store is bounded in
//! bytes, least recently read or written out; a store that cannot be written (a read-only
//! folder, a full disk) reports it ([`StoreError::Io`]) and the face compiles as without it.
//!
//! ```
//! use mjcf_forge::split::{DiskStore, StoreKey};
//!
//! let dir = tempfile::tempdir()?;
//! let store = DiskStore::open(dir.path(), 1 << 20)?;
//! let key = StoreKey::new("0123abcd", "mujoco 3.17.0").finish();
//! assert!(store.get(&key)?.is_none()); // a miss
//! store.put(&key, b"the model's bytes")?;
//! assert_eq!(store.get(&key)?.as_deref(), Some(&b"the model's bytes"[..]));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// The first bytes of every entry (the format's version in its last digit).
const MAGIC: &[u8; 10] = b"MJFSTORE1\n";
/// An entry's file name ends so.
const EXTENSION: &str = "mjfs";
/// Bytes before an entry's model: the magic, the key (64 hex digits and a newline), the
/// model's length and its hash.
const HEADER: usize = MAGIC.len() + 65 + 8 + 32;

/// The environment variable that moves the store (a folder) or turns it off (`off`).
pub const STORE_VAR: &str = "MJCF_FORGE_STORE";
/// The environment variable that bounds the store, in megabytes.
pub const STORE_MB_VAR: &str = "MJCF_FORGE_STORE_MB";
/// The store's bound unless [`STORE_MB_VAR`] says otherwise: 4 GiB.
pub const DEFAULT_STORE_BYTES: u64 = 4 << 30;

/// What names a compiled structure in a store: the structure key, the compiling MuJoCo, and
/// every file the model reads, by path and content.
///
/// ```
/// use mjcf_forge::split::StoreKey;
///
/// let a = StoreKey::new("key", "mujoco 3.17.0").finish();
/// let b = StoreKey::new("key", "mujoco 4.0.0").finish();
/// assert_ne!(a, b);
/// assert_eq!(a.len(), 64);
/// ```
pub struct StoreKey {
    hasher: blake3::Hasher,
}

impl StoreKey {
    /// The key of structure `structure` compiled by `mujoco` (its version, as the face
    /// names it).
    pub fn new(structure: &str, mujoco: &str) -> StoreKey {
        let mut hasher = blake3::Hasher::new();
        for part in [structure, mujoco] {
            hasher.update(&(part.len() as u64).to_le_bytes());
            hasher.update(part.as_bytes());
        }
        StoreKey { hasher }
    }

    /// Adds a file the model reads (a mesh, a texture, a height field, an include): its
    /// path and its bytes, read now.
    pub fn file(&mut self, path: &Path) -> io::Result<&mut StoreKey> {
        let bytes = fs::read(path)?;
        let name = path.to_string_lossy();
        self.hasher.update(&(name.len() as u64).to_le_bytes());
        self.hasher.update(name.as_bytes());
        self.hasher.update(&(bytes.len() as u64).to_le_bytes());
        self.hasher.update(&bytes);
        Ok(self)
    }

    /// Adds a file the model names that cannot be read now (its path, marked missing):
    /// a key of its own, which a later read of the file does not share.
    pub fn missing(&mut self, path: &Path) -> &mut StoreKey {
        let name = path.to_string_lossy();
        self.hasher.update(&u64::MAX.to_le_bytes());
        self.hasher.update(&(name.len() as u64).to_le_bytes());
        self.hasher.update(name.as_bytes());
        self
    }

    /// The key of structure `structure` of `doc` compiled by `mujoco`: every file the
    /// document reads added ([`StoreKey::file`], or [`StoreKey::missing`] when it cannot be
    /// read). What both faces' document caches key their entries by.
    pub fn of_document(structure: &str, mujoco: &str, doc: &crate::Document) -> String {
        let mut k = StoreKey::new(structure, mujoco);
        for file in doc.files() {
            if k.file(&file).is_err() {
                k.missing(&file);
            }
        }
        k.finish()
    }

    /// The key: 64 hex digits.
    pub fn finish(&self) -> String {
        self.hasher.finalize().to_hex().to_string()
    }
}

/// Why a store call failed.
#[derive(Debug)]
pub enum StoreError {
    /// The entry at `path` is not a whole entry of its key (`why`): removed, not loaded.
    Corrupt {
        /// The entry's file.
        path: PathBuf,
        /// What was wrong with it.
        why: String,
    },
    /// The store's folder could not be read or written (`what` was being done).
    Io {
        /// What the store was doing, with its file.
        what: String,
        /// The system's error.
        error: io::Error,
    },
}

impl fmt::Display for StoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StoreError::Corrupt { path, why } => write!(
                f,
                "{}: a corrupt model store entry ({why}): removed, compiled instead",
                path.display()
            ),
            StoreError::Io { what, error } => write!(f, "model store: {what}: {error}"),
        }
    }
}

impl std::error::Error for StoreError {}

fn io(what: impl Into<String>) -> impl FnOnce(io::Error) -> StoreError {
    let what = what.into();
    move |error| StoreError::Io { what, error }
}

/// One entry as [`DiskStore::entries`] lists it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StoreEntry {
    /// Its key.
    pub key: String,
    /// Its size on disk.
    pub bytes: u64,
    /// When it was last read or written.
    pub used: SystemTime,
}

/// Compiled models by [`StoreKey`] in a folder, bounded in bytes (see the module).
#[derive(Debug, Clone)]
pub struct DiskStore {
    dir: PathBuf,
    max_bytes: u64,
}

impl DiskStore {
    /// The store in folder `dir` (made if missing), holding about `max_bytes` at most.
    pub fn open(dir: impl Into<PathBuf>, max_bytes: u64) -> Result<DiskStore, StoreError> {
        let dir = dir.into();
        fs::create_dir_all(&dir).map_err(io(format!("making {}", dir.display())))?;
        Ok(DiskStore { dir, max_bytes })
    }

    /// The store the environment asks for: [`STORE_VAR`] a folder, or `off` for none;
    /// unset, `$XDG_CACHE_HOME/mjcf-forge/models` (or `~/.cache/mjcf-forge/models`);
    /// bounded by [`STORE_MB_VAR`] (megabytes) or [`DEFAULT_STORE_BYTES`]. `None` when
    /// turned off or when no folder can be named.
    pub fn from_env() -> Option<Result<DiskStore, StoreError>> {
        let dir = Self::env_dir(
            std::env::var_os(STORE_VAR),
            std::env::var_os("XDG_CACHE_HOME"),
            std::env::var_os("HOME"),
        )?;
        let max = std::env::var(STORE_MB_VAR)
            .ok()
            .and_then(|mb| mb.trim().parse::<u64>().ok())
            .map_or(DEFAULT_STORE_BYTES, |mb| mb << 20);
        Some(DiskStore::open(dir, max))
    }

    /// The folder [`DiskStore::from_env`] takes from these variables' values.
    ///
    /// ```
    /// use std::path::PathBuf;
    /// use mjcf_forge::split::DiskStore;
    ///
    /// let home = Some("/home/u".into());
    /// assert_eq!(DiskStore::env_dir(None, None, home.clone()),
    ///     Some(PathBuf::from("/home/u/.cache/mjcf-forge/models")));
    /// assert_eq!(DiskStore::env_dir(Some("off".into()), None, home.clone()), None);
    /// assert_eq!(DiskStore::env_dir(Some("/tmp/m".into()), None, home), Some(PathBuf::from("/tmp/m")));
    /// ```
    pub fn env_dir(
        store: Option<std::ffi::OsString>,
        xdg_cache: Option<std::ffi::OsString>,
        home: Option<std::ffi::OsString>,
    ) -> Option<PathBuf> {
        if let Some(v) = store.filter(|v| !v.is_empty()) {
            let off = ["off", "0", "false", "no"];
            if off.iter().any(|o| v.eq_ignore_ascii_case(o)) {
                return None;
            }
            return Some(PathBuf::from(v));
        }
        let cache = xdg_cache
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
            .or_else(|| {
                home.filter(|h| !h.is_empty())
                    .map(|h| PathBuf::from(h).join(".cache"))
            })?;
        Some(cache.join("mjcf-forge").join("models"))
    }

    /// The store's folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The bound, in bytes.
    pub fn max_bytes(&self) -> u64 {
        self.max_bytes
    }

    fn path(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.{EXTENSION}"))
    }

    /// The model stored under `key`, or `None`; a corrupt entry is removed and reported.
    pub fn get(&self, key: &str) -> Result<Option<Stored>, StoreError> {
        let path = self.path(key);
        let bytes = match fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(io(format!("reading {}", path.display()))(e)),
        };
        if let Err(why) = check(&bytes, key) {
            // Another process may have put a whole entry in its place meanwhile: only
            // the bytes read are judged, and a rename that came after is left alone.
            let _ = fs::remove_file(&path);
            return Err(StoreError::Corrupt { path, why });
        }
        // Recently used: the bound drops the least recently used first.
        if let Ok(f) = fs::File::options().append(true).open(&path) {
            let _ = f.set_modified(SystemTime::now());
        }
        // The header is skipped, not moved out: an entry can be hundreds of megabytes.
        Ok(Some(Stored {
            bytes,
            start: HEADER,
        }))
    }

    /// Stores `model` under `key`, whole or not at all, then keeps the store within its
    /// bound.
    pub fn put(&self, key: &str, model: &[u8]) -> Result<(), StoreError> {
        let path = self.path(key);
        let mut tmp = tempfile::Builder::new()
            .prefix(".put-")
            .tempfile_in(&self.dir)
            .map_err(io(format!("writing into {}", self.dir.display())))?;
        let mut header = Vec::with_capacity(HEADER);
        header.extend_from_slice(MAGIC);
        header.extend_from_slice(key.as_bytes());
        header.push(b'\n');
        header.extend_from_slice(&(model.len() as u64).to_le_bytes());
        header.extend_from_slice(hash(model).as_bytes());
        // Not synced to the disk: a crash that leaves the entry torn leaves it unlike its
        // hash, and a torn entry is removed and compiled again, never loaded.
        let written = tmp.write_all(&header).and_then(|()| tmp.write_all(model));
        written.map_err(io(format!("writing {}", path.display())))?;
        tmp.persist(&path)
            .map_err(|e| io(format!("writing {}", path.display()))(e.error))?;
        self.trim(key)
    }

    /// Every entry, least recently used first.
    pub fn entries(&self) -> Result<Vec<StoreEntry>, StoreError> {
        let what = || format!("listing {}", self.dir.display());
        let mut out = Vec::new();
        for e in fs::read_dir(&self.dir).map_err(io(what()))? {
            let e = e.map_err(io(what()))?;
            let name = e.file_name().to_string_lossy().into_owned();
            let Some(key) = name.strip_suffix(&format!(".{EXTENSION}")) else {
                continue;
            };
            let Ok(meta) = e.metadata() else {
                continue; // removed meanwhile
            };
            out.push(StoreEntry {
                key: key.to_string(),
                bytes: meta.len(),
                used: meta.modified().unwrap_or(SystemTime::UNIX_EPOCH),
            });
        }
        out.sort_by(|a, b| a.used.cmp(&b.used).then_with(|| a.key.cmp(&b.key)));
        Ok(out)
    }

    /// Removes every entry; returns how many.
    pub fn clear(&self) -> Result<usize, StoreError> {
        let mut n = 0;
        for e in self.entries()? {
            match fs::remove_file(self.path(&e.key)) {
                Ok(()) => n += 1,
                Err(err) if err.kind() == io::ErrorKind::NotFound => {}
                Err(err) => return Err(io(format!("removing {}", e.key))(err)),
            }
        }
        Ok(n)
    }

    /// The least recently used entries out while the store holds more than its bound
    /// (`keep`, just written, stays).
    fn trim(&self, keep: &str) -> Result<(), StoreError> {
        let entries = self.entries()?;
        let mut total: u64 = entries.iter().map(|e| e.bytes).sum();
        for e in entries {
            if total <= self.max_bytes {
                break;
            }
            if e.key == keep {
                continue;
            }
            if fs::remove_file(self.path(&e.key)).is_ok() {
                total = total.saturating_sub(e.bytes);
            }
        }
        Ok(())
    }
}

/// The one rule both faces use a store by, on a miss: the entry of `key` loaded (`load`:
/// the face's MuJoCo reading its binary model; `true` returned with it: a model of the
/// structure, to be patched), or else `compile` run and its model stored (`save`: the
/// binary model). A store that fails (a corrupt entry, an unwritable folder, a model
/// MuJoCo cannot read back) is reported to `warn` and the compile stands; without a store
/// (`None`) this is the compile.
///
/// ```
/// use mjcf_forge::split::{DiskStore, StoreKey, load_or_compile};
///
/// let dir = tempfile::tempdir()?;
/// let store = DiskStore::open(dir.path(), 1 << 20)?;
/// let key = StoreKey::new("structure", "v").finish();
/// let mut warnings = Vec::new();
/// let mut run = || load_or_compile(Some((&store, key.as_str())),
///     |b: &[u8]| Some(b.to_vec()), |m: &Vec<u8>| Some(m.clone()),
///     || Ok::<_, String>(b"compiled".to_vec()), &mut |w| warnings.push(w));
/// assert_eq!(run()?, (b"compiled".to_vec(), false)); // compiled, then stored
/// assert_eq!(run()?, (b"compiled".to_vec(), true)); // loaded
/// # drop(run);
/// assert!(warnings.is_empty());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn load_or_compile<M, E>(
    store: Option<(&DiskStore, &str)>,
    load: impl FnOnce(&[u8]) -> Option<M>,
    save: impl FnOnce(&M) -> Option<Vec<u8>>,
    compile: impl FnOnce() -> Result<M, E>,
    warn: &mut dyn FnMut(String),
) -> Result<(M, bool), E> {
    let Some((store, key)) = store else {
        return compile().map(|m| (m, false));
    };
    match store.get(key) {
        Ok(Some(bytes)) => match load(&bytes) {
            Some(model) => return Ok((model, true)),
            None => warn(format!(
                "{}: MuJoCo could not read this model store entry back: compiled instead",
                store.path(key).display()
            )),
        },
        Ok(None) => {}
        Err(e) => warn(e.to_string()),
    }
    let model = compile()?;
    if let Some(bytes) = save(&model)
        && let Err(e) = store.put(key, &bytes)
    {
        warn(e.to_string());
    }
    Ok((model, false))
}

/// The BLAKE3 hash of `bytes`, on every core for a large model.
fn hash(bytes: &[u8]) -> blake3::Hash {
    if bytes.len() < 1 << 20 {
        return blake3::hash(bytes);
    }
    let mut hasher = blake3::Hasher::new();
    hasher.update_rayon(bytes);
    hasher.finalize()
}

/// A stored model's bytes, as [`DiskStore::get`] read them (the entry's header skipped).
#[derive(Debug)]
pub struct Stored {
    bytes: Vec<u8>,
    start: usize,
}

impl std::ops::Deref for Stored {
    type Target = [u8];

    fn deref(&self) -> &[u8] {
        &self.bytes[self.start..]
    }
}

/// Whether `bytes` are a whole entry of `key`; what is wrong otherwise.
fn check(bytes: &[u8], key: &str) -> Result<(), String> {
    if bytes.len() < HEADER {
        return Err(format!("{} bytes, shorter than a header", bytes.len()));
    }
    if &bytes[..MAGIC.len()] != MAGIC {
        return Err("not a model store entry".into());
    }
    let k = &bytes[MAGIC.len()..MAGIC.len() + 64];
    if k != key.as_bytes() || bytes[MAGIC.len() + 64] != b'\n' {
        return Err("the entry of another key".into());
    }
    let at = MAGIC.len() + 65;
    let len = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap_or([0; 8]));
    let body = &bytes[HEADER..];
    if body.len() as u64 != len {
        return Err(format!("{} bytes of a {len}-byte model", body.len()));
    }
    if hash(body).as_bytes() != &bytes[at + 8..HEADER] {
        return Err("its bytes do not have its hash".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(s: &str) -> String {
        StoreKey::new(s, "test").finish()
    }

    #[test]
    fn a_changed_file_is_another_key() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = dir.path().join("m.stl");
        fs::write(&mesh, b"one").unwrap();
        let a = StoreKey::new("s", "v").file(&mesh).unwrap().finish();
        fs::write(&mesh, b"two").unwrap();
        let b = StoreKey::new("s", "v").file(&mesh).unwrap().finish();
        assert_ne!(a, b);
        let gone = StoreKey::new("s", "v").missing(&mesh).finish();
        assert!(gone != a && gone != b);
        assert!(
            StoreKey::new("s", "v")
                .file(&dir.path().join("gone"))
                .is_err()
        );
    }

    #[test]
    fn truncated_flipped_and_foreign_entries_are_corrupt_and_removed() {
        let dir = tempfile::tempdir().unwrap();
        let store = DiskStore::open(dir.path(), 1 << 20).unwrap();
        let (k, other) = (key("a"), key("b"));
        type Spoil = fn(&mut Vec<u8>);
        let cases: [(&str, Spoil); 3] = [
            ("truncated", |b| b.truncate(b.len() - 3)),
            ("flipped", |b| *b.last_mut().unwrap() ^= 1),
            ("emptied", |b| b.clear()),
        ];
        for (what, spoil) in cases {
            store.put(&k, b"0123456789").unwrap();
            let path = store.path(&k);
            let mut bytes = fs::read(&path).unwrap();
            spoil(&mut bytes);
            fs::write(&path, &bytes).unwrap();
            let err = store.get(&k).unwrap_err();
            assert!(matches!(err, StoreError::Corrupt { .. }), "{what}: {err}");
            assert!(!path.exists(), "{what}: the corrupt entry stays");
            assert!(store.get(&k).unwrap().is_none());
        }
        // An entry renamed under another key's name.
        store.put(&other, b"x").unwrap();
        fs::rename(store.path(&other), store.path(&k)).unwrap();
        assert!(matches!(store.get(&k), Err(StoreError::Corrupt { .. })));
    }

    #[test]
    fn the_bound_drops_the_least_recently_used() {
        let dir = tempfile::tempdir().unwrap();
        let one = (HEADER + 100) as u64;
        let store = DiskStore::open(dir.path(), 2 * one).unwrap();
        let keys: Vec<String> = ["a", "b", "c"].iter().map(|s| key(s)).collect();
        let old = SystemTime::UNIX_EPOCH + std::time::Duration::from_secs(1_000_000);
        for (i, k) in keys[..2].iter().enumerate() {
            store.put(k, &[i as u8; 100]).unwrap();
            let f = fs::File::options()
                .append(true)
                .open(store.path(k))
                .unwrap();
            f.set_modified(old + std::time::Duration::from_secs(i as u64))
                .unwrap();
        }
        // "a" read: now the most recent of the two.
        assert!(store.get(&keys[0]).unwrap().is_some());
        store.put(&keys[2], &[2; 100]).unwrap();
        let left: Vec<String> = store
            .entries()
            .unwrap()
            .into_iter()
            .map(|e| e.key)
            .collect();
        assert_eq!(left.len(), 2);
        assert!(left.contains(&keys[0]) && left.contains(&keys[2]));
        assert_eq!(store.clear().unwrap(), 2);
        assert!(store.entries().unwrap().is_empty());
    }

    #[test]
    fn writers_racing_on_one_entry_never_show_a_reader_half_of_it() {
        let dir = tempfile::tempdir().unwrap();
        let store = DiskStore::open(dir.path(), 1 << 30).unwrap();
        let k = key("race");
        let model: Vec<u8> = (0..2_000_000u32).map(|i| (i % 251) as u8).collect();
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    for _ in 0..5 {
                        store.put(&k, &model).unwrap();
                    }
                });
            }
            s.spawn(|| {
                for _ in 0..200 {
                    match store.get(&k) {
                        Ok(Some(got)) => assert!(*got == model[..]),
                        Ok(None) => {}
                        Err(e) => panic!("a reader saw {e}"),
                    }
                }
            });
        });
        assert_eq!(&*store.get(&k).unwrap().unwrap(), &model[..]);
        // No temporary file is left behind.
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_folder_that_cannot_be_written_is_an_io_error() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("not-a-folder");
        fs::write(&file, b"").unwrap();
        assert!(matches!(
            DiskStore::open(file.join("models"), 1),
            Err(StoreError::Io { .. })
        ));
        let store = DiskStore {
            dir: file.clone(),
            max_bytes: 1,
        };
        assert!(matches!(
            store.put(&key("a"), b"m"),
            Err(StoreError::Io { .. })
        ));
        assert!(matches!(
            store.get(&key("a")),
            Err(StoreError::Io { .. }) | Ok(None)
        ));
    }
}
