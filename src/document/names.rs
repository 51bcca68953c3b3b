//! Interned element and attribute names.
//!
//! Every tag and attribute name of MJCF is known up front (from [`crate::document::vocab`]), so those
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
    /// Per name: its length and first 16 bytes as integers. Every tag and attribute name of
    /// every document is looked up here, so the usual name (16 bytes or fewer) is matched
    /// by three integer compares, without a string compare.
    heads: Vec<Head>,
    /// Per name, as the writer puts it out (so writing a name is one copy).
    markup: Vec<Markup>,
    /// Open addressing: per slot a name's first eight bytes, length and id (or [`EMPTY`]),
    /// so a name of up to eight bytes (most attribute names) is found with one load. The
    /// keys are fixed, so a plain multiplicative hash is enough (no flooding concern).
    slots: Vec<Slot>,
    /// `64 - log2(slots.len())`: the hash's top bits pick the slot.
    shift: u32,
}

/// A name's length and first 16 bytes (zero-padded), as integers.
#[derive(Clone, Copy, PartialEq, Eq)]
struct Head {
    w0: u64,
    w1: u64,
    len: u32,
}

const EMPTY: u16 = u16::MAX;

#[derive(Clone, Copy)]
struct Slot {
    w0: u64,
    len: u16,
    id: u16,
}

#[inline]
fn le64(b: &[u8]) -> u64 {
    u64::from_le_bytes(b[..8].try_into().expect("8 bytes"))
}

#[inline]
fn le32(b: &[u8]) -> u64 {
    u64::from(u32::from_le_bytes(b[..4].try_into().expect("4 bytes")))
}

/// Up to 8 bytes, zero-padded, from overlapping loads (no byte loop, no `memcpy` call).
#[inline]
fn word(b: &[u8]) -> u64 {
    match b.len() {
        0 => 0,
        1..=3 => {
            let n = b.len();
            u64::from(b[0])
                | u64::from(b[n / 2]) << (8 * (n / 2))
                | u64::from(b[n - 1]) << (8 * (n - 1))
        }
        4..=7 => le32(b) | (le32(&b[b.len() - 4..]) >> (8 * (8 - b.len()))) << 32,
        _ => le64(b),
    }
}

impl Head {
    #[inline]
    fn of(name: &[u8]) -> Head {
        let len = name.len();
        let (w0, w1) = if len <= 8 {
            (word(name), 0)
        } else if len <= 16 {
            (le64(name), word(&name[8..]))
        } else {
            (le64(name), le64(&name[8..]))
        };
        Head {
            w0,
            w1,
            len: len as u32,
        }
    }

    #[inline]
    fn hash(&self) -> u64 {
        const K: u64 = 0x9E37_79B9_7F4A_7C15;
        let h = (self.w0 ^ u64::from(self.len)).wrapping_mul(K);
        (h.rotate_left(29) ^ self.w1).wrapping_mul(K)
    }
}

impl Base {
    #[inline]
    fn get(&self, name: &str) -> Option<u32> {
        let head = Head::of(name.as_bytes());
        let mask = self.slots.len() - 1;
        let mut i = (head.hash() >> self.shift) as usize;
        loop {
            let slot = self.slots[i];
            if slot.id == EMPTY {
                return None;
            }
            if slot.w0 == head.w0 && u32::from(slot.len) == head.len {
                let id = slot.id as usize;
                if head.len <= 8
                    || (self.heads[id] == head && (head.len <= 16 || self.names[id] == name))
                {
                    return Some(u32::from(slot.id));
                }
            }
            i = (i + 1) & mask;
        }
    }
}

#[inline]
fn base() -> &'static Base {
    static BASE: OnceLock<Base> = OnceLock::new();
    BASE.get_or_init(|| {
        let mut names: Vec<&'static str> = Vec::new();
        let mut ids: AHashMap<&'static str, u32> = AHashMap::new();
        let mut add = |n: &'static str| {
            if !ids.contains_key(n) {
                ids.insert(n, names.len() as u32);
                names.push(n);
            }
        };
        add("include");
        add("file");
        for spec in crate::document::vocab::elements() {
            add(spec.tag);
            for a in spec.attrs {
                add(a.name);
            }
        }
        assert!(
            names.len() < usize::from(EMPTY),
            "vocabulary ids fit in u16"
        );
        assert!(
            names.iter().all(|n| n.len() < usize::from(u16::MAX)),
            "lengths fit in u16"
        );
        // At most a third full: probes are short.
        let size = (names.len() * 3).next_power_of_two().max(16);
        let mut slots = vec![
            Slot {
                w0: 0,
                len: 0,
                id: EMPTY
            };
            size
        ];
        let shift = 64 - size.trailing_zeros();
        let heads: Vec<Head> = names.iter().map(|n| Head::of(n.as_bytes())).collect();
        for (id, head) in heads.iter().enumerate() {
            let mut i = (head.hash() >> shift) as usize;
            while slots[i].id != EMPTY {
                i = (i + 1) & (size - 1);
            }
            slots[i] = Slot {
                w0: head.w0,
                len: head.len as u16,
                id: id as u16,
            };
        }
        // One buffer for all of it, made `'static` like the table itself (built once per
        // process, never freed).
        let mut text = String::with_capacity(names.iter().map(|n| 3 * n.len() + 7).sum());
        for n in &names {
            for piece in [" ", n, "=\"<", n, "</", n, ">"] {
                text.push_str(piece);
            }
        }
        let text: &'static str = text.leak();
        let mut rest = text;
        let mut markup = Vec::with_capacity(names.len());
        for n in &names {
            let (attr, r) = rest.split_at(n.len() + 3);
            let (open, r) = r.split_at(n.len() + 1);
            let (close, r) = r.split_at(n.len() + 3);
            markup.push(Markup { attr, open, close });
            rest = r;
        }
        Base {
            names,
            heads,
            slots,
            shift,
            markup,
        }
    })
}

