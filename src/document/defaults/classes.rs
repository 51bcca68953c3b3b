//! The class tree: each `<default>` read into a class that starts as a copy of its parent and
//! applies its own rows, one dummy element per slot.

use super::Resolver;
use super::actuators::ActuatorSlot;
use super::layers::Layers;
use crate::document::names::Sym;
use crate::document::schema::Kind;
use crate::document::tree::{Node, StrRef};
use crate::document::vocab::DefaultSlot;
use crate::error::ErrorKind;

/// Default slots other than the actuator one, in a fixed order (index into class slots).
const SLOTS: [DefaultSlot; 11] = [
    DefaultSlot::Mesh,
    DefaultSlot::Texture,
    DefaultSlot::Material,
    DefaultSlot::Joint,
    DefaultSlot::Geom,
    DefaultSlot::Site,
    DefaultSlot::Camera,
    DefaultSlot::Light,
    DefaultSlot::Pair,
    DefaultSlot::Equality,
    DefaultSlot::Tendon,
];

pub(super) fn slot_index(slot: DefaultSlot) -> Option<usize> {
    SLOTS.iter().position(|s| *s == slot)
}

/// The slot a child of `<default>` writes, by its tag.
fn default_child_slot(default: Kind, tag: Sym) -> Option<DefaultSlot> {
    default.child(tag)?.spec().default_slot
}

/// An ordered attribute set: one class's dummy element.
#[derive(Clone, Debug, Default)]
pub(super) struct AttrSet(pub(super) Vec<(Sym, StrRef)>);

impl AttrSet {
    pub(super) fn get(&self, name: Sym) -> Option<StrRef> {
        self.0.iter().find(|(n, _)| *n == name).map(|(_, v)| *v)
    }

    pub(super) fn remove(&mut self, name: Sym) {
        self.0.retain(|(n, _)| *n != name);
    }

    pub(super) fn set(&mut self, name: Sym, value: StrRef) {
        match self.0.iter_mut().find(|(n, _)| *n == name) {
            Some(slot) => slot.1 = value,
            None => self.0.push((name, value)),
        }
    }
}

#[derive(Clone, Debug)]
pub(super) struct Class {
    pub(super) parent: Option<usize>,
    pub(super) slots: [AttrSet; SLOTS.len()],
    pub(super) actuator: ActuatorSlot,
    /// The textures of the class's material, by role. Its material slot never holds the
    /// `texture` attribute: that is the `rgb` role here.
    pub(super) layers: Layers,
}

impl Resolver<'_> {
    /// Reads one `<default>` element into class `class`: its own elements first, in order,
    /// then its nested classes (each a copy of this class as it is then), as MuJoCo does.
    /// Nested classes are read depth first from a stack of their own, not by recursion:
    /// nesting is bounded only by [`crate::Limits::max_depth`], and this may run on a
    /// worker thread with a small stack.
    pub(super) fn read_class(&mut self, section: Node, class: usize) {
        let nested = self.read_class_rows(section, class);
        let mut stack: Vec<(usize, std::vec::IntoIter<Node>)> = vec![(class, nested.into_iter())];
        while let Some((class, nested)) = stack.last_mut() {
            let class = *class;
            let Some(el) = nested.next() else {
                stack.pop();
                continue;
            };
            let Some(name) = self.doc.attr_sym(el, self.syms.class).map(str::to_string) else {
                let e = self.doc.error_at(
                    el,
                    ErrorKind::Invalid("nested <default> needs a 'class'".into()),
                );
                self.errors.push(e);
                continue;
            };
            if self.by_name.contains_key(&name) {
                let e = self.doc.error_at(el, ErrorKind::RepeatedClass(name));
                self.errors.push(e);
                continue;
            }
            let mut child = self.classes[class].clone();
            child.parent = Some(class);
            let index = self.classes.len();
            self.classes.push(child);
            self.by_name.insert(name, index);
            let nested = self.read_class_rows(el, index);
            stack.push((index, nested.into_iter()));
        }
    }

    /// Reads the elements of one `<default>` (not its nested classes) into class `class`;
    /// returns the nested `<default>` elements, in order.
    fn read_class_rows(&mut self, section: Node, class: usize) -> Vec<Node> {
        let mut kids: Vec<Node> = self.doc.elements(section).collect();
        for &el in &kids {
            if self.doc.tag_sym(el) == Some(self.syms.default) {
                continue;
            }
            let tag = self.doc.tag_sym(el).expect("element");
            match default_child_slot(self.default_kind, tag) {
                Some(DefaultSlot::Actuator) => {
                    let slot = self.classes[class].actuator.clone();
                    let own = self.own_attrs(el);
                    match self.apply_actuator(&slot, class, el, &own) {
                        Ok((next, _, _)) => self.classes[class].actuator = next,
                        Err(e) => self.errors.push(e),
                    }
                }
                Some(slot) => {
                    let i = slot_index(slot).expect("non-actuator slot");
                    let own = self.own_attrs(el);
                    let mut set = std::mem::take(&mut self.classes[class].slots[i]);
                    self.apply(&mut set, &own, None);
                    if slot == DefaultSlot::Material {
                        let mut layers = self.classes[class].layers;
                        self.take_texture(&mut set, &mut layers);
                        self.read_layers(el, &own, &mut layers);
                        self.classes[class].layers = layers;
                    }
                    self.classes[class].slots[i] = set;
                }
                None => {
                    let tag = self.doc.sym_name(tag);
                    let e = self.doc.error_at(
                        el,
                        ErrorKind::Invalid(format!("<{tag}> cannot appear in <default>")),
                    );
                    self.errors.push(e);
                }
            }
        }
        kids.retain(|&el| self.doc.tag_sym(el) == Some(self.syms.default));
        kids
    }

    /// The attributes an element writes itself (its `class` left out).
    pub(super) fn own_attrs(&self, node: Node) -> Vec<(Sym, StrRef)> {
        let mut own = Vec::new();
        self.own_attrs_into(node, &mut own);
        own
    }

    pub(super) fn own_attrs_into(&self, node: Node, own: &mut Vec<(Sym, StrRef)>) {
        own.clear();
        own.extend(
            self.doc
                .attr_slice(node)
                .iter()
                .filter(|a| a.name != self.syms.class && a.name != self.syms.childclass)
                .map(|a| (a.name, a.value)),
        );
    }
}
