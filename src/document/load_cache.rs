//! Loaded files kept for the next load of the same, unchanged file: what robosuite-style
//! code does at every environment reset (the same robot, gripper, arena and object files
//! read, inlined and made absolute again) becomes a copy of the arena.
//!
//! A kept document is served again only while its file holds the bytes it was parsed
//! from. One `stat` vouches for that once the kept bytes were seen in the file at least
//! [`SETTLED`] after its last change (as git trusts a racily clean index entry only then):
//! any later write changes the change time (`ctime`, which no program can set back), the
//! modification time or the length. Until then, the file is read and compared at each load
//! (a file rewritten within one tick of the file system's clock keeps its times). Only
//! documents read from one file are kept: a file with `<include>`s also depends on which
//! files exist where MuJoCo looks for them (see `read/include.rs`), which neither bytes nor
//! times of the files read can vouch for.
//! A load is keyed by the path as given (it is shown in messages) and, for a relative
//! path, the working directory it was read from.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use ahash::AHashMap;

use crate::document::Document;
use crate::document::limits::Limits;
use crate::error::Errors;

/// A bounded set of loaded documents, each served again (copied) while its file holds
/// the same bytes (see the module's documentation for how that is known); the oldest kept document goes first when the set is full. Shared by
/// threads: the lock is held for a look-up, never for a read, a parse or a copy.
///
/// ```
/// use mjcf_forge::LoadCache;
/// let path = std::env::temp_dir().join("mjcf_forge_load_cache_doc.xml");
/// std::fs::write(&path, r#"<mujoco><worldbody><geom size="1"/></worldbody></mujoco>"#).unwrap();
/// let cache = LoadCache::new(16);
/// let first = cache.load(&path)?;
/// let again = cache.load(&path)?; // a copy of the kept document: the file is unchanged
/// assert_eq!(first.to_xml_string(), again.to_xml_string());
/// assert_eq!((cache.len(), cache.hits()), (1, 1));
/// # std::fs::remove_file(&path).unwrap();
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
#[derive(Debug)]
pub struct LoadCache {
    capacity: usize,
    state: Mutex<State>,
}

#[derive(Debug, Default)]
struct State {
    kept: AHashMap<Key, Kept>,
    /// Keys from the oldest kept to the newest.
    order: VecDeque<Key>,
    hits: u64,
    /// Hits that read the file to compare its bytes (the others took one `stat`).
    compared: u64,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct Key {
    path: PathBuf,
    /// The working directory, for a relative path.
    cwd: Option<PathBuf>,
}

#[derive(Debug)]
struct Kept {
    /// The file's times and identity when its bytes were last seen to be `bytes`.
    stamp: Stamp,
    /// Whether `bytes` were seen in the file at least [`SETTLED`] after its last change.
    settled: bool,
    /// The file's bytes the document was parsed from.
    bytes: Arc<[u8]>,
    doc: Arc<Document>,
}

/// How long after a file's last change its times vouch for its bytes: longer than a tick
/// of any file system's clock (FAT's is 2 s; Linux's is a scheduler tick).
const SETTLED: Duration = Duration::from_secs(3);

/// What changes whenever a file is written: its length, times and identity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Stamp {
    len: u64,
    modified: Option<SystemTime>,
    /// Seconds and nanoseconds of the status change (unix; `modified` elsewhere).
    changed: (i64, i64),
    inode: u64,
    device: u64,
}

impl Stamp {
    /// The stamp of a regular file within the default size limit (anything else is left
    /// to [`Document::load`], which says what is wrong).
    fn of(path: &Path) -> Option<Stamp> {
        let meta = std::fs::metadata(path).ok()?;
        if !meta.is_file() || meta.len() > Limits::default().max_file_size {
            return None;
        }
        #[cfg(unix)]
        let (changed, inode, device) = {
            use std::os::unix::fs::MetadataExt;
            ((meta.ctime(), meta.ctime_nsec()), meta.ino(), meta.dev())
        };
        #[cfg(not(unix))]
        let (changed, inode, device) = ((0, 0), 0, 0);
        Some(Stamp {
            len: meta.len(),
            modified: meta.modified().ok(),
            changed,
            inode,
            device,
        })
    }

