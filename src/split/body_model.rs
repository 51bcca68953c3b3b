//! A body's geoms as a model of their own: what a document patch carries for a body whose
//! primitive geoms change size, so that a model cache can read off that body model's
//! compile what MuJoCo derives from the sizes (each geom's size, bounding radius and box,
//! the body's mass, inertia and inertial frame, its bounding-volume tree) and write it
//! into the compiled model of the whole structure.
//!
//! All of those are computed by the compiler from the body's own geoms in the body's own
//! frame, under the `<compiler>` settings, and from nothing else of the model, so the
//! body model (the `<compiler>`, one body at the world's origin holding the body's
//! `<inertial>` and geoms as written, without names, materials or user data) gives the
//! same numbers, bit for bit (`tests` of `compiled` and the Python cache judge it against
//! MuJoCo's compile of the whole document).
//!
//! A body qualifies only when its body model is complete: every child is a geom that
//! needs no asset (no mesh, height field or signed distance field), a joint, a site, a
//! camera, a light, an `<inertial>` or a body; no free joint of it makes MuJoCo align the
//! body with its inertial frame (which moves the body). Whether the whole document allows
//! it (masses that land unchanged, no spatial tendon wrapping a geom...) is the caller's.

use crate::document::Document;
use crate::document::tree::Node;
use crate::document::write::escape_attr;

use super::rules::{PatchEntry, PatchValue};
use super::targets::GEOM_FACTORS;

/// Geom types whose `size` alone sets their shape (with the type's defaults).
const PRIMITIVES: [&str; 5] = ["sphere", "capsule", "ellipsoid", "cylinder", "box"];

/// Children a body may have for its body model to be complete.
const KNOWN_CHILDREN: [&str; 8] = [
    "geom",
    "joint",
    "freejoint",
    "site",
    "camera",
    "light",
    "inertial",
    "body",
];

/// Geom attributes the body model leaves out: they name or reference what it does not
/// have, or set contact and looks, and the compiler derives nothing of the geom's shape,
/// bounds or mass from them (so a variant that randomizes them finds its body model
/// compiled already).
const LEFT_OUT: [&str; 12] = [
    "name",
    "material",
    "user",
    "class",
    "rgba",
    "friction",
    "solref",
    "solimp",
    "solmix",
    "priority",
    "condim",
    "fluidcoef",
];

/// Whether `geom`'s `size` can be patched through its body model: a primitive
/// type, sized by `size` (not `fromto`).
pub(crate) fn sized_primitive(doc: &Document, geom: Node) -> bool {
    doc.tag(geom) == "geom"
        && doc.attr(geom, "size").is_some()
        && doc.attr(geom, "fromto").is_none()
        && PRIMITIVES.contains(&doc.attr(geom, "type").map_or("sphere", str::trim))
}

/// Geom attributes a body model carries into the compiled model: sizes, frames,
/// densities and masses (what MuJoCo derives from them is what the body model compiles
/// to).
const CARRIED: [&str; 9] = [
    "size",
    "pos",
    "quat",
    "euler",
    "axisangle",
    "xyaxes",
    "zaxis",
    "density",
    "mass",
];

/// The body whose body model carries `attr` of `node`: a geom's size (a sized
/// primitive) or frame, in a body that [`qualifies`]; its density or mass, in a body whose
/// body model is [`complete`] (frames and meshes included).
pub(crate) fn carried_by(doc: &Document, node: Node, attr: &str) -> Option<Node> {
    if doc.tag(node) != "geom" || !CARRIED.contains(&attr) {
        return None;
    }
    let body = owner(doc, node)?;
    if matches!(attr, "density" | "mass") {
        return complete(doc, body).then_some(body);
    }
    if needs_asset(doc, node)
        || doc.attr(node, "fromto").is_some()
        || (attr == "size" && !sized_primitive(doc, node))
        || doc.parent(node) != Some(body)
    {
        return None;
    }
    qualifies(doc, body).then_some(body)
}

/// The body a geom belongs to: its parent, through any `<frame>`s.
fn owner(doc: &Document, geom: Node) -> Option<Node> {
    let mut at = doc.parent(geom)?;
    while doc.tag(at) == "frame" {
        at = doc.parent(at)?;
    }
    (doc.tag(at) == "body").then_some(at)
}

