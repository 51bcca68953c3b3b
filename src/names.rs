//! Interned element and attribute names.
//!
//! Every tag and attribute name of MJCF is known up front (from [`crate::vocab`]), so those
//! get fixed ids in a frozen table shared read-only by every document and thread. A name
//! outside the vocabulary (a user's typo, a newer MuJoCo attribute) gets an id local to its
//! document; merges remap such ids. Ids are `u32`: a merged scene never runs out.

use std::sync::OnceLock;

use ahash::AHashMap;

/// An interned element or attribute name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Sym(pub(crate) u32);

struct Base {
    names: Vec<&'static str>,
    ids: AHashMap<&'static str, u32>,
}

fn base() -> &'static Base {
    static BASE: OnceLock<Base> = OnceLock::new();
    BASE.get_or_init(|| {
        let mut names: Vec<&'static str> = Vec::new();
        let mut ids = AHashMap::new();
        let mut add = |n: &'static str| {
            if !ids.contains_key(n) {
                ids.insert(n, names.len() as u32);
                names.push(n);
            }
        };
        add("include");
        add("file");
        for spec in crate::vocab::elements() {
            add(spec.tag);
            for a in spec.attrs {
                add(a.name);
            }
        }
        Base { names, ids }
    })
}

/// The per-document part of the interner: names outside the vocabulary.
#[derive(Clone, Debug, Default)]
pub(crate) struct Names {
    extra: Vec<Box<str>>,
    extra_ids: AHashMap<Box<str>, u32>,
}

impl Names {
    /// The id of a name, adding it to this document if it is new.
    pub(crate) fn intern(&mut self, name: &str) -> Sym {
        let b = base();
        if let Some(&id) = b.ids.get(name) {
            return Sym(id);
        }
        if let Some(&id) = self.extra_ids.get(name) {
            return Sym(id);
        }
        let id = (b.names.len() + self.extra.len()) as u32;
        self.extra.push(name.into());
        self.extra_ids.insert(name.into(), id);
        Sym(id)
    }

    /// The id of a name if it is known here.
    pub(crate) fn get(&self, name: &str) -> Option<Sym> {
        let b = base();
        b.ids
            .get(name)
            .or_else(|| self.extra_ids.get(name))
            .map(|&id| Sym(id))
    }

    pub(crate) fn resolve(&self, sym: Sym) -> &str {
        let b = base();
        let i = sym.0 as usize;
        if i < b.names.len() {
            b.names[i]
        } else {
            &self.extra[i - b.names.len()]
        }
    }
}

/// The id of a vocabulary name (tags and attributes MuJoCo knows); `None` otherwise.
pub(crate) fn known(name: &str) -> Option<Sym> {
    base().ids.get(name).map(|&id| Sym(id))
}

/// The id of a vocabulary name that must exist (used for names spelled in our code).
pub(crate) fn sym(name: &'static str) -> Sym {
    known(name).unwrap_or_else(|| panic!("'{name}' is not in the MJCF vocabulary"))
}
