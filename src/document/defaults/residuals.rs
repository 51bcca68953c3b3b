//! Residual classes: values an element inherits but its kind has no attribute for, kept in
//! classes of their own (one per distinct set) so that the output still compiles to them.

use super::Resolver;
use crate::document::names::Sym;
use crate::document::tree::StrRef;
use crate::document::vocab::{self, DefaultSlot};

/// The tag of a default slot's row inside `<default>`.
fn slot_tag(slot: DefaultSlot) -> &'static str {
    let default = vocab::element("default").expect("default kind");
    default
        .children
        .iter()
        .filter_map(|n| vocab::element(n))
        .find(|e| e.default_slot == Some(slot))
        .map(|e| e.tag)
        .expect("every slot has a default row")
}

/// The name of the `i`-th residual class.
fn residual_class(i: usize) -> String {
    format!("mjcf-forge-residual-{i}")
}

impl Resolver<'_> {
    /// The name of the residual class holding `residual` for `slot` (see
    /// [`Resolver::residuals`]): elements left with the same values share one class.
    pub(super) fn residual_class_name(
        &mut self,
        slot: DefaultSlot,
        residual: Vec<(Sym, StrRef)>,
    ) -> StrRef {
        let key: Vec<(Sym, String)> = residual
            .iter()
            .map(|&(n, v)| (n, self.doc.str(v).to_string()))
            .collect();
        let found = self.residuals.iter().position(|(s, attrs)| {
            *s == slot
                && attrs.len() == key.len()
                && attrs
                    .iter()
                    .zip(&key)
                    .all(|(a, k)| a.0 == k.0 && self.doc.str(a.1) == k.1)
        });
        let i = found.unwrap_or_else(|| {
            self.residuals.push((slot, residual));
            self.residuals.len() - 1
        });
        self.doc.push_str(&residual_class(i))
    }

    /// Writes the residual classes as the only `<default>` left (see [`Resolver::residuals`]).
    pub(super) fn write_residuals(&mut self) {
        if self.residuals.is_empty() {
            return;
        }
        let root = self.doc.root;
        let top = self.doc.new_element(self.syms.default, None);
        let residuals = std::mem::take(&mut self.residuals);
        for (i, (slot, attrs)) in residuals.iter().enumerate() {
            let class = self.doc.new_element(self.syms.default, None);
            let name = self.doc.push_str(&residual_class(i));
            self.doc.set_attr_ref(class, self.syms.class, name);
            let tag = self.doc.intern(slot_tag(*slot));
            let row = self.doc.new_element(tag, None);
            let attrs: Vec<crate::document::tree::Attr> = attrs
                .iter()
                .map(|&(name, value)| crate::document::tree::Attr { name, value })
                .collect();
            self.doc.replace_attrs(row, &attrs);
            self.doc.tree.append(class, row);
            self.doc.tree.append(top, class);
        }
        // Defaults are read before the kinematic tree whatever their place: first is tidy.
        let first = self.doc.tree.first_child(root);
        match first {
            Some(first) => self.doc.tree.insert_before(first, top),
            None => self.doc.tree.append(root, top),
        }
    }
}
