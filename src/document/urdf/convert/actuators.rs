//! The actuators `UrdfOptions::actuators` writes for a URDF's hinge and slide joints.

use super::super::{UrdfActuators, UrdfImporter};
use super::{Writer, num};
use crate::document::tree::Node;

impl Writer<'_> {
    /// `UrdfOptions::actuators`: one actuator per joint of `joints` (the hinges and
    /// slides but those a `<mimic>` drives through its equality). A position actuator's control range is the
    /// joint's range as the importer reads it (none for a continuous joint under 4.0.0).
    pub(super) fn actuators(&mut self, kind: &UrdfActuators, joints: &[Node]) {
        let raw = self.raw;
        let root = raw.root();
        let section = self.child(self.root, "actuator", root);
        for &j in joints {
            let Some(name) = raw.attr(j, "name") else {
                continue;
            };
            let unlimited = raw.attr(j, "type") == Some("continuous")
                && self.options.importer == UrdfImporter::MuJoCo4;
            let limit = self.sub(j, "limit");
            let read = |attr: &str| {
                limit
                    .and_then(|l| raw.attr(l, attr))
                    .and_then(|t| t.trim().parse::<f64>().ok())
            };
            let effort = read("effort").map(f64::abs).filter(|&e| e > 0.0);
            let tag = match kind {
                UrdfActuators::Position { .. } => "position",
                UrdfActuators::Velocity { .. } => "velocity",
                UrdfActuators::Motor => "motor",
            };
            let a = self.child(section, tag, j);
            self.set(a, "name", name);
            self.set(a, "joint", name);
            let ctrl = match kind {
                UrdfActuators::Position { kp, kv } => {
                    self.set(a, "kp", &num(*kp));
                    if *kv > 0.0 {
                        self.set(a, "kv", &num(*kv));
                    }
                    match (read("lower"), read("upper")) {
                        (Some(lo), Some(hi)) if lo < hi && !unlimited => Some((lo, hi)),
                        _ => None,
                    }
                }
                UrdfActuators::Velocity { kv } => {
                    self.set(a, "kv", &num(*kv));
                    read("velocity")
                        .map(f64::abs)
                        .filter(|&v| v > 0.0)
                        .map(|v| (-v, v))
                }
                UrdfActuators::Motor => effort.map(|e| (-e, e)),
            };
            if let Some((lo, hi)) = ctrl {
                self.set(a, "ctrlrange", &format!("{} {}", num(lo), num(hi)));
            }
            if let (Some(e), false) = (effort, matches!(kind, UrdfActuators::Motor)) {
                self.set(a, "forcerange", &format!("{} {}", num(-e), num(e)));
            }
        }
    }
}
