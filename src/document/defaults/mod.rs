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
//!
//! [`inline_defaults`] is the entry point; [`Resolver`], its state, is kept here and
//! extended by one file per concept:
//! - [`classes`]: the class tree read from `<default>`, one dummy element per slot;
//! - [`precedence`]: how an element's own attributes apply over its class's dummy;
//! - [`resolve`]: every element of the model given its active class's values;
//! - [`actuators`]: the one actuator dummy per class, and the tag an actuator is written with;
//! - [`shortcuts`]: a shortcut's parameters as `<general>`'s control model, and back;
//! - [`layers`]: a material's textures, role by role;
//! - [`residuals`]: inherited values an element's kind has no attribute for.

mod actuators;
mod classes;
mod layers;
mod precedence;
mod residuals;
mod resolve;
mod shortcuts;

use ahash::AHashMap;

use crate::document::Document;
use crate::document::names::{Sym, sym};
use crate::document::schema::Kind;
use crate::document::tree::{Node, StrRef};
use crate::document::vocab::DefaultSlot;
use crate::error::{Error, ErrorKind, Errors};
use actuators::{ActuatorSlot, GENERAL_CONTROL};
use classes::{AttrSet, Class};
use layers::Layers;
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
