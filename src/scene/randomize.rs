//! Attribute randomizers: which elements (kind, name pattern, part), which attribute, and
//! how its value is drawn (uniform, log-uniform, bounded normal, weighted choice), absolute
//! or as a scale of the current value, per component.
//!
//! Two rules keep a randomized model consistent:
//! - a body's mass lives on its `<inertial>`; changing it scales the inertia by the same
//!   factor, so the body keeps its shape of inertia; a mass MuJoCo infers from the body's
//!   geoms is scaled on the geoms (each one's `density`, or `mass` where written, times one
//!   factor per body: MuJoCo's mass properties are linear in them);
//! - angles given with a `unit` are converted into the units of the model the element
//!   belongs to (`<compiler angle>`), before that model is merged into the scene.

use std::sync::Arc;

use crate::document::Document;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind, Errors, Location};

use super::Target;
use super::params::{Params, RandomizedValue};
use super::place::join;
use super::rng::Rng;

/// A compiled randomizer.
#[derive(Debug)]
pub(crate) struct Randomizer {
    pub(crate) kind: String,
    pub(crate) attribute: String,
    /// Glob over names as written in the model file (without the instance prefix).
    pub(crate) name: Option<String>,
    /// Restricts to one part (`base`, a fixture's prefix, a group's name).
    pub(crate) part: Option<String>,
    pub(crate) dist: Dist,
    pub(crate) scale: bool,
    /// Factor from the given unit to radians (`unit = "deg"` or `"rad"`).
    pub(crate) unit_to_rad: Option<f64>,
    /// The components set; `None`: see [`Randomizer::components`].
    pub(crate) components: Option<Vec<usize>>,
    pub(crate) shared: bool,
    /// The randomizer's table in the scene file.
    pub(crate) location: Location,
    /// The randomizer's index (its random stream).
    pub(crate) index: usize,
    /// The attribute names a file (choices are absolute paths).
    pub(crate) file: bool,
}

/// How values are drawn. Numeric bounds hold one value per drawn component (a single value
/// is used for every component).
#[derive(Debug)]
pub(crate) enum Dist {
    Uniform {
        lo: Vec<f64>,
        hi: Vec<f64>,
    },
    LogUniform {
        lo: Vec<f64>,
        hi: Vec<f64>,
    },
    Normal {
        mean: Vec<f64>,
        std: Vec<f64>,
        min: Vec<f64>,
        max: Vec<f64>,
    },
    Choice {
        values: Vec<String>,
        weights: Vec<f64>,
        /// Values name an object of the model: they get the element's instance prefix.
        prefixed: bool,
    },
}

/// MuJoCo's value of an attribute an element does not write (checked against `mjSpec`'s
/// defaults by `tests/scene_batch.rs`), for scaling or keeping components of a value
/// that is not written: `(element, attribute, value)`.
pub const MUJOCO_DEFAULTS: &[(&str, &str, &str)] = &[
    ("geom", "friction", "1 0.005 0.0001"),
    ("geom", "rgba", "0.5 0.5 0.5 1"),
    ("geom", "solref", "0.02 1"),
    ("geom", "solimp", "0.9 0.95 0.001 0.5 2"),
    ("geom", "density", "1000"),
    ("geom", "margin", "0"),
    ("geom", "gap", "0"),
    ("joint", "damping", "0"),
    ("joint", "stiffness", "0"),
    ("joint", "armature", "0"),
    ("joint", "frictionloss", "0"),
    ("joint", "ref", "0"),
    ("joint", "springref", "0"),
    ("site", "rgba", "0.5 0.5 0.5 1"),
    ("camera", "fovy", "45"),
    ("camera", "pos", "0 0 0"),
    ("light", "diffuse", "0.7 0.7 0.7"),
    ("light", "specular", "0.3 0.3 0.3"),
    ("light", "ambient", "0 0 0"),
    ("light", "pos", "0 0 0"),
    ("light", "dir", "0 0 -1"),
    ("light", "attenuation", "1 0 0"),
    ("light", "cutoff", "45"),
    ("light", "exponent", "10"),
    ("material", "rgba", "1 1 1 1"),
    ("material", "specular", "0.5"),
    ("material", "shininess", "0.5"),
    ("material", "reflectance", "0"),
    ("material", "emission", "0"),
    ("body", "pos", "0 0 0"),
    ("geom", "pos", "0 0 0"),
    ("site", "pos", "0 0 0"),
];