    /// Whether, at `now`, the file's last change is at least [`SETTLED`] ago.
    fn settled_at(&self, now: SystemTime) -> bool {
        let changed = UNIX_EPOCH
            .checked_add(Duration::new(
                u64::try_from(self.changed.0).unwrap_or(u64::MAX),
                u32::try_from(self.changed.1).unwrap_or(0),
            ))
            .filter(|_| cfg!(unix));
        let last = match (changed, self.modified) {
            (Some(c), Some(m)) => c.max(m),
            (c, m) => match c.or(m) {
                Some(t) => t,
                None => return false,
            },
        };
        now.duration_since(last).is_ok_and(|ago| ago >= SETTLED)
    }
}

/// The file's bytes (`None` if it cannot be read).
fn read_bytes(path: &Path) -> Option<Vec<u8>> {
    std::fs::read(path).ok()
}

impl LoadCache {
    /// A cache that keeps at most `capacity` documents (0 keeps none: every load reads).
    pub fn new(capacity: usize) -> LoadCache {
        LoadCache {
            capacity,
            state: Mutex::new(State::default()),
        }
    }

    /// [`Document::load`] of `path`, or a copy of the document kept from an earlier load
    /// of the same path while the file holds the same bytes. Errors are never kept: a file that
    /// fails to load fails again, read again.
    pub fn load(&self, path: impl AsRef<Path>) -> Result<Document, Errors> {
        let path = path.as_ref();
        let key = Key {
            path: path.to_path_buf(),
            cwd: if path.is_relative() {
                std::env::current_dir().ok()
            } else {
                None
            },
        };
        let stamp = Stamp::of(path);
        if let Some(stamp) = stamp
            && let Some(doc) = self.kept(&key, stamp, path)
        {
            return Ok(doc);
        }
        // Read, parse, and keep what was parsed if the file did not change meanwhile.
        let now = SystemTime::now();
        let before = stamp.and_then(|_| read_bytes(path));
        let doc = Document::load(path)?;
        if let (Some(stamp), Some(bytes)) = (stamp, before)
            && self.capacity > 0
            && doc.files.len() == 1
            && read_bytes(path).as_deref() == Some(&bytes[..])
            && Stamp::of(path) == Some(stamp)
        {
            let kept = Kept {
                stamp,
                settled: stamp.settled_at(now),
                bytes: bytes.into(),
                doc: Arc::new(doc.clone()),
            };
            self.keep(key, kept);
        }
        Ok(doc)
    }

    /// A copy of the document kept under `key`, if the file (stamped `stamp` just now)
    /// still holds its bytes.
    fn kept(&self, key: &Key, stamp: Stamp, path: &Path) -> Option<Document> {
        let (doc, settled, bytes) = {
            let state = self.lock();
            let kept = state.kept.get(key).filter(|k| k.stamp == stamp)?;
            (Arc::clone(&kept.doc), kept.settled, Arc::clone(&kept.bytes))
        };
        if !settled {
            let now = SystemTime::now();
            if read_bytes(path).as_deref() != Some(&bytes[..]) {
                return None;
            }
            self.lock().compared += 1;
            if stamp.settled_at(now) {
                let mut state = self.lock();
                if let Some(k) = state
                    .kept
                    .get_mut(key)
                    .filter(|k| Arc::ptr_eq(&k.doc, &doc))
                {
                    k.settled = true;
                }
            }
        }
        self.lock().hits += 1;
        Some(Document::clone(&doc))
    }

    fn keep(&self, key: Key, kept: Kept) {
        let mut state = self.lock();
        if state.kept.insert(key.clone(), kept).is_none() {
            state.order.push_back(key);
        }
        while state.kept.len() > self.capacity {
            let Some(oldest) = state.order.pop_front() else {
                break;
            };
            state.kept.remove(&oldest);
        }
    }

    /// How many documents are kept.
    pub fn len(&self) -> usize {
        self.lock().kept.len()
    }

    /// Whether no document is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// How many loads were served from kept documents so far.
    pub fn hits(&self) -> u64 {
        self.lock().hits
    }

    /// Forgets every kept document.
    pub fn clear(&self) {
        let mut state = self.lock();
        state.kept.clear();
        state.order.clear();
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        // A panic while the lock was held cannot leave the map half-written (every
        // change is one insert or remove), so a poisoned lock is still sound.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str, xml: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("mjcf_forge_load_cache_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, xml).unwrap();
        path
    }

