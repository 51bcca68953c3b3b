//! The rules of a split: which attribute lands in which compiled field, exactly.
//!
//! Each rule below says which compiled field an attribute lands in, unchanged but for the
//! compiler's own arithmetic (a quaternion normalized, a number read as `float`); an
//! attribute without a rule, or an element the rule cannot name, goes into the structure
//! key instead, so its variants are compiled, never approximated. [`PATCHABLE`] lists the
//! rules; `tests/model_cache.rs`, `tests/document_cache.rs` and
//! `python/tests/test_model_cache.py` hold each against MuJoCo compiling the XML.

use crate::document::tree::Node;
use crate::document::{Document, Section};

/// One compiled value a variant sets: `model.<object>(name).<field> = value` in MuJoCo's
/// Python bindings (the named accessors), or the rows of `<object>_<field>` (`geom_rgba`,
/// `dof_damping` for a joint's `damping`...) for the element's id.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchEntry {
    /// The element's type, as MuJoCo's named accessors call it: `body`, `joint`, `geom`,
    /// `site`, `camera`, `light`, `material`.
    pub object: &'static str,
    /// The element's name in the compiled model; empty for an unnamed element, which
    /// `id` then identifies.
    pub name: String,
    /// The element's id (index among its type) in the compiled model, for an unnamed one.
    pub id: Option<usize>,
    /// The field, as the accessor calls it (`rgba`, `friction`, `mass`, `qpos0`...).
    pub field: &'static str,
    /// The value.
    pub value: PatchValue,
}

/// A patched value.
#[derive(Clone, Debug, PartialEq)]
pub enum PatchValue {
    /// Numbers exactly as the compiled model holds them (a `float` field's values are
    /// already rounded to `f32`).
    Numbers(Vec<f64>),
    /// The id of the element of type `object` named `name` (a material chosen for a geom).
    Id {
        /// The referenced element's type.
        object: &'static str,
        /// Its name.
        name: String,
    },
    /// What MuJoCo derives from an element at compile time, to be read off the compile of
    /// this MJCF model of it (a body's geoms: see
    /// [`SplitOptions::body_models`](super::SplitOptions)).
    BodyModel(String),
}

/// `(element, attribute, compiled field, components, float)`: the attributes a patch can
/// carry. `float`: the compiled field is `float` (the text is read as `f32`, as MuJoCo's
/// parser reads it). Anything else a randomizer sets is structure.
pub const PATCHABLE: &[(&str, &str, &str, usize, bool)] = &[
    ("geom", "rgba", "rgba", 4, true),
    ("geom", "friction", "friction", 3, false),
    ("geom", "solref", "solref", 2, false),
    ("geom", "solimp", "solimp", 5, false),
    ("geom", "margin", "margin", 1, false),
    ("geom", "gap", "gap", 1, false),
    ("site", "rgba", "rgba", 4, true),
    ("material", "rgba", "rgba", 4, true),
    ("material", "specular", "specular", 1, true),
    ("material", "shininess", "shininess", 1, true),
    ("material", "reflectance", "reflectance", 1, true),
    ("material", "emission", "emission", 1, true),
    ("light", "diffuse", "diffuse", 3, true),
    ("light", "specular", "specular", 3, true),
    ("light", "ambient", "ambient", 3, true),
    ("light", "attenuation", "attenuation", 3, true),
    ("joint", "damping", "damping", 1, false),
    ("joint", "armature", "armature", 1, false),
    ("joint", "frictionloss", "frictionloss", 1, false),
    ("joint", "stiffness", "stiffness", 1, false),
    ("camera", "fovy", "fovy", 1, false),
    ("inertial", "mass", "mass", 1, false),
    ("inertial", "diaginertia", "inertia", 3, false),
    ("body", "pos", "pos", 3, false),
    ("body", "quat", "quat", 4, false),
];

