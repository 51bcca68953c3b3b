//! URDF joints: the MJCF joints each makes on its child body (the importer's kinds,
//! ranges, dynamics), and `<mimic>` as a joint equality.

use super::super::UrdfImporter;
use super::super::robot::Robot;
use super::{Writer, num};
use crate::document::tree::Node;

impl Writer<'_> {
    /// A `<joint>`'s origin on its child body, and the MJCF joint(s) it makes.
    pub(super) fn joint(&mut self, j: Node, body: Node) -> Option<JointKind> {
        let raw = self.raw;
        let ty = self.required(j, "type")?;
        let name = self.required(j, "name")?;
        let continuous = ty == "continuous";
        let kind = match ty {
            "revolute" | "continuous" => JointKind::Hinge,
            "prismatic" => JointKind::Slide,
            "fixed" => JointKind::Fixed,
            "floating" => JointKind::Free,
            "spherical" => JointKind::Ball,
            "planar" => JointKind::Planar,
            other => {
                self.error(
                    j,
                    format!(
                        "invalid joint type '{other}' in URDF joint '{name}' (revolute, \
                         continuous, prismatic, fixed, floating, planar or spherical)"
                    ),
                );
                return None;
            }
        };
        if body != self.worldbody {
            self.origin(j, body);
        }
        let axis = match self.sub(j, "axis") {
            Some(a) => self.required(a, "xyz")?,
            None => "1 0 0",
        };
        let out = match kind {
            JointKind::Fixed => return Some(kind),
            _ => self.child(body, "joint", j),
        };
        // A planar joint is the importer's three: slides along the x and y of the frame
        // whose z is the axis (`mjuu_z2quat`), and a hinge about the axis; the limit
        // reaches the first only, the dynamics all three.
        let mut all = vec![out];
        if kind == JointKind::Planar {
            let v = self.numbers(j, "axis", axis, 3)?;
            let m =
                crate::document::rotation::quat_to_mat(&crate::document::rotation::z_to_quat(&[
                    v[0], v[1], v[2],
                ]));
            self.set(out, "name", &format!("{name}_TX"));
            self.set(out, "type", "slide");
            self.set(
                out,
                "axis",
                &format!("{} {} {}", num(m[0]), num(m[3]), num(m[6])),
            );
            for (suffix, ty, ax) in [
                (
                    "_TY",
                    "slide",
                    format!("{} {} {}", num(m[1]), num(m[4]), num(m[7])),
                ),
                ("_RZ", "hinge", axis.to_string()),
            ] {
                let more = self.child(body, "joint", j);
                self.set(more, "name", &format!("{name}{suffix}"));
                self.set(more, "type", ty);
                self.set(more, "axis", &ax);
                all.push(more);
            }
        } else {
            self.set(out, "name", name);
        }
        match kind {
            JointKind::Slide => self.set(out, "type", "slide"),
            JointKind::Free => self.set(out, "type", "free"),
            JointKind::Ball => self.set(out, "type", "ball"),
            _ => {}
        }
        if !matches!(kind, JointKind::Free | JointKind::Planar) {
            self.set(out, "axis", axis);
        }
        if let Some(d) = self.sub(j, "dynamics") {
            for &n in &all {
                if let Some(v) = raw.attr(d, "damping") {
                    self.set(n, "damping", v);
                }
                if let Some(v) = raw.attr(d, "friction") {
                    self.set(n, "frictionloss", v);
                }
            }
        }
        if continuous && self.options.importer == UrdfImporter::MuJoCo4 {
            // 4.0.0 reads no range for a continuous joint.
            self.set(out, "limited", "false");
        }
        if let Some(limit) = self.sub(j, "limit") {
            let (mut lower, mut upper) = (raw.attr(limit, "lower"), raw.attr(limit, "upper"));
            if continuous && self.options.importer == UrdfImporter::MuJoCo4 {
                (lower, upper) = (None, None);
            }
            let mut value = |t: Option<&str>, attr| match t {
                Some(t) => self.numbers(limit, attr, t, 1).map(|v| v[0]),
                None => Some(0.0),
            };
            let (lo, hi) = (value(lower, "lower")?, value(upper, "upper")?);
            if lower.is_some() || upper.is_some() {
                let range = format!(
                    "{} {}",
                    lower.map_or("0", str::trim),
                    upper.map_or("0", str::trim)
                );
                self.set(out, "range", &range);
            }
            if lower.is_some() != upper.is_some() || lo > hi {
                self.set(out, "limited", "false");
            }
            // Equal bounds limit nothing in either version (MJCF's automatic `limited`
            // leaves such a range off too); 4.0.0 says so.
            if lower.is_some()
                && upper.is_some()
                && lo == hi
                && self.options.importer == UrdfImporter::MuJoCo4
            {
                self.warn(
                    limit,
                    format!("joint '{name}' has equal lower and upper limits, limit ignored"),
                );
            }
            if let Some(e) = raw.attr(limit, "effort") {
                let e = self.numbers(limit, "effort", e, 1)?[0].abs();
                if e > 0.0 {
                    self.set(out, "actuatorfrcrange", &format!("{} {}", num(-e), num(e)));
                }
            }
        }
        Some(kind)
    }

    /// Whether a `<mimic joint>` names a joint of the file that moves as one hinge or
    /// slide (revolute, continuous, prismatic); MuJoCo's importer drops the others, with a
    /// warning. A `<mimic>` without `joint` counts as moving, for [`Writer::mimic`] to
    /// report.
    pub(super) fn leader_moves(&self, m: Node, robot: &Robot<'_>) -> bool {
        let raw = self.raw;
        let Some(leader) = raw.attr(m, "joint") else {
            return true;
        };
        robot.joints.iter().any(|&j| {
            raw.attr(j, "name") == Some(leader)
                && matches!(
                    raw.attr(j, "type"),
                    Some("revolute" | "continuous" | "prismatic")
                )
        })
    }

    /// A `<mimic>` as the importer writes it: a joint equality, the follower first, with
    /// `polycoef="offset multiplier 0 0 0"`.
    pub(super) fn mimic(&mut self, eq: Node, j: Node, m: Node) {
        let raw = self.raw;
        let (Some(name), Some(leader)) = (raw.attr(j, "name"), self.required(m, "joint")) else {
            return;
        };
        let e = self.child(eq, "joint", m);
        self.set(e, "joint1", name);
        self.set(e, "joint2", leader);
        let (mult, off) = (raw.attr(m, "multiplier"), raw.attr(m, "offset"));
        if mult.is_some() || off.is_some() {
            let coef = format!(
                "{} {} 0 0 0",
                off.map_or("0", str::trim),
                mult.map_or("1", str::trim)
            );
            self.set(e, "polycoef", &coef);
        }
    }
}

/// What a URDF joint becomes.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum JointKind {
    Hinge,
    Slide,
    Fixed,
    Free,
    Ball,
    Planar,
}

impl JointKind {
    /// Whether a `<mimic>` on it is read (MuJoCo warns about and drops the others).
    pub(super) fn mimics(self) -> bool {
        matches!(self, JointKind::Hinge | JointKind::Slide)
    }
}