pub(crate) fn mujoco_default(kind: &str, attribute: &str) -> Option<&'static str> {
    MUJOCO_DEFAULTS
        .iter()
        .find(|(k, a, _)| *k == kind && *a == attribute)
        .map(|(_, _, v)| *v)
}

/// Which components of an attribute are angles in `<compiler angle>` units, if any.
pub(crate) fn angle_components(kind: &str, attribute: &str) -> Option<&'static [usize]> {
    match (kind, attribute) {
        (_, "euler") => Some(&[0, 1, 2]),
        (_, "axisangle") => Some(&[3]),
        ("joint", "range" | "ref" | "springref") => Some(&[0, 1]),
        _ => None,
    }
}

/// Where a variant's values go: straight into a document, or into an [`Overlay`] of
/// values over a document that stays as it is (the holes of pre-rendered text).
pub(crate) trait AttrTarget {
    /// The attribute's current value (as set in this variant, else as in the document).
    fn get(&self, node: Node, attr: &str) -> Option<&str>;
    /// Sets the attribute.
    fn set(&mut self, node: Node, attr: &str, value: String);
    /// The document the nodes belong to (for messages and element facts).
    fn doc(&self) -> &Document;
}

impl AttrTarget for Document {
    fn get(&self, node: Node, attr: &str) -> Option<&str> {
        self.attr(node, attr)
    }
    fn set(&mut self, node: Node, attr: &str, value: String) {
        self.set_attr(node, attr, &value);
    }
    fn doc(&self) -> &Document {
        self
    }
}

/// Values set over a document that is not changed: `(node, attribute, value)` in the order
/// set (a later value of the same attribute wins).
pub(crate) struct Overlay<'a> {
    pub(crate) doc: &'a Document,
    pub(crate) values: Vec<(Node, String, String)>,
}

impl<'a> Overlay<'a> {
    pub(crate) fn new(doc: &'a Document) -> Overlay<'a> {
        Overlay {
            doc,
            values: Vec::new(),
        }
    }

    /// Sets every value on `doc` (a copy of the overlaid document), in order.
    pub(crate) fn apply_to(&self, doc: &mut Document) {
        for (node, attr, value) in &self.values {
            doc.set_attr(*node, attr, value);
        }
    }
}

impl AttrTarget for Overlay<'_> {
    fn get(&self, node: Node, attr: &str) -> Option<&str> {
        self.values
            .iter()
            .rev()
            .find(|(n, a, _)| *n == node && a == attr)
            .map(|(_, _, v)| v.as_str())
            .or_else(|| self.doc.attr(node, attr))
    }
    fn set(&mut self, node: Node, attr: &str, value: String) {
        self.values.push((node, attr.to_string(), value));
    }
    fn doc(&self) -> &Document {
        self.doc
    }
}

/// The random state of one variant: one stream per randomizer, made on first use, and
/// the draw of each shared randomizer.
pub(crate) struct Draws {
    seed: u64,
    index: u64,
    rngs: Vec<Option<Rng>>,
    shared: Vec<Option<Drawn>>,
}

#[derive(Clone, Debug)]
enum Drawn {
    Numbers(Vec<f64>),
    Choice(usize),
}

impl Draws {
    pub(crate) fn new(seed: u64, index: u64, randomizers: usize) -> Draws {
        Draws {
            seed,
            index,
            rngs: vec![None; randomizers],
            shared: vec![None; randomizers],
        }
    }

    fn rng(&mut self, k: usize) -> &mut Rng {
        let (seed, index) = (self.seed, self.index);
        // Stream 0 is placement; randomizer k draws from stream k + 1.
        self.rngs[k].get_or_insert_with(|| Rng::new(seed, index, k as u64 + 1))
    }
}

impl Randomizer {
    /// File choices rewritten to the store's relocatable names.
    pub(crate) fn relocate_files(
        &mut self,
        store: &crate::output::AssetStore,
    ) -> Result<(), Errors> {
        if let Dist::Choice {
            values,
            prefixed: false,
            ..
        } = &mut self.dist
            && self.file
        {
            for v in values.iter_mut() {
                *v = store.relocate_file(std::path::Path::new(v.as_str()))?;
            }
        }
        Ok(())
    }