    #[test]
    fn an_unchanged_file_is_served_again_and_a_changed_one_read_again() {
        let path = temp(
            "a.xml",
            r#"<mujoco><worldbody><geom size="1"/></worldbody></mujoco>"#,
        );
        let cache = LoadCache::new(4);
        let first = cache.load(&path).unwrap();
        assert_eq!(
            cache.load(&path).unwrap().to_xml_string(),
            first.to_xml_string()
        );
        assert_eq!(cache.hits(), 1);
        // Rewritten at once with as many bytes (no time stamp would tell): read again, and
        // the new text is what comes back.
        std::fs::write(
            &path,
            r#"<mujoco><worldbody><geom size="2"/></worldbody></mujoco>"#,
        )
        .unwrap();
        let changed = cache.load(&path).unwrap();
        assert!(changed.to_xml_string().contains(r#"size="2""#));
        assert_eq!((cache.hits(), cache.len()), (1, 1));
        // Removed: an error, as Document::load gives, and never served from the cache.
        std::fs::remove_file(&path).unwrap();
        let err = cache.load(&path).unwrap_err().to_string();
        assert_eq!(err, Document::load(&path).unwrap_err().to_string());
    }

    #[test]
    fn a_settled_file_is_vouched_for_by_its_stamp_and_a_rewrite_still_seen() {
        let path = temp(
            "s.xml",
            r#"<mujoco><worldbody><geom size="1"/></worldbody></mujoco>"#,
        );
        let cache = LoadCache::new(4);
        cache.load(&path).unwrap(); // racy: kept, compared at each hit until settled
        cache.load(&path).unwrap();
        assert_eq!((cache.hits(), cache.lock().compared), (1, 1));
        std::thread::sleep(SETTLED + Duration::from_millis(100));
        cache.load(&path).unwrap(); // compared once more, then settled
        cache.load(&path).unwrap(); // one stat
        assert_eq!((cache.hits(), cache.lock().compared), (3, 2));
        // Rewritten with as many bytes: the change time moved, so it is read again.
        std::fs::write(
            &path,
            r#"<mujoco><worldbody><geom size="7"/></worldbody></mujoco>"#,
        )
        .unwrap();
        assert!(
            cache
                .load(&path)
                .unwrap()
                .to_xml_string()
                .contains(r#"size="7""#)
        );
        assert_eq!(cache.hits(), 3);
    }

    #[test]
    fn edits_to_a_served_copy_do_not_reach_the_kept_document() {
        let path = temp(
            "b.xml",
            r#"<mujoco><worldbody><body name="b"/></worldbody></mujoco>"#,
        );
        let cache = LoadCache::new(4);
        let mut copy = cache.load(&path).unwrap();
        copy.apply_prefix("p_").unwrap();
        assert!(copy.to_xml_string().contains("p_b"));
        assert!(!cache.load(&path).unwrap().to_xml_string().contains("p_b"));
    }

    #[test]
    fn files_with_includes_are_not_kept_and_the_oldest_goes_first() {
        temp(
            "part.xml",
            r#"<mujoco><worldbody><geom size="1"/></worldbody></mujoco>"#,
        );
        let main = temp("main.xml", r#"<mujoco><include file="part.xml"/></mujoco>"#);
        let cache = LoadCache::new(2);
        cache.load(&main).unwrap();
        assert!(cache.is_empty());
        let paths: Vec<PathBuf> = (0..3)
            .map(|i| temp(&format!("c{i}.xml"), "<mujoco/>"))
            .collect();
        for p in &paths {
            cache.load(p).unwrap();
        }
        assert_eq!(cache.len(), 2);
        cache.load(&paths[0]).unwrap(); // the oldest went: read again, not a hit
        assert_eq!(cache.hits(), 0);
        cache.load(&paths[2]).unwrap();
        assert_eq!(cache.hits(), 1);
        cache.clear();
        assert!(cache.is_empty());
        assert_eq!(
            LoadCache::new(0).load(&paths[1]).unwrap().to_xml_string(),
            "<mujoco/>"
        );
    }
}
