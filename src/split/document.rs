//! Any document as a *structure key* and a *patch*, found by reading the document alone:
//! what `scene::patch` does for a scene's variants, for documents built any other
//! way (robosuite's classes, a user's own code, an XML string).
//!
//! Every attribute whose value a rule of [`PATCHABLE`](super::PATCHABLE) (or of the two
//! tables here, [`PATCHABLE_OPTIONS`] and the actuator gains) can write into a compiled
//! model exactly becomes a patch entry; everything else (tags, the tree, names, every
//! other attribute and its value, which attributes are patched, where each value lands)
//! is hashed into the key. Two documents with the same key compile to models that differ
//! only in the patched values and what MuJoCo's `mj_setConst` derives from them, so one
//! compiled model per key serves them all (`crate::compiled::DocumentCache`).
//!
//! The rules only ever move a value into the key: a value the compiler checks (a mass, an
//! inertia, a time step) is patched only when it is one MuJoCo accepts as written, a value
//! the compiler derives something from that `mj_setConst` does not redo (a damping ratio,
//! a spatial tendon's spring length at `qpos0`) keeps what it feeds into the key. So a
//! key never promises more than MuJoCo's own compile gives.

use std::path::Path;

use super::body_model::{body_model, qualifies, sized_primitive};
use super::rules::{
    PatchEntry, PatchValue, Rules, derives_damping, dropped, entry, massless, normalized, numbers,
    owner, setting,
};
use crate::document::tree::Node;
use crate::document::{Document, Section};

/// What a split may patch beyond the values a compiled model takes as they are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SplitOptions {
    /// Sizes of primitive geoms (sphere, capsule, ellipsoid, cylinder, box, sized by
    /// `size`): their body's entry is a [`PatchValue::BodyModel`] model of its geoms, whose
    /// compile gives what MuJoCo derives from them (sizes, bounds, mass and inertia,
    /// bounding volumes). For a model cache that compiles those (`DocumentCache`, in Rust
    /// and Python).
    pub body_models: bool,
}

/// A document as a structure key and a patch (see [`split_document`]).
#[derive(Clone, Debug, PartialEq)]
pub struct DocumentPatch {
    /// Equal for two documents exactly when their compiled models differ only in the
    /// patched fields (and what `mj_setConst` derives from them): 32 hex digits.
    pub structure_key: String,
    /// The values that turn a compiled model of this structure into this document's, in
    /// document order. Unnamed elements are named by their compiled id.
    pub entries: Vec<PatchEntry>,
    /// The statistics the document's `<statistic>` sets (MuJoCo keeps them over what it
    /// computes): `meaninertia`, `meanmass`, `meansize`, `extent`, `center`.
    pub fixed_statistics: Vec<&'static str>,
}

/// `(attribute, components)`: the `<option>` values a patch carries, into `mjOption`'s
/// field of the same name (`model.opt.<field>`). The compiler derives nothing from them.
pub const PATCHABLE_OPTIONS: &[(&str, usize)] = &[
    ("timestep", 1),
    ("impratio", 1),
    ("tolerance", 1),
    ("ls_tolerance", 1),
    ("noslip_tolerance", 1),
    ("gravity", 3),
    ("wind", 3),
    ("magnetic", 3),
    ("density", 1),
    ("viscosity", 1),
];

/// Actuator parameters per actuator (`mjNGAIN`, `mjNBIAS`, `mjNDYN` in 3.17.0 and 4.0.0).
const PRM: usize = 10;

/// What the whole document allows, decided once before the walk.
struct DocRules {
    /// The scene tier's rules for this document as a template without parts.
    base: Rules,
    /// No muscle and no `lengthrange` computed for every actuator: the compiler's
    /// length-range simulation depends on every dynamic value, so with one only visual
    /// values are patched.
    dynamics: bool,
    /// One `<option>`.
    options: bool,
    /// The compiled id of each actuator (MuJoCo numbers them in order), when the ids of
    /// unnamed elements are known at all.
    actuator_ids: Option<ahash::AHashMap<Node, usize>>,
    /// Sizes of primitive geoms are patched through their body models
    /// ([`body_model`]): asked for, masses land unchanged and feed nothing the compiler
    /// keeps (no length-range simulation), every geom of the compiled model is one of the
    /// document (no `discardvisual`), and no spatial tendon, flex, composite or skin hangs
    /// on a geom's size or a body's inertia.
    sizes: bool,
}

