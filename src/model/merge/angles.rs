//! Angles between compiler settings: a part's Euler angles rewritten as quaternions for a
//! base with another Euler sequence, and its angle-valued attributes converted between
//! degrees and radians (or the base converted instead, when it is the smaller).

use super::compiler::{MUST_AGREE, compiler_settings};
use super::{fmt_num, syms};
use crate::document::Document;
use crate::document::names::Sym;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind};
use crate::model::geometry::{self, Angles};

/// A document's angle settings ([`Angles::of`]) where it must be used to convert angles:
/// errors at the `<compiler>` at fault, quoting at most a little of a value; and an
/// `eulerseq` with letters other than `xyzXYZ` refused when an `euler` attribute would be
/// read under it, which MuJoCo refuses too (converting it would give a wrong rotation).
pub(super) fn angles_checked(doc: &Document) -> Result<Angles, Error> {
    let mut angles = Angles::default();
    let mut seq_at = None;
    let invalid = |node: Node, msg: String| doc.error_at(node, ErrorKind::Invalid(msg));
    for c in doc.elements(doc.root).filter(|&n| doc.tag(n) == "compiler") {
        if let Some(a) = doc.attr(c, "angle") {
            angles.degrees = match a.trim() {
                "degree" => true,
                "radian" => false,
                other => {
                    let other = crate::document::read::clip(other, 40);
                    let msg = format!("compiler angle must be 'degree' or 'radian', not '{other}'");
                    return Err(invalid(c, msg));
                }
            };
        }
        if let Some(seq) = doc.attr(c, "eulerseq") {
            angles.seq = seq.as_bytes().try_into().map_err(|_| {
                let seq = crate::document::read::clip(seq, 40);
                invalid(
                    c,
                    format!("compiler eulerseq '{seq}' must have exactly 3 letters"),
                )
            })?;
            seq_at = Some(c);
        }
    }
    if let Some(c) = seq_at
        && !angles.seq.iter().all(|l| b"xyzXYZ".contains(l))
        && doc
            .descendants(doc.root)
            .any(|n| doc.attr(n, "euler").is_some())
    {
        let seq = String::from_utf8_lossy(&angles.seq);
        let msg = format!(
            "compiler eulerseq '{seq}' can only contain x, y, z, X, Y, Z (MuJoCo refuses \
             the model's euler attributes)"
        );
        return Err(invalid(c, msg));
    }
    Ok(angles)
}

impl Document {
    /// When the part differs from this document only in the angle unit and this document is
    /// the smaller, converts this document to the part's unit instead (the same compiled
    /// model, less to rewrite: an arena receiving a robot, say).
    pub(super) fn adopt_angle_unit_if_smaller(&mut self, part: &Document) {
        if self.node_count() >= part.node_count() {
            return;
        }
        let ours = compiler_settings(self);
        let theirs = compiler_settings(part);
        let same = |k: &str| ours.get(k).map(|v| v.0) == theirs.get(k).map(|v| v.0);
        let others = ["eulerseq", "autolimits", "inertiafromgeom"];
        if same("angle")
            || !MUST_AGREE.iter().all(|(k, _)| same(k))
            || !others.iter().all(|k| same(k))
        {
            return;
        }
        let (Ok(mine), Ok(target)) = (Angles::of(self), Angles::of(part)) else {
            return;
        };
        if mine.degrees == target.degrees {
            return;
        }
        self.convert_angles(mine.degrees, target.degrees);
        let compilers: Vec<Node> = self
            .elements(self.root)
            .filter(|&n| self.tag(n) == "compiler")
            .collect();
        for &c in &compilers {
            self.remove_attr(c, "angle");
        }
        let unit = if target.degrees { "degree" } else { "radian" };
        match compilers.first() {
            Some(&c) => self.set_attr(c, "angle", unit),
            None => {
                let sym = self.intern("compiler");
                let c = self.new_element(sym, None);
                match self.tree.first_child(self.root) {
                    Some(f) => self.tree.insert_before(f, c),
                    None => self.tree.append(self.root, c),
                }
                self.set_attr(c, "angle", unit);
            }
        }
    }

    /// Every `euler` becomes the `quat` it means under `angles` (for a base with another
    /// Euler sequence).
    pub(super) fn rewrite_euler_as_quat(&mut self, angles: &Angles) {
        let nodes: Vec<Node> = self
            .descendants(self.root)
            .filter(|&n| self.attr(n, "euler").is_some())
            .collect();
        for n in nodes {
            let e: Vec<f64> = self
                .attr(n, "euler")
                .unwrap_or_default()
                .split_ascii_whitespace()
                .filter_map(|t| t.parse().ok())
                .collect();
            if e.len() != 3 || self.tag(n) == "replicate" {
                continue;
            }
            let q = geometry::euler_to_quat([e[0], e[1], e[2]], angles);
            self.remove_attr(n, "euler");
            self.set_attr(n, "quat", &q.map(fmt_num).join(" "));
        }
    }

    /// Converts every angle-valued attribute between degrees and radians: Euler angles, the
    /// angle of `axisangle`, and hinge/ball joint `ref`, `springref` and, of a limited joint,
    /// `range` (the ones MuJoCo's `compiler angle` applies to: it keeps the range of a joint
    /// that is not limited as written, in 3.17.0 and 4.0.0, as dm-control's testing arm has
    /// `range="-6.28319 6.28319" limited="false"`).
    pub(super) fn convert_angles(&mut self, from_degrees: bool, to_degrees: bool) {
        if from_degrees == to_degrees {
            return;
        }
        let autolimits = compiler_settings(self)
            .get("autolimits")
            .is_none_or(|(v, _)| v == "true");
        let factor = if from_degrees {
            std::f64::consts::PI / 180.0
        } else {
            180.0 / std::f64::consts::PI
        };
        let convert = |v: &str, which: &dyn Fn(usize) -> bool| -> String {
            v.split_ascii_whitespace()
                .enumerate()
                .map(|(i, t)| match t.parse::<f64>() {
                    Ok(x) if which(i) => fmt_num(x * factor),
                    _ => t.to_string(),
                })
                .collect::<Vec<_>>()
                .join(" ")
        };
        let s = syms();
        let nodes: Vec<Node> = self.descendants(self.root).collect();
        for n in nodes {
            let mut edits: Vec<(Sym, String)> = Vec::new();
            if let Some(v) = self.attr_sym(n, s.euler) {
                edits.push((s.euler, convert(v, &|_| true)));
            }
            if let Some(v) = self.attr_sym(n, s.axisangle) {
                edits.push((s.axisangle, convert(v, &|i| i == 3)));
            }
            if self.tag_sym(n) == Some(s.joint) && self.is_body_child(n) {
                let ty = self.attr_sym(n, s.ty).map(str::trim).unwrap_or("hinge");
                let limited = match self.attr(n, "limited").map(str::trim) {
                    Some("true") => true,
                    Some("false") => false,
                    _ => autolimits && self.attr_sym(n, s.range).is_some(),
                };
                if ty == "hinge" || ty == "ball" {
                    for a in [s.range, s.reference, s.springref] {
                        if (ty == "ball" && a != s.range) || (a == s.range && !limited) {
                            continue;
                        }
                        if let Some(v) = self.attr_sym(n, a) {
                            edits.push((a, convert(v, &|_| true)));
                        }
                    }
                }
            }
            for (a, v) in edits {
                let value = self.push_str(&v);
                self.set_attr_ref(n, a, value);
            }
        }
    }
}
