//! One structure for a whole scene (`superset`): a model holding the template and every
//! object any slot of any group can hold, so that every variant, structural ones included,
//! is a patch of one compiled model, as batched simulators (MJX, MuJoCo Warp, MuJoCo's
//! batch API) need: all worlds share one structure.
//!
//! Every candidate object is compiled as it is authored (colliding geoms colliding: MuJoCo
//! cannot switch on a geom compiled as non-colliding in a body whose other geoms collide),
//! with gravity compensation on its bodies (so that `ngravcomp` counts them and switching
//! it per body works). A variant's superset patch then sets, per candidate:
//! - placed in the variant: its authored `rgba` and `gravcomp`,
//!   and the variant's own values (pose, colours, ...);
//! - not placed (parked): out of reach (each candidate in its own cell of a grid high
//!   above the world, see [`parking_cell`]), invisible (alpha 0), held still (`gravcomp`
//!   1, at rest).
//!
//! Parking is geometric, never through collision flags: every candidate keeps its
//! authored `contype` and `conaffinity` in every variant. Batched simulators fix the pairs
//! of geoms that may collide once for all worlds (MuJoCo Warp in `put_model`, MJX in its
//! collision groups), so a candidate switched off by its flags in one variant would have no
//! contacts in the worlds that place it; and below the world a parked object would sink in
//! a floor plane (a half-space) and be thrown away.

use crate::document::Document;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind, Errors};
use crate::model::merge::MergePart;

use super::patch::{self, VariantPatch};
use super::randomize::AttrTarget as _;
use super::{Scene, place};
use crate::split::{self, PatchEntry, PatchValue};

/// Where parked objects wait: a horizontal grid of square cells `PARK_STEP` wide, centred
/// `PARK_HEIGHT` straight above the world's origin: above any floor (a plane through the
/// origin, as arenas have), out of reach of a robot or a table, and no further than needed
/// (float32 simulators lose precision far from the origin). A candidate larger than a
/// cell, or a template that reaches that high, is caught by the caller's contact check
/// (python's `mjcf_forge.batch` refuses a superset whose parked geoms touch anything).
const PARK_HEIGHT: f64 = 10.0;
const PARK_STEP: f64 = 5.0;

/// The parking cell of candidate `k` of `n`: row-major in a square grid centred above the
/// origin.
fn parking_cell(k: usize, n: usize) -> [f64; 3] {
    let columns = (n as f64).sqrt().ceil().max(1.0) as usize;
    let rows = n.div_ceil(columns);
    let x = (k % columns) as f64 - (columns - 1) as f64 / 2.0;
    let y = (k / columns) as f64 - (rows.max(1) - 1) as f64 / 2.0;
    [x * PARK_STEP, y * PARK_STEP, PARK_HEIGHT]
}

/// The superset of a scene (see the module).
#[derive(Debug)]
pub struct Superset {
    /// The model: the template with every candidate object parked.
    pub document: Document,
    /// The structure key every variant's superset patch carries.
    pub structure_key: String,
    members: Vec<Member>,
}

/// One candidate object: group, slot and pool model, and what switching it takes.
#[derive(Debug)]
struct Member {
    choice: (usize, u32, usize),
    /// Added before the instance's names in the superset (when a slot can hold several
    /// pool models, their instances would otherwise share names).
    tag: String,
    root: String,
    joint: Option<String>,
    root_massless: bool,
    parked: [f64; 3],
    /// Superset names of its bodies and their authored `gravcomp`.
    bodies: Vec<(String, f64)>,
    /// Superset names of its geoms (those the compiled model keeps) and their authored
    /// `rgba` (as `f32`).
    geoms: Vec<(String, [f64; 4])>,
    /// The instance with its unnamed bodies and geoms named (see [`name_internally`]),
    /// before the tag: what its patch entries are read from.
    named: Document,
    /// Its bodies' unit models' text, made once.
    units: split::UnitCache,
    /// Which body carries an element's attribute ([`split::carried_by`]), found once.
    carried: std::sync::Mutex<ahash::AHashMap<(Node, String), Option<Node>>>,
}