/// What holds for the whole scene, decided once: which rules its compiler settings and
/// sections allow.
#[derive(Debug)]
pub(crate) struct Rules {
    /// Masses and inertias land unchanged (no `settotalmass`, bounds, balancing, or
    /// inertia from geoms over `<inertial>`).
    pub(crate) mass: bool,
    /// Body frames land unchanged (no static bodies fused away; no free bodies aligned
    /// with their inertial frames; with keyframes, no free joint or mocap body of the
    /// template, whose rows a key may give or take from the body, and no keyframe in a
    /// part).
    pub(crate) poses: bool,
    /// The model has keyframes: a placed object's free joint's rows in each of them are
    /// its pose (the merge writes them so; MuJoCo normalizes the quaternion), patched with
    /// it (`key_qpos` entries).
    pub(crate) keys: bool,
    /// A joint's armature lands unchanged and nothing derived from it stays stale (no
    /// damping ratio, no actuator that adds armature to its joint).
    pub(crate) armature: bool,
    /// A joint's damping lands unchanged (no actuator adds damping to its joint).
    pub(crate) damping: bool,
    /// A geom's size, frame, density or mass is carried by its body model
    /// (`body_model`): masses land unchanged, every geom of the compiled model is one of
    /// the document (no `discardvisual`), and no spatial tendon, flex, composite or skin
    /// hangs on a geom's size or a body's inertia.
    pub(crate) body_models: bool,
    /// Compiled ids of the template's elements that can be patched unnamed, when nothing
    /// reorders them (see [`template_ids`]).
    pub(crate) ids: Option<ahash::AHashMap<Node, usize>>,
    /// Variants are compiled with `discardvisual`: visual geoms and every material are
    /// not in the compiled model.
    pub(crate) discard: bool,
}

impl Rules {
    pub(crate) fn new(template: &Document, parts: &[&Document], discard: bool) -> Rules {
        let setting = |name: &str| setting(template, "compiler", name);
        let mass = setting("settotalmass").is_none_or(|v| v.trim().parse() == Ok(-1.0))
            && setting("boundmass").is_none_or(|v| v.trim().parse() == Ok(0.0))
            && setting("boundinertia").is_none_or(|v| v.trim().parse() == Ok(0.0))
            && setting("balanceinertia").is_none_or(|v| v.trim() == "false")
            && setting("inertiafromgeom").is_none_or(|v| v.trim() != "true");
        let has_keys = |d: &Document| {
            d.find_section(Section::Keyframe)
                .is_some_and(|k| d.elements(k).next().is_some())
        };
        // A free body MuJoCo aligns with its inertial frame lands in the inertial frame's
        // pose, which only the compiler knows.
        let aligned = |d: &Document| d.descendants(d.root()).any(|n| d.aligns_free_body(n));
        // With keyframes, a key's rows for the template's free joints and mocap bodies may
        // be its own or the body's; the parts' rows are written from their poses by the
        // merge (and a part's own keyframes are its author's).
        let keys = has_keys(template) || parts.iter().any(|d| has_keys(d));
        let follows_keys = |d: &Document| {
            d.descendants(d.root()).any(|n| {
                d.tag(n) == "freejoint"
                    || (d.tag(n) == "joint" && d.attr(n, "type").map(str::trim) == Some("free"))
                    || (d.tag(n) == "body" && d.attr(n, "mocap").map(str::trim) == Some("true"))
            })
        };
        let mocap = |d: &Document| {
            d.descendants(d.root())
                .any(|n| d.tag(n) == "body" && d.attr(n, "mocap").map(str::trim) == Some("true"))
        };
        let keys_follow_poses = !keys
            || (!follows_keys(template)
                && !parts.iter().any(|d| has_keys(d))
                && !parts.iter().any(|d| mocap(d)));
        let poses = setting("fusestatic").is_none_or(|v| v.trim() == "false")
            && keys_follow_poses
            && !aligned(template)
            && !parts.iter().any(|d| aligned(d));
        let all = || {
            std::iter::once(template)
                .chain(parts.iter().copied())
                .flat_map(|d| d.descendants(d.root()).map(move |n| (d, n)))
        };
        // A dampratio actuator's damping is derived from the masses and the joint-space
        // inertia at qpos0 (armature included) at compile time.
        let dampratio = all().any(|(d, n)| derives_damping(d, n));
        // A spatial tendon's spring length is its length at qpos0, which mj_setConst of
        // 3.17.0 and 4.0.0 leaves as compiled; flexes and composites hang on body frames.
        let hanging = all().any(|(d, n)| {
            matches!(d.tag(n), "spatial" | "flex" | "flexcomp" | "composite")
                || (d.tag(n) == "skin" && d.elements(n).next().is_some())
        });
        // Static bodies, with their masses and elements, are fused into their parents.
        let fused = setting("fusestatic").is_some_and(|v| v.trim() == "true");
        // An actuator's own armature or damping is added to its joint's.
        let actuated = |a: &str| {
            all().any(|(d, n)| {
                d.parent(n).is_some_and(|p| d.tag(p) == "actuator") && d.attr(n, a).is_some()
            })
        };
        // Objects merged in bring only bodies to the world (their elements come after the
        // template's), unless a part has world-level elements of its own.
        let world_level = parts.iter().any(|d| {
            d.worldbody().is_some_and(|w| {
                d.descendants(w)
                    .any(|n| ID_KINDS.contains(&d.tag(n)) && owner(d, n) == Some(w))
            })
        });
        Rules {
            mass: mass && !dampratio && !fused,
            poses: poses && !dampratio && !hanging,
            keys,
            armature: !dampratio && !actuated("armature"),
            damping: !actuated("damping"),
            body_models: mass && !dampratio && !fused && !discard && !hanging,
            ids: (!world_level && !fused)
                .then(|| template_ids(template, discard))
                .flatten(),
            discard,
        }
    }
}

