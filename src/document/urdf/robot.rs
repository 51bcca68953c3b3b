//! The link tree of a URDF robot: which joint makes which link whose child, and the order
//! MuJoCo's importer adds the links as bodies (each parentless link in file order, then
//! depth first, children in the order of their joints).
//!
//! Every problem of the tree is found in one pass: a link without a name or named twice, a
//! joint without `<parent>` or `<child>`, one naming a link that does not exist, a link
//! with two parents, links that form a cycle.

use ahash::AHashMap;

use crate::document::Document;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind};

/// A `<link>`.
pub(super) struct Link<'a> {
    pub(super) node: Node,
    pub(super) name: &'a str,
    /// The `<joint>` that makes this link a child, if any.
    pub(super) joint: Option<Node>,
    /// Its parent link (an index into `Robot::links`), if any.
    pub(super) parent: Option<usize>,
    pub(super) children: Vec<usize>,
}

/// The links of a robot and the order they become bodies in.
pub(super) struct Robot<'a> {
    pub(super) links: Vec<Link<'a>>,
    /// Indices into `links`, parents before children, as the importer adds them.
    pub(super) order: Vec<usize>,
    /// The `<joint>` elements, in file order.
    pub(super) joints: Vec<Node>,
}

fn invalid(doc: &Document, node: Node, msg: String) -> Error {
    doc.error_at(node, ErrorKind::Invalid(msg))
}

/// The `link` attribute of `joint`'s `<parent>` or `<child>`.
fn joint_end<'a>(
    doc: &'a Document,
    joint: Node,
    which: &str,
    errors: &mut Vec<Error>,
) -> Option<(Node, &'a str)> {
    let Some(end) = doc.elements(joint).find(|&n| doc.tag(n) == which) else {
        errors.push(invalid(doc, joint, format!("URDF joint without <{which}>")));
        return None;
    };
    match doc.attr(end, "link") {
        Some(link) => Some((end, link)),
        None => {
            errors.push(invalid(doc, end, format!("<{which}> without 'link'")));
            None
        }
    }
}

impl<'a> Robot<'a> {
    /// The tree of `doc`'s `<robot>`, or every problem found in it.
    pub(super) fn read(doc: &'a Document, errors: &mut Vec<Error>) -> Option<Robot<'a>> {
        let root = doc.root();
        let before = errors.len();
        let mut links: Vec<Link<'a>> = Vec::new();
        let mut by_name: AHashMap<&'a str, usize> = AHashMap::new();
        for n in doc.elements(root).filter(|&n| doc.tag(n) == "link") {
            let Some(name) = doc.attr(n, "name") else {
                errors.push(invalid(doc, n, "URDF link without 'name'".into()));
                continue;
            };
            if by_name.contains_key(name) {
                errors.push(invalid(doc, n, format!("repeated URDF link name '{name}'")));
                continue;
            }
            by_name.insert(name, links.len());
            links.push(Link {
                node: n,
                name,
                joint: None,
                parent: None,
                children: Vec::new(),
            });
        }
        let mut joints = Vec::new();
        for j in doc.elements(root).filter(|&n| doc.tag(n) == "joint") {
            joints.push(j);
            let parent = joint_end(doc, j, "parent", errors);
            let child = joint_end(doc, j, "child", errors);
            let (Some((pn, parent)), Some((cn, child))) = (parent, child) else {
                continue;
            };
            let found = |end: Node, name: &str, errors: &mut Vec<Error>| {
                let i = by_name.get(name).copied();
                if i.is_none() {
                    errors.push(invalid(
                        doc,
                        end,
                        format!("URDF joint names link '{name}', which no <link> defines"),
                    ));
                }
                i
            };
            let (Some(p), Some(c)) = (found(pn, parent, errors), found(cn, child, errors)) else {
                continue;
            };
            if let Some(first) = links[c].joint {
                let first = doc.location(first);
                errors.push(invalid(
                    doc,
                    j,
                    format!(
                        "URDF link '{child}' has two parents: this joint and the one at {}:{}",
                        first.line, first.col
                    ),
                ));
                continue;
            }
            links[c].joint = Some(j);
            links[c].parent = Some(p);
            links[p].children.push(c);
        }
        if errors.len() > before {
            return None;
        }
        let mut order = Vec::with_capacity(links.len());
        let mut stack = Vec::new();
        for root_link in (0..links.len()).filter(|&i| links[i].joint.is_none()) {
            stack.push(root_link);
            while let Some(i) = stack.pop() {
                order.push(i);
                stack.extend(links[i].children.iter().rev());
            }
        }
        if order.len() < links.len() {
            let mut seen = vec![false; links.len()];
            for &i in &order {
                seen[i] = true;
            }
            for (_, link) in links.iter().enumerate().filter(|(i, _)| !seen[*i]) {
                errors.push(invalid(
                    doc,
                    link.node,
                    format!(
                        "URDF link '{}' is part of a cycle of joints: no link above it has no parent",
                        link.name
                    ),
                ));
            }
            return None;
        }
        Some(Robot {
            links,
            order,
            joints,
        })
    }
}
