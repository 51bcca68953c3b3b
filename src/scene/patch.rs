//! A scene's variant as a *structure* and a *patch*: what decides the compiled model's
//! sizes, topology and asset contents (which object is placed in which slot, every value
//! that cannot be written into a compiled model exactly), and the values that can (a
//! placed object's pose, colours, frictions, masses...). Variants with the same structure
//! key compile to models that differ only in the patched values and what MuJoCo's
//! `mj_setConst` derives from them, so one compiled model per structure serves them all.
//! The rules are the split tier's ([`crate::split`]); this file reads a drawn variant's
//! values through them.

use super::Drawn;
use super::randomize::AttrTarget;
use crate::document::tree::Node;
use crate::split::{
    PatchEntry, PatchValue, Rules, body_model_entries, carried_by, dropped, entry, free_joint,
    massless, normalized, numbers, unit_model_entries,
};

/// Variant `index` as a structure key and a patch (see [`super::Scene::patch`]).
#[derive(Clone, Debug, PartialEq)]
pub struct VariantPatch {
    /// The variant's index.
    pub index: u64,
    /// Equal for two variants of one scene exactly when their compiled models differ only
    /// in the patched fields (and what `mj_setConst` derives from them): 32 hex digits.
    pub structure_key: String,
    /// The values that turn a compiled model of this structure into this variant's.
    pub entries: Vec<PatchEntry>,
}

/// Splits a drawn variant into its structure key and its patch.
pub(crate) fn split(
    fingerprint: &[u8; 32],
    rules: &Rules,
    index: u64,
    drawn: &Drawn<'_>,
) -> VariantPatch {
    split_parts(fingerprint, rules, index, drawn).0
}

/// A randomized value that went into the key: its part (0: the template, k: placed
/// object k - 1), element and attribute.
pub(crate) type Refused = (usize, Node, String);