/// Whether an actuator's damping is a damping ratio, which the compiler turns into a
/// damping from the masses at `qpos0` (`mj_setConst` of 3.17.0 does not redo it): a
/// `dampratio`, or, as a position shortcut with one is written as `<general>`, an affine
/// bias whose third parameter is positive.
pub(crate) fn derives_damping(doc: &Document, node: Node) -> bool {
    if doc.attr(node, "dampratio").is_some() {
        return true;
    }
    doc.attr(node, "biastype").map(str::trim) == Some("affine")
        && doc
            .attr(node, "biasprm")
            .and_then(|v| v.split_ascii_whitespace().nth(2))
            .is_some_and(|t| t.parse::<f64>().map_or(true, |x| x > 0.0))
}

/// The element types an unnamed element of the template can be patched by id.
const ID_KINDS: [&str; 6] = ["geom", "site", "camera", "light", "joint", "freejoint"];

/// Whether a body has neither `<inertial>` nor geoms of its own: it has no mass, and MuJoCo
/// gives it its own frame as inertial frame (seen in 3.17.0 and 4.0.0).
pub(crate) fn massless(doc: &Document, body: Node) -> bool {
    !doc.descendants(body).any(|n| {
        n != body && matches!(doc.tag(n), "inertial" | "geom") && owner(doc, n) == Some(body)
    })
}

/// The body an element belongs to: its nearest body or world body, through frames.
pub(crate) fn owner(doc: &Document, node: Node) -> Option<Node> {
    let mut at = doc.parent(node)?;
    while doc.tag(at) == "frame" {
        at = doc.parent(at)?;
    }
    matches!(doc.tag(at), "body" | "worldbody").then_some(at)
}

/// Whether MuJoCo's `discardvisual` drops this geom: `contype` and `conaffinity` both 0,
/// no ellipsoid fluid model (MuJoCo's reference, `compiler/discardvisual`). `None` when it
/// is visual but named in another element (contact pairs, sensors, tendons), which keeps
/// it: such a geom is left to the compile.
pub(crate) fn discarded(doc: &Document, geom: Node) -> Option<bool> {
    let zero = |a: &str| doc.attr(geom, a).is_some_and(|v| v.trim() == "0");
    let visual = zero("contype")
        && zero("conaffinity")
        && doc.attr(geom, "fluidshape").map(str::trim) != Some("ellipsoid");
    if !visual {
        return Some(false);
    }
    let Some(name) = doc.attr(geom, "name").filter(|n| !n.is_empty()) else {
        return Some(true);
    };
    let referenced = doc
        .elements(doc.root())
        .filter(|&s| matches!(doc.tag(s), "contact" | "sensor" | "tendon" | "equality"))
        .flat_map(|s| doc.descendants(s))
        .any(|n| doc.attrs(n).any(|(k, v)| k != "name" && v == name));
    (!referenced).then_some(true)
}

