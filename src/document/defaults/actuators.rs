//! Actuators: the one dummy per class that every actuator element writes, whichever shortcut
//! it is, and the tag a resolved actuator is written with.

use super::Resolver;
use super::classes::AttrSet;
use crate::document::Document;
use crate::document::names::Sym;
use crate::document::schema::Kind;
use crate::document::tree::{Node, StrRef};
use crate::document::vocab;
use crate::error::Error;

/// Raw control-model attributes of `<general>`: a shortcut resets all of them.
pub(super) const GENERAL_CONTROL: [&str; 9] = [
    "dyntype",
    "gaintype",
    "biastype",
    "dynprm",
    "gainprm",
    "biasprm",
    "actdim",
    "input",
    "inheritrange",
];

/// What [`Resolver::apply_actuator`] makes: the class's new actuator dummy, the tag the
/// element is written with, and its attributes.
type AppliedActuator = (ActuatorSlot, Sym, Vec<(Sym, StrRef)>);

/// The shared actuator dummy of a class.
#[derive(Clone, Debug)]
pub(super) struct ActuatorSlot {
    /// The tag of the element that wrote the slot last (`general` for the built-in one).
    pub(super) writer: Sym,
    /// Mechanical attributes (ctrlrange, gear, forcerange, group, ...).
    pub(super) mech: AttrSet,
    /// For `general`: the raw control model as written (gainprm, biastype, ...), over the
    /// built-in one. For a shortcut: its parameters as written (kp, kv, ...), over the
    /// shortcut's documented defaults.
    pub(super) control: AttrSet,
}

/// Attributes a shortcut sets itself (its documented table), so what a class says of
/// them does not reach the compiled model.
fn forced_by_shortcut(tag: &str) -> &'static [&'static str] {
    match tag {
        "damper" | "adhesion" => &["ctrllimited"],
        _ => &[],
    }
}