/// [`split`], with per entry the part it came from (0: the template, k: placed object
/// k - 1) and the values that went into the key (values, not object choices).
pub(crate) fn split_parts(
    fingerprint: &[u8; 32],
    rules: &Rules,
    index: u64,
    drawn: &Drawn<'_>,
) -> (VariantPatch, Vec<usize>, Vec<Refused>) {
    let mut key = blake3::Hasher::new();
    key.update(fingerprint);
    let mut entries = Vec::new();
    let mut parts = Vec::new();
    let mut in_key = Vec::new();
    for o in &drawn.params.objects {
        for s in [o.group.as_str(), &o.slot.to_string(), &o.model] {
            key.update(&(s.len() as u64).to_le_bytes());
            key.update(s.as_bytes());
        }
    }
    let overlays = std::iter::once((&drawn.template, None))
        .chain(drawn.placed.iter().map(|(inst, o)| (o, Some(inst.root))));
    for (part, (overlay, root)) in overlays.enumerate() {
        let doc = overlay.doc;
        // Unnamed elements are known by id in the template only.
        let ids = if part == 0 { rules.ids.as_ref() } else { None };
        let mut bodies: Vec<Node> = Vec::new();
        // Bodies whose body models carry randomized values of their geoms, and those
        // values.
        let mut modelled: Vec<Node> = Vec::new();
        let mut carried: Vec<(Node, Node, &str, &str)> = Vec::new();
        for (node, attr, value) in &overlay.values {
            if rules.discard && dropped(doc, *node, attr) == Some(true) {
                // Not in the compiled model: its value changes nothing.
                continue;
            }
            if rules.body_models
                && let Some(body) = carried_by(doc, *node, attr)
            {
                if !modelled.contains(&body) {
                    modelled.push(body);
                }
                carried.push((body, *node, attr, value));
                continue;
            }
            let structural = rules.discard && dropped(doc, *node, attr).is_none();
            match entry(doc, *node, attr, value, rules, ids, root == Some(*node))
                .filter(|_| !structural)
            {
                Some(e) => {
                    if e.object == "body" && !bodies.contains(node) {
                        bodies.push(*node);
                    }
                    entries.push(e);
                    parts.push(part);
                }
                None => {
                    in_key.push((part, *node, attr.clone()));
                    key.update(&(part as u64).to_le_bytes());
                    key.update(&(crate::document::tree::Tree::index(*node) as u64).to_le_bytes());
                    for s in [attr.as_str(), value.as_str()] {
                        key.update(&(s.len() as u64).to_le_bytes());
                        key.update(s.as_bytes());
                    }
                }
            }
        }
        // Bodies whose geoms' densities and masses alone vary: their unit models (compiled
        // once), the values read through the overlay (no copy of the document).
        modelled.retain(|&body| {
            let masses_only = carried
                .iter()
                .filter(|c| c.0 == body)
                .all(|c| matches!(c.2, "density" | "mass"));
            let value = |n: Node, a: &str| overlay.get(n, a).map(str::to_string);
            let made = match doc.attr(body, "name") {
                Some(name) if masses_only => unit_model_entries(doc, body, name, &value, None),
                _ => None,
            };
            match made {
                Some(made) => {
                    parts.extend(std::iter::repeat_n(part, made.len()));
                    entries.extend(made);
                    false
                }
                None => true,
            }
        });
        if !modelled.is_empty() {
            let mut applied = doc.clone();
            overlay.apply_to(&mut applied);
            for body in modelled {
                if let Some(name) = applied.attr(body, "name")
                    && let Some(made) = body_model_entries(&applied, body, name.to_string())
                {
                    parts.extend(std::iter::repeat_n(part, made.len()));
                    entries.extend(made);
                    continue;
                }
                // No body model after all: its values are structure.
                for &(_, node, attr, value) in carried.iter().filter(|c| c.0 == body) {
                    in_key.push((part, node, attr.to_string()));
                    key.update(&(part as u64).to_le_bytes());
                    key.update(&(crate::document::tree::Tree::index(node) as u64).to_le_bytes());
                    for s in [attr, value] {
                        key.update(&(s.len() as u64).to_le_bytes());
                        key.update(s.as_bytes());
                    }
                }
            }
        }
        // A free joint's qpos0 (and qpos_spring) is its body's frame.
        for body in bodies {
            let get = |a: &str| {
                overlay
                    .values
                    .iter()
                    .rev()
                    .find(|(n, at, _)| *n == body && at == a)
                    .map(|(_, _, v)| v.as_str())
                    .or_else(|| doc.attr(body, a))
            };
            let pos = numbers(get("pos").unwrap_or("0 0 0"), 3, false);
            let quat = numbers(get("quat").unwrap_or("1 0 0 0"), 4, false).map(normalized);
            // A frame the rules could not read stayed structure (its body entry too).
            let (Some(pos), Some(quat)) = (pos, quat) else {
                continue;
            };
            // A body with neither <inertial> nor geoms has no mass, and MuJoCo gives it
            // its own frame as inertial frame (seen in 3.17.0 and 4.0.0).
            if massless(doc, body)
                && let Some(name) = doc.attr(body, "name")
            {
                for (field, v) in [("ipos", &pos), ("iquat", &quat)] {
                    entries.push(PatchEntry {
                        object: "body",
                        name: name.to_string(),
                        id: None,
                        field,
                        value: PatchValue::Numbers(v.clone()),
                    });
                    parts.push(part);
                }
            }
            let Some(joint) = free_joint(doc, body) else {
                continue;
            };
            let qpos: Vec<f64> = pos.into_iter().chain(quat).collect();
            let fields: &[&'static str] = if rules.keys {
                &["qpos0", "qpos_spring", "key_qpos"]
            } else {
                &["qpos0", "qpos_spring"]
            };
            for &field in fields {
                entries.push(PatchEntry {
                    object: "joint",
                    name: joint.to_string(),
                    id: None,
                    field,
                    value: PatchValue::Numbers(qpos.clone()),
                });
                parts.push(part);
            }
        }
    }
    // The patch's layout too, so that one key always means one list of targets (a model
    // cache resolves a structure's targets once).
    for e in &entries {
        for s in [e.object, e.name.as_str(), e.field] {
            key.update(&(s.len() as u64).to_le_bytes());
            key.update(s.as_bytes());
        }
        key.update(&e.id.map_or(u64::MAX, |i| i as u64).to_le_bytes());
    }
    let hash = key.finalize();
    let patch = VariantPatch {
        index,
        structure_key: hash.to_hex()[..32].to_string(),
        entries,
    };
    (patch, parts, in_key)
}