impl Member {
    /// The body whose body model carries `attr` of `node` in [`Member::named`], if any:
    /// the same for every variant, so found once.
    fn carried_by(&self, node: Node, attr: &str) -> Option<Node> {
        let key = (node, attr.to_string());
        if let Some(found) = self.carried.lock().ok().and_then(|c| c.get(&key).copied()) {
            return found;
        }
        let found = split::carried_by(&self.named, node, attr);
        if let Ok(mut c) = self.carried.lock() {
            c.insert(key, found);
        }
        found
    }
}

/// Names the unnamed bodies and geoms below `root` (itself included) of an instance whose
/// names carry `prefix`: `{prefix}unnamed_body{k}` and `{prefix}unnamed_geom{k}`, `k`
/// counting that instance's unnamed elements of the kind in document order (a name the
/// instance already has is skipped). So a candidate's every body and geom can be switched
/// and patched by name in the superset; in a variant's own model they stay unnamed, and
/// the `k`-th unnamed geom of an object there is `{prefix}unnamed_geom{k}` here.
fn name_internally(doc: &mut Document, root: Node, prefix: &str) {
    let nodes: Vec<Node> = std::iter::once(root).chain(doc.descendants(root)).collect();
    let taken: ahash::AHashSet<String> = nodes
        .iter()
        .filter_map(|&n| doc.attr(n, "name"))
        .map(str::to_string)
        .collect();
    for kind in ["body", "geom"] {
        let mut k = 0usize;
        for &n in &nodes {
            if doc.tag(n) != kind || doc.attr(n, "name").is_some() {
                continue;
            }
            let name = loop {
                let name = format!("{prefix}unnamed_{kind}{k}");
                k += 1;
                if !taken.contains(&name) {
                    break name;
                }
            };
            doc.set_attr(n, "name", &name);
        }
    }
}

fn number(doc: &Document, node: Node, attr: &str, default: f64) -> f64 {
    doc.attr(node, attr)
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(default)
}

impl Scene {
    /// The scene's superset (see [`Superset`]): every object any slot can hold, parked.
    ///
    /// ```
    /// let scene = mjcf_forge::scene::Scene::demo()?;
    /// let sup = scene.superset()?;
    /// // Slots of clutter (up to 4, each one of 3 models), blocks (2), coins (1).
    /// let xml = sup.document.to_xml_string();
    /// assert!(xml.contains("m2_clutter3_"));
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn superset(&self) -> Result<Superset, Errors> {
        let mut doc = self.template.clone();
        let mut parts: Vec<(Document, String)> = Vec::new();
        let mut members = Vec::new();
        let candidates: usize = self
            .groups
            .iter()
            .map(|g| g.count.1 as usize * g.pool.len())
            .sum();
        for (gi, group) in self.groups.iter().enumerate() {
            for slot in 0..group.count.1 {
                for m in 0..group.pool.len() {
                    let inst = self.instance(group, slot, m)?;
                    let mut named = inst.doc.clone();
                    name_internally(&mut named, inst.root, &inst.prefix);
                    let mut part = named.clone();
                    place::clear_orientation(&mut part, inst.root);
                    let tag = if group.pool.len() > 1 {
                        format!("m{m}_")
                    } else {
                        String::new()
                    };
                    if !tag.is_empty() {
                        part.apply_prefix(&tag).map_err(|e| Errors(vec![e]))?;
                    }
                    let parked = parking_cell(members.len(), candidates);
                    members.push(member(
                        &mut part,
                        inst.root,
                        (gi, slot, m),
                        tag,
                        parked,
                        self.discard_visual,
                        named,
                    )?);
                    parts.push((part, inst.prefix.clone()));
                }
            }
        }
        let docs: Vec<&Document> = parts.iter().map(|(d, _)| d).collect();
        let clashes = doc.name_clashes(&docs);
        if !clashes.is_empty() {
            return Err(Errors(clashes));
        }
        let merge: Vec<MergePart<'_>> = parts
            .iter()
            .map(|(d, prefix)| MergePart {
                doc: d,
                into: None,
                prefix,
            })
            .collect();
        doc.merge_unchecked(&merge, false)?;
        if self.discard_visual {
            doc.set_discard_visual();
        }
        let (_, fingerprint) = self.structure();
        let mut key = blake3::Hasher::new();
        key.update(fingerprint);
        key.update(b"superset");
        Ok(Superset {
            document: doc,
            structure_key: key.finalize().to_hex()[..32].to_string(),
            members,
        })
    }