/// Whether a geom needs an asset (a mesh, height field or signed distance field).
fn needs_asset(doc: &Document, geom: Node) -> bool {
    doc.attr(geom, "mesh").is_some()
        || doc.attr(geom, "hfield").is_some()
        || matches!(
            doc.attr(geom, "type").map(str::trim),
            Some("mesh" | "hfield" | "sdf")
        )
}

/// A mesh geom whose body model can hold its mesh: the `<mesh>` asset it names, with no
/// plugin (a height field or signed distance field is not carried).
fn mesh_asset(doc: &Document, geom: Node) -> Option<Node> {
    if doc.attr(geom, "hfield").is_some()
        || !matches!(doc.attr(geom, "type").map(str::trim), Some("mesh") | None)
    {
        return None;
    }
    let name = doc.attr(geom, "mesh")?.trim();
    let stem = |file: &str| {
        let base = file.rsplit(['/', '\\']).next().unwrap_or(file);
        base.rsplit_once('.').map_or(base, |(s, _)| s).to_string()
    };
    doc.elements(doc.root())
        .filter(|&n| doc.tag(n) == "asset")
        .flat_map(|a| doc.elements(a))
        .filter(|&m| doc.tag(m) == "mesh")
        .find(|&m| match doc.attr(m, "name") {
            Some(n) => n.trim() == name,
            None => doc.attr(m, "file").is_some_and(|f| stem(f) == name),
        })
        .filter(|&m| doc.elements(m).next().is_none())
}

/// The body model of `body` (see the module), if the body model is
/// [`complete`].
pub(crate) fn body_model(doc: &Document, body: Node) -> Option<String> {
    if !complete(doc, body) {
        return None;
    }
    let mut xml = String::from("<mujoco>");
    let compilers: Vec<Node> = doc
        .elements(doc.root())
        .filter(|&n| doc.tag(n) == "compiler")
        .collect();
    push_compilers(doc, &compilers, &mut xml);
    let mut meshes: Vec<Node> = Vec::new();
    let mut inner = String::new();
    push_children(doc, body, &mut inner, &mut meshes);
    push_meshes(doc, &meshes, &mut xml);
    xml.push_str("<worldbody><body>");
    xml.push_str(&inner);
    xml.push_str("</body></worldbody></mujoco>");
    Some(xml)
}

/// The entry of `body` (named `name` in the compiled model) for what its geoms derive:
/// its body model (`geoms`), when it has one. (Bodies whose geoms' densities and masses
/// alone vary take [`unit_model_entries`] instead.)
pub(crate) fn body_model_entries(
    doc: &Document,
    body: Node,
    name: String,
) -> Option<Vec<PatchEntry>> {
    Some(vec![PatchEntry {
        object: "body",
        name,
        id: None,
        field: "geoms",
        value: PatchValue::BodyModel(body_model(doc, body)?),
    }])
}

/// Unit models' text already made, by body (its node's index) and which of its geoms set a
/// mass (all the text depends on besides the document): a superset's variants make the
/// same ones again and again.
pub(crate) type UnitCache = std::sync::Mutex<ahash::AHashMap<(usize, Vec<bool>), String>>;

/// The unit model's entries of `body` (named `name`), its geoms' densities and masses
/// read through `value` (a variant's values over the document's: no copy of the document
/// with them applied is needed, since the unit model's text holds none of them), its text
/// kept in `cache` when given.
pub(crate) fn unit_model_entries(
    doc: &Document,
    body: Node,
    name: &str,
    value: &dyn Fn(Node, &str) -> Option<String>,
    cache: Option<&UnitCache>,
) -> Option<Vec<PatchEntry>> {
    let (unit, factors) = unit_model(doc, body, value, cache)?;
    let entry = |field: &'static str, value: PatchValue| PatchEntry {
        object: "body",
        name: name.to_string(),
        id: None,
        field,
        value,
    };
    Some(vec![
        entry("unit_geoms", PatchValue::BodyModel(unit)),
        entry(GEOM_FACTORS, PatchValue::Numbers(factors)),
    ])
}