    /// Whether this randomizer can select elements of `part`.
    pub(crate) fn applies_to_part(&self, part: &str) -> bool {
        self.part.as_deref().is_none_or(|p| p == part)
    }

    /// The elements of `doc` this randomizer sets: tag `kind`, name (without `prefix`)
    /// matching the pattern. For a body's `mass`, the body's `<inertial>`. Errors: a
    /// selected element lacks what the randomizer needs.
    pub(crate) fn select(
        &self,
        doc: &Document,
        nodes: impl Iterator<Item = Node>,
        prefix: &str,
        part: &Arc<str>,
    ) -> Result<Vec<Target>, Errors> {
        let mut out = Vec::new();
        let mut errors = Vec::new();
        // Bodies selected for their mass that have none (neither geoms nor <inertial>).
        let mut massless = Vec::new();
        // A geom's density does nothing where it has a mass, its own or its class's: the
        // document with its classes inlined (same nodes) tells, made once when needed.
        let mut inlined: Option<Option<Document>> = None;
        for node in nodes {
            if doc.tag(node) != self.kind {
                continue;
            }
            let name = doc.attr(node, "name");
            if let Some(pattern) = &self.name {
                let raw = name.map(|n| n.strip_prefix(prefix).unwrap_or(n));
                if !raw.is_some_and(|r| glob(pattern, r)) {
                    continue;
                }
            }
            if self.kind == "body" && self.attribute == "mass" && mass_from_geoms(doc, node) {
                // MuJoCo's mass properties are linear in each geom's density (or mass), so
                // scaling all of them scales the body's mass and inertia by that factor and
                // keeps its centre of mass and principal axes.
                if !self.scale || self.components.is_some() {
                    errors.push(doc.error_at(
                        node,
                        ErrorKind::Invalid(format!(
                            "randomizer at {}: body {} has no <inertial>: its mass comes from its geoms, so it can only be scaled (add `scale = true`, without `components`), or give the body an <inertial> (on an object group, leave `write_inertials` unset or set it true, and MuJoCo's own is written)",
                            self.location,
                            quoted(name)
                        )),
                    ));
                    continue;
                }
                // A body with neither <inertial> nor geoms weighs nothing: nothing to scale
                // (robosuite's and LIBERO's objects hold their geoms in an inner body,
                // which a pattern selects with it); an error below when nothing selected
                // has a mass.
                let geoms = doc.children_through_frames(node, "geom");
                if geoms.is_empty() {
                    massless.push(node);
                }
                for g in geoms {
                    out.push(Target {
                        node: g,
                        name: doc.attr(g, "name").map(str::to_string),
                        part: part.clone(),
                        prefix: Arc::from(prefix),
                        mass_of: Some(node),
                    });
                }
                continue;
            }
            if self.kind == "geom" && self.attribute == "density" {
                let resolved = inlined.get_or_insert_with(|| {
                    let mut copy = doc.clone();
                    crate::document::defaults::inline_defaults(&mut copy)
                        .ok()
                        .map(|()| copy)
                });
                let has_mass = match resolved {
                    Some(r) => r.attr(node, "mass").is_some(),
                    None => doc.attr(node, "mass").is_some(),
                };
                if has_mass {
                    errors.push(doc.error_at(
                        node,
                        ErrorKind::Invalid(format!(
                            "randomizer at {}: {} has a mass, which MuJoCo takes over its density: randomize its `mass` instead",
                            self.location,
                            element_label(doc, node)
                        )),
                    ));
                    continue;
                }
            }
            let target = if self.kind == "body" && self.attribute == "mass" {
                match doc.elements(node).find(|&k| doc.tag(k) == "inertial") {
                    Some(inertial) => inertial,
                    None => {
                        errors.push(doc.error_at(
                            node,
                            ErrorKind::Invalid(format!(
                                "randomizer at {}: body {} has no <inertial> and its compiler infers no mass from geoms (inertiafromgeom=\"false\"): it has no mass to randomize",
                                self.location,
                                quoted(name)
                            )),
                        ));
                        continue;
                    }
                }
            } else {
                node
            };
            if let Err(e) = self.check_target(doc, target) {
                errors.push(e);
                continue;
            }
            out.push(Target {
                node: target,
                name: name.map(str::to_string),
                part: part.clone(),
                prefix: Arc::from(prefix),
                mass_of: None,
            });
        }
        if let Some(&body) = massless.first()
            && out.is_empty()
            && errors.is_empty()
        {
            errors.push(doc.error_at(
                body,
                ErrorKind::Invalid(format!(
                    "randomizer at {}: body {} has neither geoms nor an <inertial>: it has no mass to randomize",
                    self.location,
                    quoted(doc.attr(body, "name"))
                )),
            ));
        }
        if errors.is_empty() {
            Ok(out)
        } else {
            Err(Errors(errors))
        }
    }