    /// Variant `index` as a patch of the scene's superset: which candidates are placed
    /// (and their values), which are parked. An error when the variant randomizes a value
    /// no patch can carry (see [`super::PATCHABLE`]): its model is not a patch of any
    /// other.
    pub fn superset_patch(&self, superset: &Superset, index: u64) -> Result<VariantPatch, Errors> {
        let drawn = self.draw(index)?;
        let (rules, fingerprint) = self.structure();
        let (own, parts, refused) = patch::split_parts(fingerprint, rules, index, &drawn);
        let placed: Vec<Option<usize>> = drawn
            .choices
            .iter()
            .map(|c| superset.members.iter().position(|m| m.choice == *c))
            .collect();
        // A placed object's value refused only for want of a name is patched by its
        // internal name (see `name_internally`).
        let in_key = refused
            .iter()
            .filter(|(part, node, attr)| {
                let Some(j) = part.checked_sub(1) else {
                    return true;
                };
                let (Some((inst, overlay)), Some(Some(k))) = (drawn.placed.get(j), placed.get(j))
                else {
                    return true;
                };
                let named = &superset.members[*k].named;
                overlay.get(*node, attr).is_none_or(|value| {
                    split::entry(named, *node, attr, value, rules, None, *node == inst.root)
                        .is_none()
                })
            })
            .count();
        if in_key > 0 {
            return Err(Errors(vec![Error::bare(ErrorKind::Invalid(format!(
                "variant {index}: {in_key} randomized value(s) cannot be patched (see \
                 PATCHABLE), so the variant is not a patch of the superset"
            )))]));
        }
        let mut entries = Vec::new();
        let numbers = |v: &[f64]| PatchValue::Numbers(v.to_vec());
        let push = |entries: &mut Vec<PatchEntry>, object, name: &str, field, value| {
            entries.push(PatchEntry {
                object,
                name: name.to_string(),
                id: None,
                field,
                value,
            });
        };
        // Per candidate, in one layout whatever the variant (so that a model cache resolves
        // the superset's targets once): every value a randomizer may give it (placed: the
        // variant's; parked: as authored, so that its model never depends on earlier
        // variants), then its switches (gravity compensation, colour with alpha 0 when
        // parked; collision bits stay as authored, see the module), then its pose.
        for (k, m) in superset.members.iter().enumerate() {
            let at = placed.iter().position(|p| *p == Some(k));
            let overlay = at.map(|j| &drawn.placed[j].1);
            let (g, slot, model) = m.choice;
            let inst = self.instance(&self.groups[g], slot, model)?;
            let mut rgba: Vec<(String, Vec<f64>)> = Vec::new();
            // The instance with its unnamed elements named (the same nodes as inst.doc).
            let doc = &m.named;
            // Bodies whose body models carry randomized values of their geoms (sizes,
            // frames, densities): one entry each, placed or parked.
            // With whether only their geoms' densities and masses vary.
            let mut modelled: Vec<(Node, bool)> = Vec::new();
            for (r, targets) in &inst.targets {
                for t in targets {
                    for attr in self.randomizers[*r].attributes_set(doc, t.node) {
                        if rules.body_models
                            && let Some(body) = m.carried_by(t.node, attr)
                        {
                            let masses = matches!(attr, "density" | "mass");
                            match modelled.iter_mut().find(|(b, _)| *b == body) {
                                Some((_, only)) => *only &= masses,
                                None => modelled.push((body, masses)),
                            }
                            continue;
                        }
                        let tag = doc.tag(t.node);
                        let value = match overlay {
                            Some(o) => o.get(t.node, attr),
                            None => doc
                                .attr(t.node, attr)
                                .or_else(|| super::randomize::mujoco_default(tag, attr)),
                        };
                        let Some(value) = value else { continue };
                        if rules.discard && split::dropped(doc, t.node, attr) != Some(false) {
                            continue;
                        }
                        let root = t.node == inst.root;
                        let Some(mut e) = split::entry(doc, t.node, attr, value, rules, None, root)
                        else {
                            continue;
                        };
                        e.name = format!("{}{}", m.tag, e.name);
                        match (&e.value, e.object, e.field) {
                            (PatchValue::Numbers(v), "geom", "rgba") => {
                                rgba.push((e.name.clone(), v.clone()));
                            }
                            _ => entries.push(e),
                        }
                    }
                }
            }
            // Bodies whose geoms' densities and masses alone vary: their unit models, the
            // values read through the variant's (no copy of the document).
            let mut whole = Vec::new();
            // The variant's densities and masses by element, found at once.
            let drawn_masses: ahash::AHashMap<(Node, &str), &str> = overlay
                .map(|o| {
                    o.values
                        .iter()
                        .filter(|(_, a, _)| matches!(a.as_str(), "density" | "mass"))
                        .map(|(n, a, v)| ((*n, a.as_str()), v.as_str()))
                        .collect()
                })
                .unwrap_or_default();
            for (body, masses_only) in modelled {
                let made = match doc.attr(body, "name") {
                    Some(name) if masses_only => {
                        let value = |n: Node, a: &str| {
                            drawn_masses
                                .get(&(n, a))
                                .copied()
                                .or_else(|| doc.attr(n, a))
                                .map(str::to_string)
                        };
                        split::unit_model_entries(
                            doc,
                            body,
                            &format!("{}{name}", m.tag),
                            &value,
                            Some(&m.units),
                        )
                    }
                    _ => None,
                };
                match made {
                    Some(made) => entries.extend(made),
                    None => whole.push(body),
                }
            }
            let modelled = whole;
            if !modelled.is_empty() {
                // Placed: the variant's values; parked: as authored.
                let applied;
                let source = match overlay {
                    Some(o) => {
                        let mut copy = doc.clone();
                        o.apply_to(&mut copy);
                        applied = copy;
                        &applied
                    }
                    None => doc,
                };
                for body in modelled {
                    let made = source.attr(body, "name").and_then(|name| {
                        split::body_model_entries(source, body, format!("{}{name}", m.tag))
                    });
                    let Some(made) = made else {
                        return Err(Errors(vec![Error::bare(ErrorKind::Invalid(format!(
                            "variant {index}: a geom of '{}' changes what its body derives, \
                             and the body cannot be compiled alone",
                            m.root
                        )))]));
                    };
                    entries.extend(made);
                }
            }
            let active = overlay.is_some();
            for (body, gravcomp) in &m.bodies {
                let g = if active { *gravcomp } else { 1.0 };
                push(&mut entries, "body", body, "gravcomp", numbers(&[g]));
            }
            for (geom, authored) in &m.geoms {
                let colour = rgba
                    .iter()
                    .rev()
                    .find(|(n, _)| n == geom)
                    .map_or(authored.to_vec(), |(_, v)| v.clone());
                let alpha = if active { colour[3] } else { 0.0 };
                push(
                    &mut entries,
                    "geom",
                    geom,
                    "rgba",
                    numbers(&[colour[0], colour[1], colour[2], alpha]),
                );
            }
            let (pos, quat) = match overlay {
                Some(o) => {
                    let read = |a: &str, n| {
                        o.get(inst.root, a)
                            .and_then(|v| split::numbers(v, n, false))
                    };
                    match (read("pos", 3), read("quat", 4)) {
                        (Some(p), Some(q)) => (p, split::normalized(q)),
                        _ => {
                            return Err(Errors(vec![Error::bare(ErrorKind::Invalid(format!(
                                "variant {index}: the pose of '{}' cannot be read",
                                m.root
                            )))]));
                        }
                    }
                }
                None => (m.parked.to_vec(), vec![1.0, 0.0, 0.0, 0.0]),
            };
            push(&mut entries, "body", &m.root, "pos", numbers(&pos));
            push(&mut entries, "body", &m.root, "quat", numbers(&quat));
            if m.root_massless {
                push(&mut entries, "body", &m.root, "ipos", numbers(&pos));
                push(&mut entries, "body", &m.root, "iquat", numbers(&quat));
            }
            if let Some(j) = &m.joint {
                let qpos: Vec<f64> = pos.iter().chain(&quat).copied().collect();
                push(&mut entries, "joint", j, "qpos0", numbers(&qpos));
                push(&mut entries, "joint", j, "qpos_spring", numbers(&qpos));
                if rules.keys {
                    push(&mut entries, "joint", j, "key_qpos", numbers(&qpos));
                }
            }
        }
        // The template's own values.
        for (e, part) in own.entries.into_iter().zip(parts) {
            if part == 0 {
                entries.push(e);
            }
        }
        Ok(VariantPatch {
            index,
            structure_key: superset.structure_key.clone(),
            entries,
        })
    }
}

