//! A fast index over [`crate::vocab`]: element kinds and attributes looked up by interned
//! name, built once and shared read-only by every document and thread.

use std::sync::OnceLock;

use crate::names::{Sym, known};
use crate::vocab::{self, AttrSpec, ElementSpec};

/// An element kind: an index into [`vocab::elements`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct Kind(pub(crate) u16);

struct Index {
    /// Per kind: (child tag, child kind), sorted by tag.
    children: Vec<Vec<(Sym, Kind)>>,
    /// Per kind: (attribute name, attribute spec), sorted by name.
    attrs: Vec<Vec<(Sym, &'static AttrSpec)>>,
    root: Kind,
}

fn index() -> &'static Index {
    static INDEX: OnceLock<Index> = OnceLock::new();
    INDEX.get_or_init(|| {
        let all = vocab::elements();
        let kind_of = |spec: &ElementSpec| {
            Kind(all.iter().position(|e| std::ptr::eq(e, spec)).expect("vocab kind") as u16)
        };
        let mut children = Vec::with_capacity(all.len());
        let mut attrs = Vec::with_capacity(all.len());
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
            let mut a: Vec<(Sym, &'static AttrSpec)> =
                spec.attrs.iter().filter_map(|a| known(a.name).map(|s| (s, a))).collect();
            a.sort_by_key(|(s, _)| *s);
            attrs.push(a);
        }
        Index { children, attrs, root: kind_of(vocab::root()) }
    })
}

impl Kind {
    /// The root kind, `mujoco`.
    pub(crate) fn root() -> Kind {
        index().root
    }

    /// The kind's spec.
    pub(crate) fn spec(self) -> &'static ElementSpec {
        &vocab::elements()[self.0 as usize]
    }

    /// The kind of a child element with this tag.
    pub(crate) fn child(self, tag: Sym) -> Option<Kind> {
        let c = &index().children[self.0 as usize];
        c.binary_search_by_key(&tag, |(t, _)| *t).ok().map(|i| c[i].1)
    }

    /// The attribute `name` of this kind.
    pub(crate) fn attr(self, name: Sym) -> Option<&'static AttrSpec> {
        let a = &index().attrs[self.0 as usize];
        a.binary_search_by_key(&name, |(s, _)| *s).ok().map(|i| a[i].1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::names::sym;

    #[test]
    fn resolves_context() {
        let equality = Kind::root().child(sym("equality")).unwrap();
        let joint = equality.child(sym("joint")).unwrap();
        assert_eq!(joint.spec().name, "equality_joint");
        assert!(joint.attr(sym("joint1")).is_some());
        let world = Kind::root().child(sym("worldbody")).unwrap();
        let body = world.child(sym("body")).unwrap();
        assert_eq!(body.child(sym("joint")).unwrap().spec().name, "joint");
    }
}