    /// The value attribute on the element that holds it (the body's `<inertial>` for mass).
    fn attr_tag(&self) -> &str {
        if self.kind == "body" && self.attribute == "mass" {
            "inertial"
        } else {
            &self.kind
        }
    }

    /// Checks that every value this randomizer needs from `node` is there.
    fn check_target(&self, doc: &Document, node: Node) -> Result<(), Error> {
        let needs_current = self.scale
            || self
                .components
                .as_ref()
                .is_some_and(|c| c.iter().any(|&i| i > 0));
        if matches!(self.dist, Dist::Choice { .. }) || !needs_current {
            return Ok(());
        }
        if doc.attr(node, &self.attribute).is_some()
            || mujoco_default(self.attr_tag(), &self.attribute).is_some()
        {
            return Ok(());
        }
        Err(doc.error_at(
            node,
            ErrorKind::Invalid(format!(
                "randomizer at {}: {} has no '{}' to {} (write it in the model, or set it absolutely)",
                self.location,
                element_label(doc, node),
                self.attribute,
                if self.scale { "scale" } else { "keep components of" }
            )),
        ))
    }

    /// Sets the attribute on every target, recording each value.
    pub(crate) fn apply(
        &self,
        out: &mut impl AttrTarget,
        targets: &[Target],
        draws: &mut Draws,
        params: &mut Params,
    ) -> Result<(), Errors> {
        // The factor drawn for the body whose geoms carry its mass (one draw per body).
        let mut body_factor: Option<(Node, f64)> = None;
        for t in targets {
            if let Some(body) = t.mass_of {
                let factor = match body_factor {
                    Some((b, f)) if b == body => f,
                    _ => match self.draw(draws) {
                        Drawn::Numbers(x) => x[0],
                        Drawn::Choice(_) => unreachable!("a body's mass from geoms is scaled"),
                    },
                };
                body_factor = Some((body, factor));
                let attr = geom_mass_attribute(out.doc(), t.node);
                let current = out
                    .get(t.node, attr)
                    .or_else(|| mujoco_default("geom", attr))
                    .and_then(|v| v.trim().parse::<f64>().ok())
                    .unwrap_or(0.0);
                let value = join(&[current * factor]);
                params.randomized.push(RandomizedValue {
                    kind: "geom".to_string(),
                    name: t.name.clone(),
                    part: t.part.to_string(),
                    attribute: attr.to_string(),
                    value: value.clone(),
                });
                out.set(t.node, attr, value);
                continue;
            }
            let drawn = self.draw(draws);
            let value = match drawn {
                Drawn::Choice(i) => {
                    let Dist::Choice {
                        values, prefixed, ..
                    } = &self.dist
                    else {
                        unreachable!("a choice is drawn only from a choice")
                    };
                    if *prefixed {
                        format!("{}{}", t.prefix, values[i])
                    } else {
                        values[i].clone()
                    }
                }
                Drawn::Numbers(x) => self.numbers(out, t.node, &x)?,
            };
            if self.kind == "body" && self.attribute == "mass" {
                scale_inertia(out, t.node, &value, &self.location)?;
            }
            params.randomized.push(RandomizedValue {
                kind: self.kind.clone(),
                name: t.name.clone(),
                part: t.part.to_string(),
                attribute: self.attribute.clone(),
                value: value.clone(),
            });
            out.set(t.node, &self.attribute, value);
        }
        Ok(())
    }

