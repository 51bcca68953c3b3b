//! A fast index over [`crate::document::vocab`]: element kinds and attributes looked up by interned
//! name, built once and shared read-only by every document and thread.

use std::sync::OnceLock;

use crate::document::names::{Sym, known};
use crate::document::vocab::{self, AttrKind, AttrSpec, ElementSpec};

/// An element kind: an index into [`vocab::elements`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct Kind(pub(crate) u16);

/// Per kind, a small open-addressing table from an interned name to a value: one probe
/// for the usual lookup (these run for every element of every document), where a binary
/// search takes several dependent, unpredictable steps.
struct SymTables<V: Copy> {
    /// Per kind: where its table starts in `slots`, and log2 of its size (0: no entries).
    tables: Vec<(u32, u32)>,
    slots: Vec<Option<(Sym, V)>>,
}

impl<V: Copy> SymTables<V> {
    fn new(per_kind: &[Vec<(Sym, V)>]) -> SymTables<V> {
        let mut tables = Vec::with_capacity(per_kind.len());
        let mut slots = Vec::new();
        for entries in per_kind {
            let bits = if entries.is_empty() {
                0
            } else {
                (entries.len() * 2).next_power_of_two().trailing_zeros()
            };
            let start = slots.len();
            tables.push((start as u32, bits));
            if bits == 0 {
                continue;
            }
            slots.resize(start + (1 << bits), None);
            for &(sym, v) in entries {
                let mut i = Self::home(sym, bits);
                while slots[start + i].is_some() {
                    i = (i + 1) & ((1 << bits) - 1);
                }
                slots[start + i] = Some((sym, v));
            }
        }
        SymTables { tables, slots }
    }

    #[inline]
    fn home(sym: Sym, bits: u32) -> usize {
        (sym.0.wrapping_mul(0x9E37_79B9) >> (32 - bits)) as usize
    }

    #[inline]
    fn get(&self, kind: Kind, sym: Sym) -> Option<V> {
        let (start, bits) = self.tables[kind.0 as usize];
        if bits == 0 {
            return None;
        }
        let mut i = Self::home(sym, bits);
        loop {
            match self.slots[start as usize + i] {
                Some((s, v)) if s == sym => return Some(v),
                Some(_) => i = (i + 1) & ((1 << bits) - 1),
                None => return None,
            }
        }
    }
}

struct Index {
    /// Per kind: child tag -> child kind.
    children: SymTables<Kind>,
    /// Per kind: attribute name -> attribute spec.
    attrs: SymTables<&'static AttrSpec>,
    /// Per kind: whether any attribute holds a file name (most kinds have none).
    has_file_attrs: Vec<bool>,
    /// Per kind: whether it or a kind below it (through any chain of children) has one.
    reaches_file_attrs: Vec<bool>,
    /// Per vocabulary name: the kind whose schema name it is (`vocab::element(name)`).
    by_name: Vec<Option<Kind>>,
    root: Kind,
}

#[inline]
fn index() -> &'static Index {
    static INDEX: OnceLock<Index> = OnceLock::new();
    INDEX.get_or_init(|| {
        let all = vocab::elements();
        let kind_of = |spec: &ElementSpec| {
            Kind(
                all.iter()
                    .position(|e| std::ptr::eq(e, spec))
                    .expect("vocab kind") as u16,
            )
        };
        let mut children = Vec::with_capacity(all.len());
        let mut attrs = Vec::with_capacity(all.len());
        let mut has_file_attrs = Vec::with_capacity(all.len());
        for spec in all {
            let mut c: Vec<(Sym, Kind)> = spec
                .children
                .iter()
                .filter_map(|n| vocab::element(n))
                .filter_map(|e| known(e.tag).map(|t| (t, kind_of(e))))
                .collect();
            c.sort_by_key(|(t, _)| *t);
            c.dedup_by_key(|(t, _)| *t);
            children.push(c);
            let mut a: Vec<(Sym, &'static AttrSpec)> = spec
                .attrs
                .iter()
                .filter_map(|a| known(a.name).map(|s| (s, a)))
                .collect();
            a.sort_by_key(|(s, _)| *s);
            attrs.push(a);
            has_file_attrs.push(spec.attrs.iter().any(|a| a.kind == AttrKind::File));
        }
        // Kinds nest recursively (a body holds bodies): settle to a fixed point.
        let mut reaches_file_attrs = has_file_attrs.clone();
        let mut changed = true;
        while changed {
            changed = false;
            for k in 0..all.len() {
                if !reaches_file_attrs[k]
                    && children[k]
                        .iter()
                        .any(|(_, c): &(Sym, Kind)| reaches_file_attrs[c.0 as usize])
                {
                    reaches_file_attrs[k] = true;
                    changed = true;
                }
            }
        }
        let mut by_name = Vec::new();
        for (k, spec) in all.iter().enumerate() {
            if let Some(s) = known(spec.name) {
                let i = s.0 as usize;
                if by_name.len() <= i {
                    by_name.resize(i + 1, None);
                }
                by_name[i] = Some(Kind(k as u16));
            }
        }
        Index {
            children: SymTables::new(&children),
            attrs: SymTables::new(&attrs),
            has_file_attrs,
            reaches_file_attrs,
            by_name,
            root: kind_of(vocab::root()),
        }
    })
}