impl DocRules {
    fn new(doc: &Document, options: SplitOptions) -> DocRules {
        let discard = setting(doc, "compiler", "discardvisual").map(str::trim) == Some("true");
        // The scene tier's rules: damping ratios, fused static bodies, spatial tendons,
        // flexes, composites and skins, and actuators' own armature and damping included.
        let base = Rules::new(doc, &[], discard);
        let all = || doc.descendants(doc.root());
        let actuators: Vec<Node> = doc
            .find_section(Section::Actuator)
            .map(|s| doc.elements(s).collect())
            .unwrap_or_default();
        let hanging = all().any(|n| {
            matches!(doc.tag(n), "spatial" | "flex" | "flexcomp" | "composite")
                || (doc.tag(n) == "skin" && doc.elements(n).next().is_some())
        });
        let muscle = |n: Node| {
            doc.tag(n) == "muscle"
                || ["dyntype", "gaintype", "biastype"]
                    .iter()
                    .any(|a| doc.attr(n, a).map(str::trim) == Some("muscle"))
        };
        let lengthrange_all = all().any(|n| {
            doc.tag(n) == "lengthrange" && doc.attr(n, "mode").map(str::trim) == Some("all")
        });
        let actuator_ids = base
            .ids
            .as_ref()
            .map(|_| actuators.iter().enumerate().map(|(i, &n)| (n, i)).collect());
        let dynamics = !actuators.iter().any(|&n| muscle(n)) && !lengthrange_all;
        DocRules {
            sizes: options.body_models && base.mass && dynamics && !discard && !hanging,
            dynamics,
            options: doc
                .elements(doc.root())
                .filter(|&n| doc.tag(n) == "option")
                .count()
                == 1,
            actuator_ids,
            base,
        }
    }
}

/// Splits `doc` into its structure key and its patch.
///
/// A document that still has `<default>` classes (added after loading) is split as its
/// classes resolve; one whose classes do not resolve is all structure.
///
/// ```
/// use mjcf_forge::Document;
/// use mjcf_forge::split::split_document;
///
/// let xml = |rgba: &str, size: &str| {
///     format!(
///         "<mujoco><worldbody><body name='b'><freejoint/>\
///          <geom name='g' size='{size}' rgba='{rgba}'/></body></worldbody></mujoco>"
///     )
/// };
/// let a = split_document(&Document::from_str(&xml("1 0 0 1", "0.1"), ".")?);
/// let b = split_document(&Document::from_str(&xml("0 1 0 1", "0.1"), ".")?);
/// let c = split_document(&Document::from_str(&xml("1 0 0 1", "0.2"), ".")?);
/// assert_eq!(a.structure_key, b.structure_key); // a colour is patched
/// assert_ne!(a.structure_key, c.structure_key); // a size is compiled
/// assert_eq!((a.entries[0].object, a.entries[0].field), ("geom", "rgba"));
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn split_document(doc: &Document) -> DocumentPatch {
    split_document_with(doc, SplitOptions::default())
}

/// [`split_document`] with [`SplitOptions`]: with `body_models`, documents that differ
/// in the sizes of primitive geoms share a structure.
///
/// ```
/// use mjcf_forge::Document;
/// use mjcf_forge::split::{PatchValue, SplitOptions, split_document_with};
///
/// let xml = |size: &str| {
///     format!("<mujoco><worldbody><body name='b'><freejoint/><geom size='{size}'/></body></worldbody></mujoco>")
/// };
/// let sizes = SplitOptions { body_models: true };
/// let a = split_document_with(&Document::from_str(&xml("0.1"), ".")?, sizes);
/// let b = split_document_with(&Document::from_str(&xml("0.2"), ".")?, sizes);
/// assert_eq!(a.structure_key, b.structure_key);
/// assert_eq!((b.entries[0].object, b.entries[0].field), ("body", "geoms"));
/// let PatchValue::BodyModel(body) = &b.entries[0].value else { unreachable!() };
/// assert_eq!(body, r#"<mujoco><worldbody><body><geom size="0.2"/></body></worldbody></mujoco>"#);
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn split_document_with(doc: &Document, options: SplitOptions) -> DocumentPatch {
    if doc
        .elements(doc.root())
        .any(|n| doc.tag(n) == "default" && doc.elements(n).next().is_some())
    {
        let mut resolved = doc.clone();
        return match crate::document::defaults::inline_defaults(&mut resolved) {
            Ok(()) => split_resolved(&resolved, options),
            Err(_) => all_structure(doc),
        };
    }
    split_resolved(doc, options)
}

