//! Resolution: every element MJCF knows, in document order, given its active class's values
//! and left with explicit attributes only.

use super::classes::slot_index;
use super::layers::{Layers, RGB};
use super::{Resolver, Scratch};
use crate::document::Document;
use crate::document::names::Sym;
use crate::document::schema::Kind;
use crate::document::tree::{Node, StrRef};
use crate::document::vocab::DefaultSlot;
use crate::error::ErrorKind;

impl Resolver<'_> {
    /// Resolves one element (of kind `kind`); returns the class its children default to.
    fn resolve(&mut self, node: Node, kind: Kind, childclass: Option<usize>) -> Option<usize> {
        let mut active = childclass;
        if let Some(cc) = self.doc.attr_sym(node, self.syms.childclass) {
            match self.by_name.get(cc) {
                Some(&c) => active = Some(c),
                None => {
                    let e = self
                        .doc
                        .error_at(node, ErrorKind::UnknownClass(cc.to_string()));
                    self.errors.push(e);
                }
            }
            self.doc.remove_attr_sym(node, self.syms.childclass);
        }
        if let Some(slot) = kind.spec().default_slot {
            self.resolve_element(node, kind, slot, active);
        }
        active
    }

    /// Resolves the elements MJCF knows below `node` (of kind `kind`), in document order.
    /// Resolving changes attributes and tags only, never the tree. An explicit stack, not
    /// recursion: a deep body tree must not exhaust a worker thread's stack.
    pub(super) fn resolve_children(&mut self, node: Node, kind: Kind, childclass: Option<usize>) {
        let mut stack: Vec<(Node, Kind, Option<usize>)> = Vec::new();
        let push_kids = |doc: &Document, stack: &mut Vec<_>, node, kind: Kind, class| {
            let at = stack.len();
            for kid in doc.children(node) {
                if let Some(kkind) = doc.tag_sym(kid).and_then(|t| kind.child(t)) {
                    stack.push((kid, kkind, class));
                }
            }
            // Popped first to last.
            stack[at..].reverse();
        };
        push_kids(self.doc, &mut stack, node, kind, childclass);
        while let Some((node, kind, class)) = stack.pop() {
            let active = self.resolve(node, kind, class);
            push_kids(self.doc, &mut stack, node, kind, active);
        }
    }

    fn class_of(&mut self, node: Node, childclass: Option<usize>) -> Option<usize> {
        match self.doc.attr_sym(node, self.syms.class) {
            Some(name) => match self.by_name.get(name) {
                Some(&c) => Some(c),
                None => {
                    let e = self
                        .doc
                        .error_at(node, ErrorKind::UnknownClass(name.to_string()));
                    self.errors.push(e);
                    None
                }
            },
            None => Some(childclass.unwrap_or(0)),
        }
    }

    fn resolve_element(
        &mut self,
        node: Node,
        mut kind: Kind,
        slot: DefaultSlot,
        childclass: Option<usize>,
    ) {
        let Some(class) = self.class_of(node, childclass) else {
            return;
        };
        let material = slot == DefaultSlot::Material;
        if slot != DefaultSlot::Actuator
            && self.classes[class].slots[slot_index(slot).expect("non-actuator slot")]
                .0
                .is_empty()
            && (!material || self.classes[class].layers.is_empty())
        {
            // Nothing to inherit (the common case for classes that set few rows): what the
            // general path below makes is the element's own attributes in their order.
            if material {
                // Still refused as MuJoCo refuses it, as when a class is involved.
                let own = self.own_attrs(node);
                self.read_layers(node, &own, &mut Layers::default());
            }
            self.doc.remove_attr_sym(node, self.syms.class);
            return;
        }
        let mut own = std::mem::take(&mut self.scratch.own);
        self.own_attrs_into(node, &mut own);
        let mut merged = std::mem::take(&mut self.scratch.set);
        // A material's textures, when they must be written as `<layer>` children.
        let mut new_layers: Option<Layers> = None;
        if slot == DefaultSlot::Actuator {
            let dummy = self.classes[class].actuator.clone();
            match self.apply_actuator(&dummy, class, node, &own) {
                Ok((_, out_tag, attrs)) => {
                    if self.doc.tag_sym(node) != Some(out_tag) {
                        self.doc.set_tag(node, out_tag);
                        // Which attributes the element can carry is now the new tag's
                        // business (`general` carries what `adhesion` cannot).
                        if let Some(k) = self
                            .doc
                            .parent(node)
                            .and_then(|p| self.doc.tag_sym(p))
                            .and_then(|t| Kind::root().child(t))
                            .and_then(|section| section.child(out_tag))
                        {
                            kind = k;
                        }
                    }
                    merged.0 = attrs;
                }
                Err(e) => {
                    self.errors.push(e);
                    self.scratch.own = own;
                    self.scratch.set = merged;
                    return;
                }
            }
        } else {
            let i = slot_index(slot).expect("non-actuator slot");
            merged.0.clear();
            merged.0.extend_from_slice(&self.classes[class].slots[i].0);
            if slot == DefaultSlot::Texture {
                self.reset_gridlayout(&mut merged, &own);
            }
            self.apply(&mut merged, &own, Some(kind.spec()));
            if material {
                let mut layers = self.classes[class].layers;
                self.take_texture(&mut merged, &mut layers);
                let has_layers = self.read_layers(node, &own, &mut layers);
                if !has_layers && layers.only_rgb() {
                    // As written before layers existed: the `texture` attribute, in the
                    // element's own place when it wrote it.
                    if let Some(t) = layers.0[RGB] {
                        merged.set(self.syms.texture, t);
                    }
                } else {
                    new_layers = Some(layers);
                }
            }
        }
        // Own attributes keep their place; inherited ones follow in class order.
        let mut out = std::mem::take(&mut self.scratch.out);
        out.clear();
        let mut residual: Vec<(Sym, StrRef)> = Vec::new();
        for &(name, _) in &own {
            if let Some(v) = merged.get(name) {
                out.push(crate::document::tree::Attr { name, value: v });
            }
        }
        for &(name, value) in &merged.0 {
            if own.iter().any(|(n, _)| *n == name) {
                continue;
            }
            if kind.attr(name).is_none() {
                residual.push((name, value));
                continue;
            }
            out.push(crate::document::tree::Attr { name, value });
        }
        if !residual.is_empty() {
            let value = self.residual_class_name(slot, residual);
            out.push(crate::document::tree::Attr {
                name: self.syms.class,
                value,
            });
        }
        self.doc.replace_attrs(node, &out);
        if let Some(layers) = new_layers {
            self.write_layers(node, &layers);
        }
        self.scratch = Scratch {
            own,
            set: merged,
            out,
            text: std::mem::take(&mut self.scratch.text),
        };
    }
}