impl Resolver<'_> {
    /// Applies an actuator element (in a class, or a real one) onto the class dummy `slot`;
    /// returns the new dummy and the attributes that reproduce the element without classes.
    pub(super) fn apply_actuator(
        &mut self,
        slot: &ActuatorSlot,
        class: usize,
        node: Node,
        own: &[(Sym, StrRef)],
    ) -> Result<AppliedActuator, Error> {
        let tag = self.doc.tag_sym(node).expect("element");
        let tag_name = self.doc.sym_name(tag).to_string();
        let is_general = tag == self.syms.general || tag_name == "plugin";
        let params: Vec<Sym> = vocab::shortcut_params(&tag_name)
            .iter()
            .filter_map(|p| crate::document::names::known(p))
            .collect();
        let (spec, _) = self.actuator_kinds(tag);
        let is_control = |n: Sym| {
            if is_general {
                self.syms.control.contains(&n)
            } else {
                params.contains(&n)
            }
        };
        // Transmission and other per-element attributes never enter a class dummy.
        let name_attr = self.syms.name;
        let defaultable = |_: &Document, n: Sym| {
            spec.and_then(|s| s.attr(n)).is_some_and(|a| !a.nodefault) && n != name_attr
        };
        let mut mech_own: Vec<(Sym, StrRef)> = Vec::new();
        let mut control_own: Vec<(Sym, StrRef)> = Vec::new();
        let mut other_own: Vec<(Sym, StrRef)> = Vec::new();
        for &(n, v) in own {
            if is_control(n) {
                control_own.push((n, v));
            } else if defaultable(self.doc, n) {
                mech_own.push((n, v));
            } else {
                other_own.push((n, v));
            }
        }
        let mut mech = slot.mech.clone();
        self.apply(&mut mech, &mech_own, None);

        let control = if is_general {
            let mut control = if slot.writer == self.syms.general {
                slot.control.clone()
            } else {
                let writer = self.doc.sym_name(slot.writer).to_string();
                self.shortcut_table(&writer, &slot.control, node)?
            };
            let inherited_gain = self.gaintype(&control);
            if let Some(&(_, g)) = control_own.iter().find(|(n, _)| *n == self.syms.gaintype)
                && self.doc.str(g) != inherited_gain
            {
                control.remove(self.syms.input);
            }
            self.apply(&mut control, &control_own, None);
            control
        } else {
            let mut s = match self.shortcut_source(slot, class, &tag_name) {
                None => AttrSet::default(),
                // The built-in slot reads as the shortcut's documented defaults.
                Some(src) if src.control.0.is_empty() => AttrSet::default(),
                Some(src) if src.writer == tag => src.control.clone(),
                Some(src) => self.params_from_general(&src.control, &tag_name, node)?,
            };
            let damping_given = control_own
                .iter()
                .any(|(n, _)| *n == self.syms.kv || *n == self.syms.dampratio);
            if damping_given {
                s.remove(self.syms.kv);
                s.remove(self.syms.dampratio);
            }
            self.apply(&mut s, &control_own, None);
            s
        };

        let next = ActuatorSlot {
            writer: if is_general { self.syms.general } else { tag },
            mech,
            control,
        };
        let out_tag = if is_general {
            tag
        } else {
            self.output_tag(&next, spec)
        };
        let control_out = if out_tag == tag {
            next.control.clone()
        } else {
            self.shortcut_table(&tag_name, &next.control, node)?
        };
        let (_, out_spec) = self.actuator_kinds(out_tag);
        let forced = forced_by_shortcut(&tag_name);
        let mut attrs: Vec<(Sym, StrRef)> = Vec::new();
        for &(n, v) in &other_own {
            attrs.push((n, v));
        }
        // A name in both (a shortcut's table sets `ctrllimited`, which a class default may
        // also hold among the mechanical rows) is written once, with the table's value: an
        // attribute written twice makes the output unreadable.
        let mech_only = next
            .mech
            .0
            .iter()
            .filter(|(n, _)| !control_out.0.iter().any(|(m, _)| m == n));
        for &(n, v) in mech_only.chain(control_out.0.iter()) {
            let name = self.doc.sym_name(n);
            if out_tag == tag && forced.contains(&name) {
                continue;
            }
            if out_spec.is_some_and(|s| s.attr(n).is_none()) && out_tag == tag && !is_general {
                continue;
            }
            attrs.push((n, v));
        }
        self.drop_overridden_range(&tag_name, own, &mut attrs);
        // Keep the element's own attribute order first, inherited ones after.
        let position = |n: Sym| own.iter().position(|(m, _)| *m == n).unwrap_or(usize::MAX);
        attrs.sort_by_key(|(n, _)| position(*n));
        Ok((next, out_tag, attrs))
    }

    /// A shortcut's explicit range (`ctrlrange`, `actrange` for `intvelocity`, `posrange`
    /// for `pid`) or `inheritrange` overrides the other one inherited from its class: the
    /// inherited one is dropped from `attrs`. This is MuJoCo 4.0.0's rule (changelog 4.0.0,
    /// bug fix 60; corpora/features/actuator_range_overrides_inheritrange.xml). MuJoCo 3.17.0
    /// rejects such an element (`ctrlrange and inheritrange cannot both be defined`), so no
    /// model that 3.17.0 compiles is changed by it; without it, what we write would be
    /// rejected by 4.0.0 too, although 4.0.0 compiles the input.
    fn drop_overridden_range(
        &self,
        tag: &str,
        own: &[(Sym, StrRef)],
        attrs: &mut Vec<(Sym, StrRef)>,
    ) {
        let ranges: &[&str] = match tag {
            "position" => &["ctrlrange"],
            "intvelocity" => &["actrange"],
            "pid" => &["ctrlrange", "posrange"],
            _ => return,
        };
        let Some(inheritrange) = crate::document::names::known("inheritrange") else {
            return;
        };
        let ranges: Vec<Sym> = ranges
            .iter()
            .filter_map(|r| crate::document::names::known(r))
            .collect();
        let is_own = |n: Sym| own.iter().any(|(m, _)| *m == n);
        if ranges.iter().any(|r| is_own(*r)) && !is_own(inheritrange) {
            attrs.retain(|(n, _)| *n != inheritrange);
        } else if is_own(inheritrange) && !ranges.iter().any(|r| is_own(*r)) {
            attrs.retain(|(n, _)| !ranges.contains(n));
        }
    }

    /// For an actuator tag: the kind its attributes are read as (the vocabulary's element of
    /// that name, else the `<actuator>` child of that tag) and its kind as an `<actuator>`
    /// child.
    fn actuator_kinds(&mut self, tag: Sym) -> (Option<Kind>, Option<Kind>) {
        if let Some(&(_, spec, child)) = self.actuator_kinds.iter().find(|(t, _, _)| *t == tag) {
            return (spec, child);
        }
        let kinds = if crate::document::names::is_vocabulary(tag) {
            let actuator = Kind::named(self.syms.actuator).expect("actuator kind");
            let child = actuator.child(tag);
            (Kind::named(tag).or(child), child)
        } else {
            // A name outside the vocabulary can still be a schema name (`default_geom`).
            let name = self.doc.sym_name(tag);
            let child = vocab::child(vocab::element("actuator").expect("actuator kind"), name);
            let spec = vocab::element(name).or(child);
            (spec.map(Kind::of), child.map(Kind::of))
        };
        self.actuator_kinds.push((tag, kinds.0, kinds.1));
        kinds
    }

    /// The tag an actuator is written with: its own shortcut when that shortcut can carry
    /// every attribute it inherits (or sets those itself), else `general` with the
    /// shortcut's table spelled out.
    fn output_tag(&self, slot: &ActuatorSlot, spec: Option<Kind>) -> Sym {
        let Some(spec) = spec else { return slot.writer };
        let forced = forced_by_shortcut(spec.spec().tag);
        let carries = slot
            .mech
            .0
            .iter()
            .all(|(n, _)| spec.attr(*n).is_some() || forced.contains(&self.doc.sym_name(*n)));
        if carries {
            slot.writer
        } else {
            self.syms.general
        }
    }

    fn gaintype(&self, control: &AttrSet) -> String {
        control
            .get(self.syms.gaintype)
            .map(|v| self.doc.str(v).trim().to_string())
            .unwrap_or_else(|| "fixed".to_string())
    }

    /// The slot a shortcut pre-reads: this class's dummy if written with the same shortcut
    /// or with `general` of the shortcut's gain type, else the nearest such ancestor.
    fn shortcut_source(
        &self,
        slot: &ActuatorSlot,
        class: usize,
        tag: &str,
    ) -> Option<ActuatorSlot> {
        let inherits = |s: &ActuatorSlot| {
            let writer = self.doc.sym_name(s.writer);
            if writer == tag {
                return true;
            }
            if s.writer != self.syms.general {
                return false;
            }
            let want = match tag {
                "damper" => "affine",
                "muscle" => "muscle",
                "dcmotor" => "dcmotor",
                "pid" => "pid",
                "orientation" => "so3",
                _ => "fixed",
            };
            self.gaintype(&s.control) == want
        };
        if inherits(slot) {
            return Some(slot.clone());
        }
        let mut c = self.classes[class].parent;
        while let Some(i) = c {
            if inherits(&self.classes[i].actuator) {
                return Some(self.classes[i].actuator.clone());
            }
            c = self.classes[i].parent;
        }
        None
    }
}
