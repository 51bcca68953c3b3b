//! Loaded files kept for the next load of the same, unchanged file: what robosuite-style
//! code does at every environment reset (the same robot, gripper, arena and object files
//! read, inlined and made absolute again) becomes a copy of the arena.
//!
//! A kept document is served again only while its file holds the same bytes: the file is
//! read at every load and compared with what was parsed (no time stamp can vouch for a
//! file rewritten within the file system's clock tick). Only documents read from one file
//! are kept: a file with `<include>`s also depends on which files exist where MuJoCo looks
//! for them (see `read/include.rs`), which no comparison of the files read can vouch for.
//! A load is keyed by the path as given (it is shown in messages) and, for a relative
//! path, the working directory it was read from.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use ahash::AHashMap;

use crate::document::Document;
use crate::document::limits::Limits;
use crate::error::Errors;

/// A bounded set of loaded documents, each served again (copied) while its file holds
/// the same bytes; the oldest kept document goes first when the set is full. Shared by
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
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct Key {
    path: PathBuf,
    /// The working directory, for a relative path.
    cwd: Option<PathBuf>,
}

#[derive(Debug)]
struct Kept {
    /// The file's bytes the document was parsed from.
    bytes: Arc<[u8]>,
    doc: Arc<Document>,
}

/// The file's bytes, if it is a readable file within the default size limit (anything
/// else is left to [`Document::load`], which says what is wrong).
fn read_bytes(path: &Path) -> Option<Vec<u8>> {
    let meta = std::fs::metadata(path).ok()?;
    if !meta.is_file() || meta.len() > Limits::default().max_file_size {
        return None;
    }
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
        let bytes = read_bytes(path);
        if let Some(bytes) = &bytes {
            let mut state = self.lock();
            let kept = state
                .kept
                .get(&key)
                .filter(|kept| *kept.bytes == **bytes)
                .map(|kept| Arc::clone(&kept.doc));
            if let Some(doc) = kept {
                state.hits += 1;
                drop(state);
                return Ok(Document::clone(&doc));
            }
        }
        let doc = Document::load(path)?;
        // Kept only if the file held the same bytes before and after it was parsed.
        if let Some(bytes) = bytes
            && self.capacity > 0
            && doc.files.len() == 1
            && read_bytes(path).as_deref() == Some(&bytes[..])
        {
            self.keep(key, bytes.into(), Arc::new(doc.clone()));
        }
        Ok(doc)
    }

    fn keep(&self, key: Key, bytes: Arc<[u8]>, doc: Arc<Document>) {
        let mut state = self.lock();
        if state
            .kept
            .insert(key.clone(), Kept { bytes, doc })
            .is_none()
        {
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
