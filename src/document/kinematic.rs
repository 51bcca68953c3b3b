//! Where elements sit in the kinematic tree, as MuJoCo reads it: the world body, the
//! bodies directly under it or a body (through `<frame>`s, which MuJoCo dissolves into
//! their parent), and whether an element is a body's own child. The model, split and
//! scene tiers ask these questions of a document.

use crate::document::tree::Node;
use crate::document::{Document, Section};

impl Document {
    /// The world body, if the document has one (no section is created).
    pub(crate) fn worldbody(&self) -> Option<Node> {
        self.find_section(Section::Worldbody)
    }

    /// The bodies whose parent is the world body (directly or through frames).
    pub(crate) fn top_level_bodies(&self, world: Node) -> Vec<Node> {
        self.children_through_frames(world, "body")
    }

    /// The `tag` elements whose parent is `node`, directly or through `<frame>`s, in
    /// document order (a body's geoms, the world's bodies).
    pub(crate) fn children_through_frames(&self, node: Node, tag: &str) -> Vec<Node> {
        let mut out = Vec::new();
        // Document order through nested frames, from a stack (frames nest without bound).
        let mut stack: Vec<Node> = self.elements(node).collect();
        stack.reverse();
        while let Some(k) = stack.pop() {
            match self.tag(k) {
                t if t == tag => out.push(k),
                "frame" => {
                    let at = stack.len();
                    stack.extend(self.elements(k));
                    stack[at..].reverse();
                }
                _ => {}
            }
        }
        out
    }

    /// Whether an element sits in the kinematic tree as a body's own child (through frames),
    /// not inside a tendon, composite or default.
    pub(crate) fn is_body_child(&self, node: Node) -> bool {
        let mut p = self.parent(node);
        while let Some(n) = p {
            match self.tag(n) {
                "body" | "worldbody" => return true,
                "frame" => p = self.parent(n),
                _ => return false,
            }
        }
        false
    }
}