/// The key of a document taken whole, with no patch.
fn all_structure(doc: &Document) -> DocumentPatch {
    let mut key = Key::new(doc);
    key.str(&doc.to_xml_string());
    DocumentPatch {
        structure_key: key.finish(&[]),
        entries: Vec::new(),
        fixed_statistics: Vec::new(),
    }
}

/// The structure key's input, laid out as length-prefixed strings and markers, hashed
/// once at the end.
struct Key(Vec<u8>);

impl Key {
    fn new(doc: &Document) -> Key {
        let mut key = Key(Vec::with_capacity(1 << 16));
        key.str("mjcf-forge document key 1");
        // Relative file names resolve from the model's folder (loading makes them
        // absolute; a document edited afterwards may have some).
        let relative = doc.descendants(doc.root()).any(|n| {
            doc.attrs(n).any(|(a, v)| {
                (a.starts_with("file") || matches!(a, "meshdir" | "texturedir" | "assetdir"))
                    && Path::new(v.trim()).is_relative()
            })
        });
        if relative {
            key.str(&doc.model_dir().to_string_lossy());
        }
        key
    }

    fn str(&mut self, s: &str) {
        self.0.extend_from_slice(&(s.len() as u64).to_le_bytes());
        self.0.extend_from_slice(s.as_bytes());
    }

    fn mark(&mut self, m: u8) {
        self.0.push(m);
    }

    /// The hash, with the patch's layout (so that one key always means one list of
    /// targets: a model cache resolves a structure's targets once).
    fn finish(mut self, entries: &[PatchEntry]) -> String {
        self.mark(b'#');
        for e in entries {
            for s in [e.object, e.name.as_str(), e.field] {
                self.str(s);
            }
            let id = e.id.map_or(u64::MAX, |i| i as u64);
            self.0.extend_from_slice(&id.to_le_bytes());
        }
        blake3::hash(&self.0).to_hex()[..32].to_string()
    }
}

fn split_resolved(doc: &Document, options: SplitOptions) -> DocumentPatch {
    let rules = DocRules::new(doc, options);
    let mut key = Key::new(doc);
    let mut entries: Vec<PatchEntry> = Vec::new();
    // The open elements, to mark where each one closes (the key holds the tree's shape).
    let mut open: Vec<Node> = Vec::new();
    let mut replicated = 0usize;
    // A <body> or <frame> directly under <mujoco> (a file meant to be included into a
    // <worldbody>) is read and left out by MuJoCo, which compiles such a file to the world
    // alone: what it holds is in the key, and in no patch.
    let root = doc.root();
    let ignored = |node: Node| {
        let mut top = node;
        while let Some(p) = doc.parent(top).filter(|&p| p != root) {
            top = p;
        }
        matches!(doc.tag(top), "body" | "frame") && doc.parent(top) == Some(root)
    };
    for node in doc.descendants(doc.root()) {
        let parent = doc.parent(node);
        while open.last().is_some_and(|&o| Some(o) != parent) {
            if let Some(closed) = open.pop()
                && doc.tag(closed) == "replicate"
            {
                replicated -= 1;
            }
            key.mark(b'>');
        }
        open.push(node);
        let tag = doc.tag(node);
        key.mark(b'<');
        key.str(tag);
        // Elements a `replicate` repeats are renamed and numbered by the compiler.
        let patched = if replicated == 0 && !ignored(node) {
            element_entries(doc, node, &rules)
        } else {
            Patched::default()
        };
        if tag == "replicate" {
            replicated += 1;
        }
        for (attr, value) in doc.attrs(node) {
            key.str(attr);
            if patched.attrs.contains(&attr) {
                key.mark(b'*');
            } else {
                key.str(value);
            }
        }
        for text in doc.children(node).filter_map(|c| doc.text(c)) {
            if !text.trim().is_empty() {
                key.mark(b'"');
                key.str(text);
            }
        }
        entries.extend(patched.entries);
    }
    let fixed_statistics = super::fixed_statistics(doc);
    DocumentPatch {
        structure_key: key.finish(&entries),
        entries,
        fixed_statistics,
    }
}