/// The unit model of `body` and its geoms' factors: every geom that counts for its
/// inertia (its group in the compiler's `inertiagrouprange`), in order, alone in a body of
/// its own (inside its `<frame>`s) at `density="1"` (or `mass="1"` where it sets a mass),
/// and each one's density (MuJoCo's 1000 where unset) or mass. A geom's mass and inertia
/// are linear in those, so one compile of the unit model serves every variant whose
/// geoms differ in them alone ([`write_geom_masses`](super::write_geom_masses)). `None`
/// when the body model is not [`complete`], the body has an `<inertial>` or the compiler
/// does not take inertias from geoms the default way, or a number does not read. The
/// geoms' `mass` and `density` are read through `value`; the text is kept in `cache`.
pub(crate) fn unit_model(
    doc: &Document,
    body: Node,
    value: &dyn Fn(Node, &str) -> Option<String>,
    cache: Option<&UnitCache>,
) -> Option<(String, Vec<f64>)> {
    if !complete(doc, body) || doc.elements(body).any(|c| doc.tag(c) == "inertial") {
        return None;
    }
    let compilers: Vec<Node> = doc
        .elements(doc.root())
        .filter(|&n| doc.tag(n) == "compiler")
        .collect();
    let setting = |attr: &str| compilers.iter().rev().find_map(|&c| doc.attr(c, attr));
    if setting("inertiafromgeom").is_some_and(|v| v.trim() != "auto") {
        return None;
    }
    let range: Vec<i64> = match setting("inertiagrouprange") {
        Some(v) => v
            .split_whitespace()
            .map(|x| x.parse().ok())
            .collect::<Option<_>>()?,
        None => vec![0, 5],
    };
    let [low, high] = range[..] else {
        return None;
    };
    let mut geoms: Vec<(Node, Vec<Node>)> = Vec::new();
    collect_geoms(doc, body, &mut Vec::new(), &mut geoms);
    // The geoms that count, whether each sets a mass, and its density or mass.
    let mut counted = Vec::new();
    let (mut masses, mut factors) = (Vec::new(), Vec::new());
    for (geom, frames) in geoms {
        let group: i64 = match doc.attr(geom, "group") {
            Some(g) => g.trim().parse().ok()?,
            None => 0,
        };
        if group < low || group > high {
            continue;
        }
        let (mass, factor) = match (
            value(geom, "mass").as_deref(),
            value(geom, "density").as_deref(),
        ) {
            (Some(m), _) => (true, m.trim().parse().ok()?),
            (None, Some(d)) => (false, d.trim().parse().ok()?),
            (None, None) => (false, 1000.0),
        };
        counted.push((geom, frames));
        masses.push(mass);
        factors.push(factor);
    }
    if factors.is_empty() {
        return None;
    }
    let key = (crate::document::tree::Tree::index(body), masses);
    if let Some(text) = cache.and_then(|c| c.lock().ok()?.get(&key).cloned()) {
        return Some((text, factors));
    }
    let mut xml = String::from("<mujoco>");
    push_compilers(doc, &compilers, &mut xml);
    let mut meshes: Vec<Node> = Vec::new();
    let mut bodies = String::new();
    for ((geom, frames), &mass) in counted.iter().zip(&key.1) {
        if let Some(mesh) = mesh_asset(doc, *geom)
            && !meshes.contains(&mesh)
        {
            meshes.push(mesh);
        }
        bodies.push_str("<body>");
        for &frame in frames {
            bodies.push_str("<frame");
            for (a, v) in doc.attrs(frame) {
                if !LEFT_OUT.contains(&a) && a != "childclass" {
                    push_attr(&mut bodies, a, v);
                }
            }
            bodies.push('>');
        }
        bodies.push_str("<geom");
        for (a, v) in doc.attrs(*geom) {
            if !LEFT_OUT.contains(&a) && !matches!(a, "mass" | "density") {
                push_attr(&mut bodies, a, v);
            }
        }
        push_attr(&mut bodies, if mass { "mass" } else { "density" }, "1");
        bodies.push_str("/>");
        for _ in frames {
            bodies.push_str("</frame>");
        }
        bodies.push_str("</body>");
    }
    push_meshes(doc, &meshes, &mut xml);
    xml.push_str("<worldbody>");
    xml.push_str(&bodies);
    xml.push_str("</worldbody></mujoco>");
    if let Some(mut held) = cache.and_then(|c| c.lock().ok()) {
        held.insert(key, xml.clone());
    }
    Some((xml, factors))
}

