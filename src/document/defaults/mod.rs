//! Default classes resolved into explicit attributes, with MuJoCo's rules.
//!
//! MuJoCo keeps one complete set of "dummy" elements per class. A class starts as a copy of
//! its parent (taken after the parent's own elements are read, before any nested class),
//! then its elements are applied in order. A real element starts from its class's dummy and
//! applies its own attributes. Applying means: an attribute replaces the dummy's value,
//! except that a fixed-capacity numeric array given with fewer numbers overwrites only its
//! first entries (`friction="0.7"` over `"1 0.1 0.01"` is `0.7 0.1 0.01`), and any one
//! orientation attribute replaces the whole orientation of the dummy.
//!
//! Actuators share ONE dummy per class whatever shortcut wrote it; that is modelled in
//! [`ActuatorSlot`]. Each class's slot remembers which element wrote it last, because a
//! shortcut pre-reads its parameters (kp, kv, ...) only from a slot written with the same
//! shortcut or with `general` of the matching gain type (looking up the class chain), while
//! mechanical attributes (ctrlrange, gear, ...) are inherited from any slot.
//!
//! The active class of an element: its own `class`, else the `childclass` of the nearest
//! ancestor (body, frame, replicate) that has one, else the top-level class `main`.
//!
//! One kind of default row has children: a class's `<material>` may hold `<layer role=...
//! texture=...>` elements (the only such row in MuJoCo 3.17.0's and 4.0.0's schema), and a
//! material of that class inherits them. MuJoCo keeps a material's textures as one name per
//! role, so they are inherited role by role; see [`Layers`].

mod actuators;
mod classes;
mod layers;
mod precedence;
mod residuals;
mod shortcuts;

use ahash::AHashMap;

use crate::document::Document;
use crate::document::names::{Sym, sym};
use crate::document::schema::Kind;
use crate::document::tree::{Node, StrRef};
use crate::document::vocab::DefaultSlot;
use crate::error::{Error, ErrorKind, Errors};
use actuators::{ActuatorSlot, GENERAL_CONTROL};
use classes::{AttrSet, Class, slot_index};
use layers::{Layers, RGB};
use precedence::{LIGHT_TYPE, ORIENTATION};

/// Frequently used names, interned once.
struct Syms {
    class: Sym,
    childclass: Sym,
    default: Sym,
    general: Sym,
    gaintype: Sym,
    input: Sym,
    kv: Sym,
    dampratio: Sym,
    user: Sym,
    name: Sym,
    actuator: Sym,
    texture: Sym,
    layer: Sym,
    role: Sym,
    orientation: [Sym; 5],
    light_type: [Sym; 2],
    control: [Sym; 9],
}

impl Syms {
    fn new() -> Syms {
        Syms {
            class: sym("class"),
            childclass: sym("childclass"),
            default: sym("default"),
            general: sym("general"),
            gaintype: sym("gaintype"),
            input: sym("input"),
            kv: sym("kv"),
            dampratio: sym("dampratio"),
            user: sym("user"),
            name: sym("name"),
            actuator: sym("actuator"),
            texture: sym("texture"),
            layer: sym("layer"),
            role: sym("role"),
            orientation: ORIENTATION.map(sym),
            light_type: LIGHT_TYPE.map(sym),
            control: GENERAL_CONTROL.map(sym),
        }
    }
}

struct Resolver<'a> {
    doc: &'a mut Document,
    syms: &'static Syms,
    classes: Vec<Class>,
    by_name: AHashMap<String, usize>,
    errors: Vec<Error>,
    /// Values an element inherits but MJCF gives its kind no attribute for (a `<fixed>`
    /// tendon's rgba, width and material): kept in residual classes, one per distinct set.
    residuals: Vec<(DefaultSlot, Vec<(Sym, StrRef)>)>,
    /// The kind of `<default>` (its children are the rows of each slot).
    default_kind: Kind,
    /// Per actuator tag met: the kind its class rows are read as, and its kind as a child
    /// of `<actuator>` (found by name in the vocabulary once, not per element).
    actuator_kinds: Vec<(Sym, Option<Kind>, Option<Kind>)>,
    /// Buffers reused across elements, so resolving allocates nothing per element.
    scratch: Scratch,
}

#[derive(Default)]
struct Scratch {
    own: Vec<(Sym, StrRef)>,
    set: AttrSet,
    out: Vec<crate::document::tree::Attr>,
    text: String,
}

/// Resolves every default class into explicit attributes and removes `<default>`, `class`
/// and `childclass`. All problems are reported at once.
pub(crate) fn inline_defaults(doc: &mut Document) -> Result<(), Errors> {
    // Vocabulary ids are the same in every document: interned once per process.
    static SYMS: std::sync::OnceLock<Syms> = std::sync::OnceLock::new();
    let syms = SYMS.get_or_init(Syms::new);
    let syms_default = syms.default;
    let main = Class {
        parent: None,
        slots: Default::default(),
        actuator: ActuatorSlot {
            writer: syms.general,
            mech: AttrSet::default(),
            control: AttrSet::default(),
        },
        layers: Layers::default(),
    };
    let mut r = Resolver {
        doc,
        syms,
        classes: vec![main],
        by_name: AHashMap::from_iter([("main".to_string(), 0)]),
        errors: Vec::new(),
        residuals: Vec::new(),
        default_kind: Kind::root().child(syms_default).expect("<default> kind"),
        actuator_kinds: Vec::new(),
        scratch: Scratch::default(),
    };
    let root = r.doc.root;
    let sections: Vec<Node> = r
        .doc
        .elements(root)
        .filter(|&n| r.doc.tag_sym(n) == Some(r.syms.default))
        .collect();
    for &section in &sections {
        if let Some(name) = r.doc.attr_sym(section, r.syms.class)
            && name != "main"
        {
            let e = r
                .doc
                .error_at(section, ErrorKind::RenamedMainClass(name.to_string()));
            r.errors.push(e);
        }
        r.read_class(section, 0);
    }
    for &section in &sections {
        r.doc.remove(section);
    }
    r.resolve_children(root, Kind::root(), None);
    if !r.errors.is_empty() {
        return Err(Errors(r.errors));
    }
    r.write_residuals();
    Ok(())
}

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
    fn resolve_children(&mut self, node: Node, kind: Kind, childclass: Option<usize>) {
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