/// One element's patch entries and the attributes they carry.
#[derive(Default)]
struct Patched<'d> {
    attrs: Vec<&'d str>,
    entries: Vec<PatchEntry>,
}

impl<'d> Patched<'d> {
    fn add(&mut self, attr: &'d str, e: PatchEntry) {
        self.mark(attr);
        self.entries.push(e);
    }

    /// An attribute whose value an entry of another element carries.
    fn mark(&mut self, attr: &'d str) {
        if !self.attrs.contains(&attr) {
            self.attrs.push(attr);
        }
    }
}

/// The entries of one element (none when every value of it is structure).
fn element_entries<'d>(doc: &'d Document, node: Node, rules: &DocRules) -> Patched<'d> {
    let mut out = Patched::default();
    let tag = doc.tag(node);
    let parent_tag = doc.parent(node).map(|p| doc.tag(p));
    if rules.sizes {
        compiled_body_entries(doc, node, &mut out);
    }
    match (tag, parent_tag) {
        ("body", _) => body_entries(doc, node, rules, &mut out),
        ("option", Some("mujoco")) if rules.options && rules.dynamics => {
            for (attr, value) in doc.attrs(node) {
                if let Some(e) = option_entry(attr, value) {
                    out.add(attr, e);
                }
            }
        }
        (_, Some("actuator")) if rules.dynamics => actuator_entries(doc, node, rules, &mut out),
        _ => {
            let ids = rules.base.ids.as_ref();
            for (attr, value) in doc.attrs(node) {
                if rules.base.discard && dropped(doc, node, attr) != Some(false) {
                    continue;
                }
                let Some(e) = entry(doc, node, attr, value, &rules.base, ids, false) else {
                    continue;
                };
                if (rules.dynamics || visual(&e)) && accepted(&e) {
                    out.add(attr, e);
                }
            }
        }
    }
    out
}

/// A body's frame (`pos`, `quat`), with what follows it: its free joint's `qpos0` and
/// `qpos_spring`, and for a body with neither `<inertial>` nor geoms its inertial frame.
/// All or nothing: a frame the rules cannot read, or whose free joint has neither name
/// nor id, stays structure whole.
fn body_entries<'d>(doc: &'d Document, body: Node, rules: &DocRules, out: &mut Patched<'d>) {
    let (pos_text, quat_text) = (doc.attr(body, "pos"), doc.attr(body, "quat"));
    if (pos_text.is_none() && quat_text.is_none()) || !rules.dynamics {
        return;
    }
    let ids = rules.base.ids.as_ref();
    let mut frame = Vec::new();
    for (attr, text) in [("pos", pos_text), ("quat", quat_text)] {
        if let Some(text) = text {
            match entry(doc, body, attr, text, &rules.base, ids, false) {
                Some(e) if accepted(&e) => frame.push((attr, e)),
                _ => return,
            }
        }
    }
    let pos = numbers(pos_text.unwrap_or("0 0 0"), 3, false);
    // A quaternion of (nearly) zero norm is the compiler's to refuse.
    let quat = numbers(quat_text.unwrap_or("1 0 0 0"), 4, false)
        .filter(|q| q.iter().map(|x| x * x).sum::<f64>() > 1e-10)
        .map(normalized);
    let (Some(pos), Some(quat), Some(name)) = (pos, quat, doc.attr(body, "name")) else {
        return;
    };
    let joint = match free_joint(doc, body, ids) {
        FreeJoint::None => None,
        FreeJoint::Unknown => return,
        FreeJoint::Found(name, id) => Some((name, id)),
    };
    for (attr, e) in frame {
        out.add(attr, e);
    }
    let attr = if pos_text.is_some() { "pos" } else { "quat" };
    let numbers = |v: &[f64]| PatchValue::Numbers(v.to_vec());
    if massless(doc, body) {
        for (field, v) in [("ipos", &pos), ("iquat", &quat)] {
            let e = PatchEntry {
                object: "body",
                name: name.to_string(),
                id: None,
                field,
                value: numbers(v),
            };
            out.add(attr, e);
        }
    }
    if let Some((name, id)) = joint {
        let qpos: Vec<f64> = pos.iter().chain(&quat).copied().collect();
        for field in ["qpos0", "qpos_spring"] {
            let e = PatchEntry {
                object: "joint",
                name: name.clone(),
                id,
                field,
                value: numbers(&qpos),
            };
            out.add(attr, e);
        }
    }
}