/// The document's `<compiler>`s as a body or unit model has them: their folders left out
/// (mesh files are absolute, as documents are loaded, so the folders do not matter).
fn push_compilers(doc: &Document, compilers: &[Node], xml: &mut String) {
    for &compiler in compilers {
        xml.push_str("<compiler");
        for (attr, value) in doc.attrs(compiler) {
            if !matches!(attr, "meshdir" | "texturedir" | "assetdir") {
                push_attr(xml, attr, value);
            }
        }
        xml.push_str("/>");
    }
}

/// The `<mesh>` assets a body or unit model's geoms use, as written.
fn push_meshes(doc: &Document, meshes: &[Node], xml: &mut String) {
    if meshes.is_empty() {
        return;
    }
    xml.push_str("<asset>");
    for &mesh in meshes {
        xml.push_str("<mesh");
        for (attr, value) in doc.attrs(mesh) {
            push_attr(xml, attr, value);
        }
        xml.push_str("/>");
    }
    xml.push_str("</asset>");
}

/// The geoms of `node` in document order, each with the `<frame>`s around it.
fn collect_geoms(
    doc: &Document,
    node: Node,
    frames: &mut Vec<Node>,
    out: &mut Vec<(Node, Vec<Node>)>,
) {
    for child in doc.elements(node) {
        match doc.tag(child) {
            "geom" => out.push((child, frames.clone())),
            "frame" => {
                frames.push(child);
                collect_geoms(doc, child, frames, out);
                frames.pop();
            }
            _ => {}
        }
    }
}

/// Writes the `<inertial>`, geoms and `<frame>`s (with their geoms) of `node` as the body
/// model has them, collecting the meshes its geoms use.
fn push_children(doc: &Document, node: Node, xml: &mut String, meshes: &mut Vec<Node>) {
    for child in doc.elements(node) {
        let tag = doc.tag(child);
        if !matches!(tag, "geom" | "inertial" | "frame") {
            continue;
        }
        if tag == "geom"
            && let Some(mesh) = mesh_asset(doc, child)
            && !meshes.contains(&mesh)
        {
            meshes.push(mesh);
        }
        xml.push('<');
        xml.push_str(tag);
        for (attr, value) in doc.attrs(child) {
            if !LEFT_OUT.contains(&attr) && attr != "childclass" {
                push_attr(xml, attr, value);
            }
        }
        if tag == "frame" {
            xml.push('>');
            push_children(doc, child, xml, meshes);
            xml.push_str("</frame>");
        } else {
            xml.push_str("/>");
        }
    }
}

/// Whether `body`'s geoms can be compiled alone for its sizes and frames: its body model
/// is complete without meshes or frames, and it has a geom of [`sized_primitive`] (the
/// document cache makes an entry for every such body).
pub(crate) fn qualifies(doc: &Document, body: Node) -> bool {
    complete(doc, body)
        && doc.elements(body).all(|c| {
            let tag = doc.tag(c);
            tag != "frame" && !(tag == "geom" && needs_asset(doc, c))
        })
        && doc.elements(body).any(|c| sized_primitive(doc, c))
}

/// Whether `body` has a complete body model: a named body whose children are all of
/// [`KNOWN_CHILDREN`] or `<frame>`s of geoms, whose geoms need no asset but a `<mesh>` (see
/// [`mesh_asset`]), and no free joint of which aligns the body with its inertial frame.
pub(crate) fn complete(doc: &Document, body: Node) -> bool {
    if doc.tag(body) != "body" || doc.attr(body, "name").is_none() {
        return false;
    }
    fn frame_of_geoms(doc: &Document, frame: Node) -> bool {
        doc.elements(frame).all(|c| match doc.tag(c) {
            "geom" => !needs_asset(doc, c) || mesh_asset(doc, c).is_some(),
            "frame" => frame_of_geoms(doc, c),
            _ => false,
        })
    }
    doc.elements(body).all(|child| match doc.tag(child) {
        "geom" => !needs_asset(doc, child) || mesh_asset(doc, child).is_some(),
        "frame" => frame_of_geoms(doc, child),
        tag => KNOWN_CHILDREN.contains(&tag) && !doc.aligns_free_body(child),
    })
}