impl Kind {
    /// The root kind, `mujoco`.
    pub(crate) fn root() -> Kind {
        index().root
    }

    /// The kind of a spec from [`vocab::elements`].
    pub(crate) fn of(spec: &'static ElementSpec) -> Kind {
        let all = vocab::elements();
        let at = (spec as *const ElementSpec as usize).wrapping_sub(all.as_ptr() as usize)
            / std::mem::size_of::<ElementSpec>();
        assert!(
            at < all.len() && std::ptr::eq(&all[at], spec),
            "not a vocabulary spec"
        );
        Kind(at as u16)
    }

    /// The kind's spec.
    #[inline]
    pub(crate) fn spec(self) -> &'static ElementSpec {
        &vocab::elements()[self.0 as usize]
    }

    /// The kind of a child element with this tag.
    #[inline]
    pub(crate) fn child(self, tag: Sym) -> Option<Kind> {
        index().children.get(self, tag)
    }

    /// The attribute `name` of this kind.
    #[inline]
    pub(crate) fn attr(self, name: Sym) -> Option<&'static AttrSpec> {
        index().attrs.get(self, name)
    }

    /// The kind whose schema name is the vocabulary name `name` (as `vocab::element` finds
    /// it by string); `None` also for names outside the vocabulary, which the caller
    /// looks up by string.
    #[inline]
    pub(crate) fn named(name: Sym) -> Option<Kind> {
        index().by_name.get(name.0 as usize).copied().flatten()
    }

    /// Whether this kind or any kind that can be nested in it has a file attribute.
    #[inline]
    pub(crate) fn reaches_file_attrs(self) -> bool {
        index().reaches_file_attrs[self.0 as usize]
    }

    /// Whether some attribute of this kind holds a file name.
    #[inline]
    pub(crate) fn has_file_attrs(self) -> bool {
        index().has_file_attrs[self.0 as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::names::sym;

    #[test]
    fn resolves_context() {
        let equality = Kind::root().child(sym("equality")).unwrap();
        let joint = equality.child(sym("joint")).unwrap();
        assert_eq!(joint.spec().name, "equality_joint");
        assert!(joint.attr(sym("joint1")).is_some());
        let world = Kind::root().child(sym("worldbody")).unwrap();
        let body = world.child(sym("body")).unwrap();
        assert_eq!(body.child(sym("joint")).unwrap().spec().name, "joint");
        assert_eq!(Kind::of(body.spec()), body);
        let asset = Kind::root().child(sym("asset")).unwrap();
        assert!(asset.child(sym("mesh")).unwrap().has_file_attrs());
        assert!(!body.has_file_attrs());
        assert!(body.reaches_file_attrs()); // a body can hold a flexcomp
        assert!(
            !Kind::root()
                .child(sym("sensor"))
                .unwrap()
                .reaches_file_attrs()
        );
        for spec in vocab::elements() {
            if let Some(s) = crate::document::names::known(spec.name) {
                assert_eq!(
                    Kind::named(s).map(Kind::spec).map(|e| e.name),
                    vocab::element(spec.name).map(|e| e.name)
                );
            }
        }
        assert_eq!(Kind::named(sym("geom")).unwrap().spec().name, "geom");
    }

    #[test]
    fn attribute_names_are_unique_per_kind() {
        // `Kind::attr` finds one row by name; two rows of one name would make that ambiguous.
        for spec in vocab::elements() {
            let mut names: Vec<&str> = spec.attrs.iter().map(|a| a.name).collect();
            names.sort_unstable();
            let n = names.len();
            names.dedup();
            assert_eq!(n, names.len(), "{} repeats an attribute", spec.name);
        }
    }
}