/// A body's entry of its body model ([`body_model`]), and a sized geom's `size`, which
/// that entry carries.
fn compiled_body_entries<'d>(doc: &'d Document, node: Node, out: &mut Patched<'d>) {
    match doc.tag(node) {
        "body" => {
            if qualifies(doc, node)
                && let Some(model) = body_model(doc, node)
            {
                let name = doc.attr(node, "name").unwrap_or_default().to_string();
                out.entries.push(PatchEntry {
                    object: "body",
                    name,
                    id: None,
                    field: "geoms",
                    value: PatchValue::BodyModel(model),
                });
            }
        }
        "geom"
            if sized_primitive(doc, node)
                && doc.parent(node).is_some_and(|body| qualifies(doc, body)) =>
        {
            out.mark("size");
        }
        _ => {}
    }
}

enum FreeJoint {
    None,
    /// A free joint that has neither a name nor a known id.
    Unknown,
    Found(String, Option<usize>),
}

/// The body's free joint (a body with one has no other joint).
fn free_joint(doc: &Document, body: Node, ids: Option<&ahash::AHashMap<Node, usize>>) -> FreeJoint {
    let free =
        |j: Node| doc.tag(j) == "freejoint" || doc.attr(j, "type").map(str::trim) == Some("free");
    let Some(j) = doc
        .descendants(body)
        .filter(|&n| matches!(doc.tag(n), "joint" | "freejoint") && owner(doc, n) == Some(body))
        .find(|&j| free(j))
    else {
        return FreeJoint::None;
    };
    match doc.attr(j, "name").filter(|n| !n.is_empty()) {
        Some(name) => FreeJoint::Found(name.to_string(), None),
        None => match ids.and_then(|ids| ids.get(&j)) {
            Some(&id) => FreeJoint::Found(String::new(), Some(id)),
            None => FreeJoint::Unknown,
        },
    }
}

/// An `<option>` value as its entry (`object` "option", id 0).
fn option_entry(attr: &str, value: &str) -> Option<PatchEntry> {
    let &(field, n) = PATCHABLE_OPTIONS.iter().find(|(a, _)| *a == attr)?;
    let e = PatchEntry {
        object: "option",
        name: String::new(),
        id: Some(0),
        field,
        value: PatchValue::Numbers(numbers(value, n, false)?),
    };
    accepted(&e).then_some(e)
}