fn push_attr(xml: &mut String, attr: &str, value: &str) {
    xml.push(' ');
    xml.push_str(attr);
    xml.push_str("=\"");
    escape_attr(xml, value);
    xml.push('"');
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(xml: &str) -> Option<String> {
        let doc = Document::from_str(xml, ".").unwrap();
        let b = doc
            .descendants(doc.root())
            .find(|&n| doc.tag(n) == "body")
            .unwrap();
        body_model(&doc, b)
    }

    #[test]
    fn a_body_of_primitives_becomes_its_geoms_and_inertial() {
        let xml = r#"<mujoco><compiler angle="radian" meshdir="m"/><asset><material name="m"/></asset>
            <worldbody><body name="b" pos="1 2 3"><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
            <geom name="g" size="0.1 0.2 0.3" type="box" material="m" euler="0 0 1"/>
            <site name="s"/><geom fromto="0 0 0 0 0 1" size="0.1" type="capsule"/></body></worldbody></mujoco>"#;
        assert_eq!(
            body(xml).unwrap(),
            r#"<mujoco><compiler angle="radian"/><worldbody><body><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/><geom size="0.1 0.2 0.3" type="box" euler="0 0 1"/><geom fromto="0 0 0 0 0 1" size="0.1" type="capsule"/></body></worldbody></mujoco>"#
        );
    }

    #[test]
    fn bodies_that_need_more_than_their_geoms_do_not_qualify() {
        let doc = |inner: &str| {
            Document::from_str(
                &format!(
                    r#"<mujoco><asset><mesh name="m" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/><hfield name="h" nrow="2" ncol="2" size="1 1 1 1"/></asset>
                    <worldbody><body name="b">{inner}</body></worldbody></mujoco>"#
                ),
                ".",
            )
            .unwrap()
        };
        // (complete: a body model exists; qualifies: its sizes are patched through it)
        let facts = |inner: &str| {
            let d = doc(inner);
            let b = d
                .descendants(d.root())
                .find(|&n| d.tag(n) == "body")
                .unwrap();
            (complete(&d, b), qualifies(&d, b))
        };
        assert_eq!(facts(r#"<geom size="0.1"/>"#), (true, true));
        // Meshes and frames of geoms: their densities and masses are carried, not sizes.
        assert_eq!(
            facts(r#"<geom size="0.1"/><geom type="mesh" mesh="m"/>"#),
            (true, false)
        );
        assert_eq!(
            facts(r#"<frame><geom size="0.1"/></frame><geom size="0.1"/>"#),
            (true, false)
        );
        assert_eq!(facts(r#"<geom type="hfield" hfield="h"/>"#), (false, false));
        assert_eq!(facts(r#"<frame><site/></frame>"#), (false, false));
        assert_eq!(
            facts(r#"<geom fromto="0 0 0 1 0 0" size="0.1" type="capsule"/>"#),
            (true, false)
        );
        assert_eq!(
            facts(r#"<freejoint align="true"/><geom size="0.1"/>"#),
            (false, false)
        );
        assert!(
            body(r#"<mujoco><worldbody><body><geom size="0.1"/></body></worldbody></mujoco>"#)
                .is_none()
        );
    }

    #[test]
    fn a_body_model_holds_its_frames_and_meshes() {
        let xml = r#"<mujoco><asset><mesh name="m" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/><mesh name="n" vertex="0 0 0 1 0 0 0 1 0 0 0 2"/></asset>
            <worldbody><body name="b"><geom name="g" type="mesh" mesh="m" density="5"/>
            <frame name="f" pos="1 0 0"><geom size="0.1" mass="2"/></frame></body></worldbody></mujoco>"#;
        assert_eq!(
            body(xml).unwrap(),
            r#"<mujoco><asset><mesh name="m" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/></asset><worldbody><body><geom type="mesh" mesh="m" density="5"/><frame pos="1 0 0"><geom size="0.1" mass="2"/></frame></body></worldbody></mujoco>"#
        );
    }
}
