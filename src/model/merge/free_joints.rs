//! Free joints: which elements hold one, and which free bodies MuJoCo aligns with their
//! inertial frames (`alignfree`, or a `<freejoint>`'s own `align`).

use super::compiler::compiler_settings;
use crate::document::Document;
use crate::document::tree::Node;

impl Document {
    pub(super) fn has_free_joint(&self, node: Node) -> bool {
        self.descendants(node).any(|n| {
            self.tag(n) == "freejoint"
                || (self.tag(n) == "joint" && self.attr(n, "type").map(str::trim) == Some("free"))
        })
    }

    /// Whether `node` is a `<joint type="free">` (a `<freejoint>` is not) whose body
    /// `alignfree` would align.
    pub(super) fn is_free_joint_element(&self, node: Node) -> bool {
        self.tag(node) == "joint"
            && self.attr(node, "type").is_some_and(|t| t.trim() == "free")
            && self.joint_body_is_a_leaf(node)
    }

    /// Whether the body of `joint` has no child bodies: MuJoCo aligns only such free bodies
    /// with their inertial frames (`freejoint/align` in its reference; seen in 3.17.0 and
    /// 4.0.0).
    fn joint_body_is_a_leaf(&self, joint: Node) -> bool {
        let mut body = self.parent(joint);
        while let Some(b) = body
            && self.tag(b) != "body"
        {
            body = self.parent(b);
        }
        body.is_none_or(|b| !self.descendants(b).skip(1).any(|n| self.tag(n) == "body"))
    }

    /// Whether MuJoCo aligns the body of the free joint `joint` (a `<freejoint>` or a
    /// `<joint type="free">`) with its inertial frame: `align="true"` on a `<freejoint>`,
    /// or the compiler's `alignfree="true"` where the joint does not say (a
    /// `<joint type="free">` never does), for a body without child bodies. Its frame and
    /// `qpos0` are then the inertial frame's, which only MuJoCo's compiler knows exactly.
    pub(crate) fn aligns_free_body(&self, joint: Node) -> bool {
        let free = match self.tag(joint) {
            "freejoint" => true,
            "joint" => self.attr(joint, "type").is_some_and(|t| t.trim() == "free"),
            _ => false,
        };
        if !free {
            return false;
        }
        let global = || {
            compiler_settings(self)
                .get("alignfree")
                .is_some_and(|(v, _)| v == "true")
        };
        let on = match self.attr(joint, "align").map(str::trim) {
            Some("true") if self.tag(joint) == "freejoint" => true,
            Some("false") if self.tag(joint) == "freejoint" => false,
            _ => global(),
        };
        on && self.joint_body_is_a_leaf(joint)
    }
}