/// An actuator's gains as its entries: the whole `gainprm` and `biasprm` rows (and
/// `dynprm` for `<general>`), as the parser fills them (`mjs_setToPosition`...): a
/// `<position>`'s `kp` and `kv` are `gainprm = [kp]`, `biasprm = [0, -kp, -kv]` (`-kv`
/// only when `kv` is given: `-0` differs from `0` bit for bit), a `<velocity>`'s `kv` is
/// `gainprm = [kv]`, `biasprm = [0, 0, -kv]`, a `<general>`'s lists are written as given,
/// the rest of each row zero. A damping ratio stays structure (the compiler turns it into
/// a damping from the masses).
fn actuator_entries<'d>(doc: &'d Document, node: Node, rules: &DocRules, out: &mut Patched<'d>) {
    let (name, id) = match doc.attr(node, "name").filter(|n| !n.is_empty()) {
        Some(n) => (n.to_string(), None),
        None => match rules.actuator_ids.as_ref().and_then(|ids| ids.get(&node)) {
            Some(&id) => (String::new(), Some(id)),
            None => return,
        },
    };
    if derives_damping(doc, node) {
        return;
    }
    // A shortcut's parameter: absent, or one number the parser takes (never negative).
    let param = |attr: &str| -> Result<Option<f64>, ()> {
        match doc.attr(node, attr) {
            None => Ok(None),
            Some(t) => match numbers(t, 1, false) {
                Some(v) if v[0] >= 0.0 => Ok(Some(v[0])),
                _ => Err(()),
            },
        }
    };
    let row = |first: &[(usize, f64)]| {
        let mut v = vec![0.0; PRM];
        for &(i, x) in first {
            v[i] = x;
        }
        v
    };
    let mut carried: Vec<&'d str> = Vec::new();
    let mut rows: Vec<(&'static str, Vec<f64>)> = Vec::new();
    match doc.tag(node) {
        "position" => {
            let (Ok(kp), Ok(kv)) = (param("kp"), param("kv")) else {
                return;
            };
            carried.extend(kp.map(|_| "kp").into_iter().chain(kv.map(|_| "kv")));
            let kp = kp.unwrap_or(1.0);
            rows.push(("gainprm", row(&[(0, kp)])));
            // Without `kv` the parser leaves biasprm[2] at its +0.
            rows.push(("biasprm", row(&[(1, -kp), (2, kv.map_or(0.0, |kv| -kv))])));
        }
        "velocity" => {
            let Ok(Some(kv)) = param("kv") else {
                return;
            };
            carried.push("kv");
            rows.push(("gainprm", row(&[(0, kv)])));
            rows.push(("biasprm", row(&[(2, -kv)])));
        }
        "general" => {
            for field in ["gainprm", "biasprm", "dynprm"] {
                let Some(text) = doc.attr(node, field) else {
                    continue;
                };
                let given = text
                    .split_ascii_whitespace()
                    .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
                    .collect::<Option<Vec<f64>>>();
                if let Some(v) = given.filter(|v| !v.is_empty() && v.len() <= PRM) {
                    let pairs: Vec<(usize, f64)> = v.into_iter().enumerate().collect();
                    carried.push(field);
                    rows.push((field, row(&pairs)));
                }
            }
        }
        _ => {}
    }
    if carried.is_empty() {
        return;
    }
    out.attrs.extend(carried);
    for (field, value) in rows {
        out.entries.push(PatchEntry {
            object: "actuator",
            name: name.clone(),
            id,
            field,
            value: PatchValue::Numbers(value),
        });
    }
}

/// Values that only rendering reads: patched even where the dynamics are compiled.
fn visual(e: &PatchEntry) -> bool {
    matches!(
        (e.object, e.field),
        ("geom", "rgba" | "matid") | ("site", "rgba") | ("material", _) | ("light", _)
    ) || (e.object, e.field) == ("camera", "fovy")
}

/// Whether MuJoCo compiles the value as written (a value it refuses, or checks against
/// others, is left to the compile, which gives MuJoCo's own verdict).
fn accepted(e: &PatchEntry) -> bool {
    let PatchValue::Numbers(v) = &e.value else {
        return true;
    };
    let positive = v.iter().all(|&x| x > 0.0);
    let non_negative = v.iter().all(|&x| x >= 0.0);
    match (e.object, e.field) {
        ("body", "mass") => positive,
        // Each principal moment at most the sum of the other two.
        ("body", "inertia") => {
            positive && v.len() == 3 && (0..3).all(|i| v[i] <= v[(i + 1) % 3] + v[(i + 2) % 3])
        }
        ("joint", "damping" | "armature" | "frictionloss" | "stiffness") => non_negative,
        ("geom", "friction" | "margin" | "gap") => non_negative,
        ("camera", "fovy") => v[0] > 0.0 && v[0] < 180.0,
        ("option", "timestep" | "impratio") => positive,
        ("option", "tolerance" | "ls_tolerance" | "noslip_tolerance") => non_negative,
        ("option", "density" | "viscosity") => non_negative,
        _ => true,
    }
}