/// Compiled ids of the template's geoms, sites, cameras, lights and joints: MuJoCo
/// numbers bodies depth first in document order and each body's elements (through frames)
/// in document order, body after body (with `discard`, the geoms `discardvisual` drops
/// take no id). `None` when the template has what changes that order (`replicate`,
/// `attach`, an `include` left unexpanded, `composite`, `flexcomp`).
fn template_ids(template: &Document, discard: bool) -> Option<ahash::AHashMap<Node, usize>> {
    let world = template.worldbody()?;
    let mut order = ahash::AHashMap::new();
    order.insert(world, 0usize);
    let mut elements: Vec<(usize, usize, Node)> = Vec::new();
    for n in template.descendants(world) {
        let tag = template.tag(n);
        // Each of these makes elements the arena does not hold (composite and flexcomp
        // make bodies, geoms and sites of their own).
        if matches!(
            tag,
            "replicate" | "attach" | "include" | "composite" | "flexcomp"
        ) {
            return None;
        }
        if tag == "body" {
            let next = order.len();
            order.insert(n, next);
        } else if let Some(kind) = ID_KINDS.iter().position(|k| *k == tag) {
            if discard && tag == "geom" && discarded(template, n)? {
                continue;
            }
            let body = owner(template, n)?;
            // joint and freejoint share one numbering.
            elements.push((*order.get(&body)?, kind.min(4), n));
        }
    }
    // Stable: within a body, document order.
    elements.sort_by_key(|&(body, _, _)| body);
    let mut ids = ahash::AHashMap::new();
    let mut next = [0usize; 5];
    for (_, kind, n) in elements {
        ids.insert(n, next[kind]);
        next[kind] += 1;
    }
    Some(ids)
}

/// The value of `attr` on the root's `tag` elements (`compiler`, `statistic`), the last
/// one that sets it winning, as MuJoCo reads repeated elements.
pub(crate) fn setting<'d>(doc: &'d Document, tag: &str, attr: &str) -> Option<&'d str> {
    doc.elements(doc.root())
        .filter(|&n| doc.tag(n) == tag)
        .filter_map(|n| doc.attr(n, attr))
        .last()
}

/// Under `discardvisual`: whether the value lands nowhere (every material, a discarded
/// geom, a geom's material: `Some(true)`), or is left to the compile (a visual geom that
/// another element names: `None`).
pub(crate) fn dropped(doc: &Document, node: Node, attr: &str) -> Option<bool> {
    // Materials stay when a sensor or a custom tuple names one: then leave them to the
    // compile.
    let materials_kept = || {
        doc.find_section(Section::Custom).is_some()
            || doc
                .find_section(Section::Sensor)
                .is_some_and(|s| doc.descendants(s).any(|n| doc.attr(n, "objtype").is_some()))
    };
    match doc.tag(node) {
        "material" | "geom" if (doc.tag(node) == "material" || attr == "material") => {
            (!materials_kept()).then_some(true)
        }
        "geom" => discarded(doc, node),
        _ => Some(false),
    }
}