    /// The attributes this randomizer sets on `node`, in the order it sets them.
    pub(crate) fn attributes_set(&self, doc: &Document, node: Node) -> Vec<&str> {
        let mut out = Vec::new();
        if self.kind == "body" && self.attribute == "mass" && doc.tag(node) == "geom" {
            return vec![geom_mass_attribute(doc, node)];
        }
        if self.kind == "body" && self.attribute == "mass" {
            for a in ["diaginertia", "fullinertia"] {
                if doc.attr(node, a).is_some() {
                    out.push(a);
                }
            }
        }
        out.push(self.attribute.as_str());
        out
    }

    fn draw(&self, draws: &mut Draws) -> Drawn {
        if self.shared
            && let Some(d) = &draws.shared[self.index]
        {
            return d.clone();
        }
        let rng = draws.rng(self.index);
        let d = match &self.dist {
            Dist::Uniform { lo, hi } => Drawn::Numbers(
                (0..lo.len().max(hi.len()))
                    .map(|i| rng.uniform(at(lo, i), at(hi, i)))
                    .collect(),
            ),
            Dist::LogUniform { lo, hi } => Drawn::Numbers(
                (0..lo.len().max(hi.len()))
                    .map(|i| rng.uniform(at(lo, i).ln(), at(hi, i).ln()).exp())
                    .collect(),
            ),
            Dist::Normal {
                mean,
                std,
                min,
                max,
            } => {
                let n = [mean.len(), std.len(), min.len(), max.len()]
                    .into_iter()
                    .max()
                    .unwrap_or(1);
                Drawn::Numbers(
                    (0..n)
                        .map(|i| {
                            let (lo, hi) = (at(min, i), at(max, i));
                            // Redraw until inside; after many misses (a bound far in the
                            // tail) fall back to uniform in the bounds so a draw always ends.
                            for _ in 0..1000 {
                                let x = at(mean, i) + at(std, i) * rng.normal();
                                if (lo..=hi).contains(&x) {
                                    return x;
                                }
                            }
                            rng.uniform(lo, hi)
                        })
                        .collect(),
                )
            }
            Dist::Choice { weights, .. } => Drawn::Choice(rng.weighted(weights)),
        };
        if self.shared {
            draws.shared[self.index] = Some(d.clone());
        }
        d
    }

    /// The new text of the attribute of `node` from the drawn numbers.
    fn numbers(&self, out: &impl AttrTarget, node: Node, drawn: &[f64]) -> Result<String, Errors> {
        let doc = out.doc();
        let current_text = out
            .get(node, &self.attribute)
            .or_else(|| mujoco_default(self.attr_tag(), &self.attribute));
        let mut current: Vec<f64> = match current_text {
            Some(t) => parse_numbers(t).ok_or_else(|| {
                doc.error_at(
                    node,
                    ErrorKind::Invalid(format!(
                        "randomizer at {}: '{}' of {} is not a list of numbers: '{}'",
                        self.location,
                        self.attribute,
                        element_label(doc, node),
                        t
                    )),
                )
            })?,
            None => Vec::new(),
        };
        let components: Vec<usize> = match &self.components {
            Some(c) => c.clone(),
            None if self.scale && drawn.len() == 1 => (0..current.len().max(1)).collect(),
            None => (0..drawn.len()).collect(),
        };
        let angle = self
            .unit_to_rad
            .map(|to_rad| (to_rad, angle_components(&self.kind, &self.attribute)));
        let degrees = doc_uses_degrees(doc);
        for (j, &c) in components.iter().enumerate() {
            let mut x = drawn[j.min(drawn.len() - 1)];
            if let Some((to_rad, Some(angles))) = angle
                && angles.contains(&c)
            {
                x *= to_rad;
                if degrees {
                    x = x.to_degrees();
                }
            }
            if current.len() <= c {
                current.resize(c + 1, 0.0);
            }
            current[c] = if self.scale { current[c] * x } else { x };
        }
        Ok(join(&current))
    }
}