/// A vocabulary name as markup (see [`Names::markup`]).
#[derive(Debug)]
pub(crate) struct Markup {
    pub(crate) attr: &'static str,
    pub(crate) open: &'static str,
    pub(crate) close: &'static str,
}

/// The per-document part of the interner: names outside the vocabulary.
#[derive(Clone, Debug, Default)]
pub(crate) struct Names {
    extra: Vec<Box<str>>,
    extra_ids: AHashMap<Box<str>, u32>,
}

impl Names {
    /// The id of a name, adding it to this document if it is new.
    #[inline]
    pub(crate) fn intern(&mut self, name: &str) -> Sym {
        let b = base();
        if let Some(id) = b.get(name) {
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
    #[inline]
    pub(crate) fn get(&self, name: &str) -> Option<Sym> {
        match base().get(name) {
            Some(id) => Some(Sym(id)),
            None => self.extra_ids.get(name).map(|&id| Sym(id)),
        }
    }

    /// For a vocabulary name: ` name="`, `<name` and `</name>`, as the writer puts them out.
    #[inline]
    pub(crate) fn markup(&self, sym: Sym) -> Option<&'static Markup> {
        base().markup.get(sym.0 as usize)
    }

    #[inline]
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
#[inline]
pub(crate) fn known(name: &str) -> Option<Sym> {
    base().get(name).map(Sym)
}

/// Whether `sym` is a vocabulary name (the same id in every document).
#[inline]
pub(crate) fn is_vocabulary(sym: Sym) -> bool {
    (sym.0 as usize) < base().names.len()
}

/// The id of a vocabulary name that must exist (used for names spelled in our code).
pub(crate) fn sym(name: &'static str) -> Sym {
    known(name).unwrap_or_else(|| panic!("'{name}' is not in the MJCF vocabulary"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_vocabulary_name_finds_its_id() {
        let b = base();
        for (id, n) in b.names.iter().enumerate() {
            assert_eq!(b.get(n), Some(id as u32), "{n}");
        }
        for n in ["", "geomz", "zz", "a_very_long_name_outside_the_vocabulary"] {
            assert_eq!(b.get(n), None, "{n}");
        }
        // Every length class of the inline head, against a name that differs in one byte.
        for n in b.names.iter().filter(|n| n.is_ascii()) {
            for i in 0..n.len() {
                let mut other = n.as_bytes().to_vec();
                other[i] ^= 0x20;
                let other = String::from_utf8(other).unwrap();
                if !b.names.contains(&other.as_str()) {
                    assert_eq!(b.get(&other), None, "{other}");
                }
            }
        }
        for len in 0..40 {
            let mut head = [0u8; 40];
            let mut other = [0u8; 40];
            for i in 0..len {
                head[i] = b'a' + i as u8;
                other[i] = b'a' + i as u8;
            }
            assert!(Head::of(&head[..len]) == Head::of(&other[..len]));
            if len > 0 {
                other[len - 1] = b'Z';
                assert!(
                    len > 16 || Head::of(&head[..len]) != Head::of(&other[..len]),
                    "{len}"
                );
                other[0] = b'Z';
                assert!(Head::of(&head[..len]) != Head::of(&other[..len]), "{len}");
            }
        }
        let mut names = Names::default();
        let extra = names.intern("not-mjcf");
        assert_eq!(names.intern("not-mjcf"), extra);
        assert_eq!(names.resolve(extra), "not-mjcf");
        assert_eq!(names.get("geom"), known("geom"));
        let m = names.markup(known("geom").unwrap()).unwrap();
        assert_eq!((m.attr, m.open, m.close), (" geom=\"", "<geom", "</geom>"));
        assert!(names.markup(extra).is_none());
    }
}
