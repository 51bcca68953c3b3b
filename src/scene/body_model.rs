//! A body's geoms as a model of their own: what a document patch carries for a body whose
//! primitive geoms change size, so that a model cache can read off that little model's
//! compile what MuJoCo derives from the sizes (each geom's size, bounding radius and box,
//! the body's mass, inertia and inertial frame, its bounding-volume tree) and write it
//! into the compiled model of the whole structure.
//!
//! All of those are computed by the compiler from the body's own geoms in the body's own
//! frame, under the `<compiler>` settings, and from nothing else of the model, so the
//! little model (the `<compiler>`, one body at the world's origin holding the body's
//! `<inertial>` and geoms as written, without names, materials or user data) gives the
//! same numbers, bit for bit (`tests` of `compiled` and the Python cache judge it against
//! MuJoCo's compile of the whole document).
//!
//! A body qualifies only when its little model is complete: every child is a geom that
//! needs no asset (no mesh, height field or signed distance field), a joint, a site, a
//! camera, a light, an `<inertial>` or a body; no free joint of it makes MuJoCo align the
//! body with its inertial frame (which moves the body). Whether the whole document allows
//! it (masses that land unchanged, no spatial tendon wrapping a geom...) is the caller's.

use crate::document::Document;
use crate::document::tree::Node;
use crate::document::write::escape_attr;

/// Geom types whose `size` alone sets their shape (with the type's defaults).
const PRIMITIVES: [&str; 5] = ["sphere", "capsule", "ellipsoid", "cylinder", "box"];

/// Children a body may have for its little model to be complete.
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

/// Geom attributes the little model leaves out: they name or reference what it does not
/// have, and the compiler derives nothing of the geom's shape or mass from them.
const LEFT_OUT: [&str; 4] = ["name", "material", "user", "class"];

/// Whether `geom`'s `size` can be patched through its body's little model: a primitive
/// type, sized by `size` (not `fromto`).
pub(crate) fn sized_primitive(doc: &Document, geom: Node) -> bool {
    doc.tag(geom) == "geom"
        && doc.attr(geom, "size").is_some()
        && doc.attr(geom, "fromto").is_none()
        && PRIMITIVES.contains(&doc.attr(geom, "type").map_or("sphere", str::trim))
}

/// Geom attributes a body's little model carries into the compiled model: sizes, frames,
/// densities and masses (what MuJoCo derives from them is what the little model compiles
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

/// The body whose little model carries `attr` of `node`: a geom's size (a sized
/// primitive), frame, density or mass, in a body that has a little model.
pub(crate) fn carried_by(doc: &Document, node: Node, attr: &str) -> Option<Node> {
    if doc.tag(node) != "geom"
        || !CARRIED.contains(&attr)
        || needs_asset(doc, node)
        || doc.attr(node, "fromto").is_some()
        || (attr == "size" && !sized_primitive(doc, node))
    {
        return None;
    }
    doc.parent(node).filter(|&body| qualifies(doc, body))
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

/// The little model of `body` (see the module), if the body qualifies and has a geom of
/// [`sized_primitive`].
pub(crate) fn body_model(doc: &Document, body: Node) -> Option<String> {
    if !qualifies(doc, body) {
        return None;
    }
    let mut xml = String::from("<mujoco>");
    for compiler in doc
        .elements(doc.root())
        .filter(|&n| doc.tag(n) == "compiler")
    {
        xml.push_str("<compiler");
        for (attr, value) in doc.attrs(compiler) {
            // No asset is read: the folders do not matter.
            if !matches!(attr, "meshdir" | "texturedir" | "assetdir") {
                push_attr(&mut xml, attr, value);
            }
        }
        xml.push_str("/>");
    }
    xml.push_str("<worldbody><body>");
    for child in doc.elements(body) {
        let tag = doc.tag(child);
        if tag != "geom" && tag != "inertial" {
            continue;
        }
        xml.push('<');
        xml.push_str(tag);
        for (attr, value) in doc.attrs(child) {
            if !LEFT_OUT.contains(&attr) {
                push_attr(&mut xml, attr, value);
            }
        }
        xml.push_str("/>");
    }
    xml.push_str("</body></worldbody></mujoco>");
    Some(xml)
}

/// Whether `body` has a little model (see [`body_model`]).
pub(crate) fn qualifies(doc: &Document, body: Node) -> bool {
    if doc.tag(body) != "body" || doc.attr(body, "name").is_none() {
        return false;
    }
    let mut sized = false;
    for child in doc.elements(body) {
        let tag = doc.tag(child);
        if !KNOWN_CHILDREN.contains(&tag)
            || (tag == "geom" && needs_asset(doc, child))
            || doc.aligns_free_body(child)
        {
            return false;
        }
        sized |= sized_primitive(doc, child);
    }
    sized
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
        let with = |inner: &str| {
            body(&format!(
                r#"<mujoco><asset><mesh name="m" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/></asset>
                <worldbody><body name="b">{inner}</body></worldbody></mujoco>"#
            ))
        };
        assert!(with(r#"<geom size="0.1"/>"#).is_some());
        assert!(with(r#"<geom size="0.1"/><geom type="mesh" mesh="m"/>"#).is_none());
        assert!(with(r#"<frame><geom size="0.1"/></frame><geom size="0.1"/>"#).is_none());
        assert!(with(r#"<geom fromto="0 0 0 1 0 0" size="0.1" type="capsule"/>"#).is_none());
        assert!(with(r#"<freejoint align="true"/><geom size="0.1"/>"#).is_none());
        assert!(
            body(r#"<mujoco><worldbody><body><geom size="0.1"/></body></worldbody></mujoco>"#)
                .is_none()
        );
    }
}
