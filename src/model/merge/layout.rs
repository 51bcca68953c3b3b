//! The layout of a model's state vectors, which keyframes are written against: the joints,
//! actuators and mocap bodies that fill `qpos`, `qvel`, `act`, `ctrl`, `mpos` and `mquat`,
//! and where each one's values sit.

use crate::document::tree::Node;
use crate::document::{Document, Section};

/// How a joint sits in `qpos`/`qvel`.
pub(super) fn joint_widths(doc: &Document, joint: Node) -> (usize, usize) {
    if doc.tag(joint) == "freejoint" {
        return (7, 6);
    }
    match doc.attr(joint, "type").map(str::trim).unwrap_or("hinge") {
        "free" => (7, 6),
        "ball" => (4, 3),
        _ => (1, 1),
    }
}

/// How many activation states an actuator has.
pub(super) fn actuator_states(doc: &Document, act: Node) -> Result<usize, String> {
    if let Some(d) = doc.attr(act, "actdim") {
        let n: i64 = d.trim().parse().map_err(|_| format!("bad actdim '{d}'"))?;
        if n >= 0 {
            return Ok(n as usize);
        }
    }
    Ok(match doc.tag(act) {
        "general" => match doc.attr(act, "dyntype").map(str::trim).unwrap_or("none") {
            "none" => 0,
            _ => 1,
        },
        "position" => {
            let tc = doc
                .attr(act, "timeconst")
                .and_then(|t| t.trim().parse::<f64>().ok())
                .unwrap_or(0.0);
            usize::from(tc > 0.0)
        }
        "intvelocity" | "cylinder" | "muscle" => 1,
        "motor" | "velocity" | "damper" | "adhesion" => 0,
        other => {
            return Err(format!(
                "activation size of <{other}> actuators is not known"
            ));
        }
    })
}

/// The layout of a model's state vectors: joints (qpos/qvel), actuators (ctrl/act) and
/// mocap bodies (mpos/mquat), in MuJoCo's order.
#[derive(Default)]
pub(super) struct Layout {
    pub(super) joints: Vec<Node>,
    pub(super) actuators: Vec<Node>,
    pub(super) mocap: Vec<Node>,
    /// Why the layout cannot be known (elements that expand into objects at compile time).
    pub(super) opaque: Option<(Node, String)>,
}

impl Layout {
    pub(super) fn of(doc: &Document) -> Layout {
        let mut l = Layout::default();
        if let Some(world) = doc.find_section(Section::Worldbody) {
            l.visit_body(doc, world);
        }
        if let Some(acts) = doc.find_section(Section::Actuator) {
            l.actuators = doc.elements(acts).collect();
        }
        l
    }

    /// MuJoCo numbers bodies depth first in document order; a body's joints (its own and
    /// those in its frames) come before the joints of its child bodies.
    /// Explicit stacks rather than recursion: bodies and frames nest without bound.
    fn visit_body(&mut self, doc: &Document, body: Node) {
        let mut bodies = vec![body];
        let mut children = Vec::new();
        while let Some(body) = bodies.pop() {
            if doc.attr(body, "mocap").map(str::trim) == Some("true") {
                self.mocap.push(body);
            }
            children.clear();
            self.collect(doc, body, &mut children);
            bodies.extend(children.iter().rev());
        }
    }

    /// The joints of `node` and of its frames (into the layout), and its child bodies
    /// (into `bodies`), in document order.
    fn collect(&mut self, doc: &Document, node: Node, bodies: &mut Vec<Node>) {
        let mut stack: Vec<Node> = doc.elements(node).collect();
        stack.reverse();
        while let Some(k) = stack.pop() {
            match doc.tag(k) {
                "joint" | "freejoint" => self.joints.push(k),
                "body" => bodies.push(k),
                "frame" => {
                    let at = stack.len();
                    stack.extend(doc.elements(k));
                    stack[at..].reverse();
                }
                t @ ("replicate" | "composite" | "flexcomp" | "attach")
                    if self.opaque.is_none() =>
                {
                    self.opaque = Some((
                        k,
                        format!(
                            "<{t}> creates bodies and joints when MuJoCo compiles, whose places \
                             in the keyframes' vectors are not modelled"
                        ),
                    ));
                }
                _ => {}
            }
        }
    }
}

/// Offsets of each item in a document's state vectors.
pub(super) struct Offsets {
    qpos: Vec<(usize, usize)>,
    qvel: Vec<(usize, usize)>,
    act: Vec<(usize, usize)>,
    ctrl: Vec<(usize, usize)>,
    mpos: Vec<(usize, usize)>,
    mquat: Vec<(usize, usize)>,
}

impl Offsets {
    pub(super) fn of(doc: &Document, layout: &Layout, need_act: bool) -> Result<Offsets, String> {
        let run = |widths: Vec<usize>| -> Vec<(usize, usize)> {
            let mut at = 0;
            widths
                .into_iter()
                .map(|w| {
                    let r = (at, w);
                    at += w;
                    r
                })
                .collect()
        };
        let jw: Vec<(usize, usize)> = layout
            .joints
            .iter()
            .map(|&j| joint_widths(doc, j))
            .collect();
        let act = if need_act {
            layout
                .actuators
                .iter()
                .map(|&a| actuator_states(doc, a))
                .collect::<Result<Vec<_>, _>>()?
        } else {
            vec![0; layout.actuators.len()]
        };
        Ok(Offsets {
            qpos: run(jw.iter().map(|w| w.0).collect()),
            qvel: run(jw.iter().map(|w| w.1).collect()),
            act: run(act),
            ctrl: run(vec![1; layout.actuators.len()]),
            mpos: run(vec![3; layout.mocap.len()]),
            mquat: run(vec![4; layout.mocap.len()]),
        })
    }

    pub(super) fn vector(&self, v: usize) -> &[(usize, usize)] {
        match v {
            0 => &self.qpos,
            1 => &self.qvel,
            2 => &self.act,
            3 => &self.ctrl,
            4 => &self.mpos,
            _ => &self.mquat,
        }
    }

    pub(super) fn len(&self, v: usize) -> usize {
        self.vector(v).last().map(|(a, w)| a + w).unwrap_or(0)
    }
}