/// Whether MuJoCo infers `body`'s mass and inertia from its geoms: it has no `<inertial>`
/// (under `inertiafromgeom` "auto", MuJoCo's default, or "true"), or the compiler's
/// `inertiafromgeom="true"` overrides its `<inertial>` with a massive geom in
/// `inertiagrouprange`.
fn mass_from_geoms(doc: &Document, body: Node) -> bool {
    let compiler = |attr: &str| {
        doc.elements(doc.root())
            .filter(|&n| doc.tag(n) == "compiler")
            .filter_map(|n| doc.attr(n, attr))
            .last()
            .map(str::trim)
    };
    let has_inertial = doc.elements(body).any(|k| doc.tag(k) == "inertial");
    match compiler("inertiafromgeom") {
        Some("false") => false,
        Some("true") => {
            !has_inertial
                || doc
                    .has_massive_geom_in_range(body, compiler("inertiagrouprange").unwrap_or("0 5"))
        }
        _ => !has_inertial,
    }
}

/// The attribute that holds a geom's share of its body's mass: `mass` where written (MuJoCo
/// then ignores `density`), else `density`.
fn geom_mass_attribute(doc: &Document, geom: Node) -> &'static str {
    if doc.attr(geom, "mass").is_some() {
        "mass"
    } else {
        "density"
    }
}

/// After a body's mass changed to `value`, its inertia scaled by new/old mass.
fn scale_inertia(
    out: &mut impl AttrTarget,
    inertial: Node,
    value: &str,
    at: &Location,
) -> Result<(), Errors> {
    let old: f64 = out
        .get(inertial, "mass")
        .and_then(|m| m.trim().parse().ok())
        .unwrap_or(0.0);
    let new: f64 = value.trim().parse().unwrap_or(0.0);
    if old <= 0.0 {
        return Err(out
            .doc()
            .error_at(
                inertial,
                ErrorKind::Invalid(format!(
                    "randomizer at {at}: <inertial> has no positive mass to scale its inertia from"
                )),
            )
            .into());
    }
    let factor = new / old;
    for attr in ["diaginertia", "fullinertia"] {
        if let Some(v) = out.get(inertial, attr).and_then(parse_numbers) {
            let scaled: Vec<f64> = v.iter().map(|x| x * factor).collect();
            out.set(inertial, attr, join(&scaled));
        }
    }
    Ok(())
}

/// Whether the document's angles are in degrees (MuJoCo's default).
fn doc_uses_degrees(doc: &Document) -> bool {
    let root = doc.root();
    doc.elements(root)
        .filter(|&n| doc.tag(n) == "compiler")
        .filter_map(|n| doc.attr(n, "angle"))
        .last()
        .is_none_or(|a| a.trim() != "radian")
}

fn at(v: &[f64], i: usize) -> f64 {
    v[i.min(v.len() - 1)]
}

pub(crate) fn parse_numbers(text: &str) -> Option<Vec<f64>> {
    text.split_ascii_whitespace()
        .map(|t| t.parse().ok())
        .collect()
}

fn quoted(name: Option<&str>) -> String {
    name.map_or_else(|| "(unnamed)".to_string(), |n| format!("'{n}'"))
}

fn element_label(doc: &Document, node: Node) -> String {
    format!("<{}> {}", doc.tag(node), quoted(doc.attr(node, "name")))
}

/// Shell-style glob: `*` any run, `?` one character.
pub(crate) fn glob(pattern: &str, text: &str) -> bool {
    let (p, t): (Vec<char>, Vec<char>) = (pattern.chars().collect(), text.chars().collect());
    let (mut pi, mut ti) = (0, 0);
    let (mut star, mut mark) = (None, 0);
    while ti < t.len() {
        if pi < p.len() && (p[pi] == '?' || p[pi] == t[ti]) {
            pi += 1;
            ti += 1;
        } else if pi < p.len() && p[pi] == '*' {
            star = Some(pi);
            mark = ti;
            pi += 1;
        } else if let Some(s) = star {
            pi = s + 1;
            mark += 1;
            ti = mark;
        } else {
            return false;
        }
    }
    p[pi..].iter().all(|&c| c == '*')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs() {
        assert!(glob("*", ""));
        assert!(glob("g*_vis", "g12_vis"));
        assert!(!glob("g*_vis", "g12_col"));
        assert!(glob("a?c*", "abcde"));
        assert!(!glob("a?c", "ac"));
        assert!(glob("*a*b", "xxaxxb"));
        assert!(!glob("*a*b", "xxaxxbc"));
    }
}