/// The patch entry for `attr = value` on `node`, or `None` when it is structure.
/// `placed_root`: the node is a placed object's root body, whose written orientation is
/// its `quat` alone (placement clears the others).
pub(crate) fn entry(
    doc: &Document,
    node: Node,
    attr: &str,
    value: &str,
    rules: &Rules,
    ids: Option<&ahash::AHashMap<Node, usize>>,
    placed_root: bool,
) -> Option<PatchEntry> {
    let tag = doc.tag(node);
    // The element's name, or for an unnamed one its compiled id.
    let named = |n: Node| -> Option<(String, Option<usize>)> {
        match doc.attr(n, "name").filter(|s| !s.is_empty()) {
            Some(name) => Some((name.to_string(), None)),
            None => Some((String::new(), Some(*ids?.get(&n)?))),
        }
    };
    if tag == "geom" && attr == "material" {
        let (name, id) = named(node)?;
        return Some(PatchEntry {
            object: "geom",
            name,
            id,
            field: "matid",
            value: PatchValue::Id {
                object: "material",
                name: value.to_string(),
            },
        });
    }
    let &(_, _, field, n, float) = PATCHABLE
        .iter()
        .find(|(k, a, ..)| *k == tag && *a == attr)?;
    if (tag, attr) == ("joint", "armature") && !rules.armature
        || (tag, attr) == ("joint", "damping") && !rules.damping
    {
        return None;
    }
    let (object, (name, id)) = match tag {
        "inertial" => {
            if !rules.mass || doc.attr(node, "fullinertia").is_some() {
                return None;
            }
            let body = doc.parent(node)?;
            ("body", (doc.attr(body, "name")?.to_string(), None))
        }
        "body" => {
            // A frame relative to the world or a parent body, on a body that exists.
            let parent = doc.parent(node)?;
            if !rules.poses
                || !matches!(doc.tag(parent), "body" | "worldbody")
                || (!placed_root
                    && ["euler", "axisangle", "xyaxes", "zaxis"]
                        .iter()
                        .any(|a| doc.attr(node, a).is_some()))
            {
                return None;
            }
            ("body", (doc.attr(node, "name")?.to_string(), None))
        }
        // A spring-damper's stiffness and damping are derived from its own attributes.
        "joint" if doc.attr(node, "springdamper").is_some() => return None,
        "camera" if doc.attr(node, "sensorsize").is_some() => return None,
        "material" => ("material", (doc.attr(node, "name")?.to_string(), None)),
        _ => (object_of(tag), named(node)?),
    };
    if name.is_empty() && id.is_none() {
        return None;
    }
    let mut v = numbers(value, n, float)?;
    if attr == "quat" {
        v = normalized(v);
    }
    Some(PatchEntry {
        object,
        name,
        id,
        field,
        value: PatchValue::Numbers(v),
    })
}

fn object_of(tag: &str) -> &'static str {
    match tag {
        "geom" => "geom",
        "site" => "site",
        "material" => "material",
        "light" => "light",
        "joint" => "joint",
        "camera" => "camera",
        _ => "body",
    }
}

/// The body's free joint's name, when its only joint is a named free joint.
pub(crate) fn free_joint(doc: &Document, body: Node) -> Option<&str> {
    let mut joints = doc
        .elements(body)
        .filter(|&k| matches!(doc.tag(k), "joint" | "freejoint"));
    let j = joints.next()?;
    let free = doc.tag(j) == "freejoint" || doc.attr(j, "type").map(str::trim) == Some("free");
    (free && joints.next().is_none())
        .then(|| doc.attr(j, "name"))
        .flatten()
}

/// Exactly `n` numbers, each as MuJoCo reads it (`f32` for a `float` field).
pub(crate) fn numbers(text: &str, n: usize, float: bool) -> Option<Vec<f64>> {
    let v: Vec<f64> = text
        .split_ascii_whitespace()
        .map(|t| {
            if float {
                t.parse::<f32>().ok().map(f64::from)
            } else {
                t.parse::<f64>().ok()
            }
        })
        .collect::<Option<_>>()?;
    (v.len() == n && v.iter().all(|x| x.is_finite())).then_some(v)
}

/// A quaternion normalized as MuJoCo's compiler does (`mjuu_normvec`, `mjEPS` = 1e-14):
/// left alone when its norm is within 1e-14 of 1 (3.17.0 and 4.0.0 both keep
/// `quat="1.0000000000000002 0 0 0"` as written).
pub(crate) fn normalized(q: Vec<f64>) -> Vec<f64> {
    const EPS: f64 = 1e-14;
    let squares = q.iter().fold(0.0, |acc, x| acc + x * x);
    if squares < EPS {
        return q;
    }
    let norm = squares.sqrt();
    if (norm - 1.0).abs() <= EPS {
        return q;
    }
    q.iter().map(|x| x / norm).collect()
}