impl Scene {
    /// For variant `index`, each placed object's prefix and the tag its names carry in the
    /// superset (a superset name is tag + the variant's name; the tag is empty when the
    /// object's group draws from one model).
    pub fn superset_names(
        &self,
        superset: &Superset,
        index: u64,
    ) -> Result<Vec<(String, String)>, Errors> {
        let drawn = self.draw(index)?;
        Ok(drawn
            .placed
            .iter()
            .zip(&drawn.choices)
            .filter_map(|((inst, _), c)| {
                let m = superset.members.iter().find(|m| m.choice == *c)?;
                Some((inst.prefix.clone(), m.tag.clone()))
            })
            .collect())
    }
}

impl Scene {
    /// For variant `index`, the superset names of the root bodies of the objects it does
    /// not place (parked).
    pub fn superset_parked(&self, superset: &Superset, index: u64) -> Result<Vec<String>, Errors> {
        let drawn = self.draw(index)?;
        Ok(superset
            .members
            .iter()
            .filter(|m| !drawn.choices.contains(&m.choice))
            .map(|m| m.root.clone())
            .collect())
    }
}

/// Prepares one candidate's instance for the superset (parked, gravity-compensated, every
/// body and geom named) and records what switching it takes.
fn member(
    part: &mut Document,
    root: Node,
    choice: (usize, u32, usize),
    tag: String,
    parked: [f64; 3],
    discard: bool,
    named: Document,
) -> Result<Member, Errors> {
    let unnamed = |part: &Document, what: &str| {
        Errors(vec![part.error_at(
            root,
            ErrorKind::Invalid(format!(
                "the superset needs every {what} of a placed object named (give it a name, or \
                 set name_unnamed_geoms for geoms)"
            )),
        )])
    };
    let root_name = part
        .attr(root, "name")
        .ok_or_else(|| unnamed(part, "root body"))?
        .to_string();
    let joint = split::free_joint(part, root).map(str::to_string);
    let root_massless = split::massless(part, root);
    part.set_attr(root, "pos", &place::join(&parked));
    part.set_attr(root, "quat", "1 0 0 0");
    let nodes: Vec<Node> = std::iter::once(root)
        .chain(part.descendants(root))
        .collect();
    let mut bodies = Vec::new();
    let mut geoms = Vec::new();
    for n in nodes {
        match part.tag(n) {
            "body"
                if !bodies
                    .iter()
                    .any(|(b, _): &(String, f64)| Some(b.as_str()) == part.attr(n, "name")) =>
            {
                let name = part
                    .attr(n, "name")
                    .ok_or_else(|| unnamed(part, "body"))?
                    .to_string();
                bodies.push((name, number(part, n, "gravcomp", 0.0)));
                part.set_attr(n, "gravcomp", "1");
            }
            "geom" => {
                if discard && split::discarded(part, n) != Some(false) {
                    // Not in the compiled model (or kept by a reference: left alone).
                    continue;
                }
                let name = part
                    .attr(n, "name")
                    .ok_or_else(|| unnamed(part, "geom"))?
                    .to_string();
                let rgba: Vec<f64> = part
                    .attr(n, "rgba")
                    .unwrap_or("0.5 0.5 0.5 1")
                    .split_ascii_whitespace()
                    .filter_map(|t| t.parse::<f32>().ok().map(f64::from))
                    .collect();
                let rgba = match rgba[..] {
                    [r, g, b, a] => [r, g, b, a],
                    _ => return Err(unnamed(part, "geom with a readable rgba,")),
                };
                geoms.push((name, rgba));
            }
            _ => {}
        }
    }
    Ok(Member {
        choice,
        tag,
        root: root_name,
        joint,
        root_massless,
        parked,
        bodies,
        geoms,
        named,
        units: split::UnitCache::default(),
        carried: Default::default(),
    })
}
