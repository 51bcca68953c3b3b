//! Where a body's mass and inertia come from, its `<inertial>` or its geoms: what the
//! compiler's inertia settings act on, and so what converting them must rewrite.

use crate::document::Document;
use crate::document::tree::Node;

impl Document {
    /// Whether `body` has a geom (directly or in a `<frame>` inside it) in the compiler's
    /// `inertiagrouprange` ("lo hi") whose mass is not zero (`mass="0"`, or `density="0"`
    /// without `mass`). Under inertiafromgeom="true" such a body takes its inertia from its
    /// geoms; a body without one keeps its `<inertial>` (MuJoCo 3.17.0 and 4.0.0: a body with
    /// no geom, only geoms of other groups, or only massless ones).
    pub(crate) fn has_massive_geom_in_range(&self, body: Node, range: &str) -> bool {
        let bounds: Vec<i64> = range
            .split_ascii_whitespace()
            .filter_map(|t| t.parse().ok())
            .collect();
        let (lo, hi) = match bounds[..] {
            [lo, hi] => (lo, hi),
            _ => (0, 5),
        };
        let zero = |n: Node, k: &str| {
            self.attr(n, k)
                .and_then(|v| v.trim().parse::<f64>().ok())
                .is_some_and(|x| x == 0.0)
        };
        let mut stack: Vec<Node> = self.elements(body).collect();
        while let Some(n) = stack.pop() {
            match self.tag(n) {
                "geom" => {
                    let group = self
                        .attr(n, "group")
                        .and_then(|v| v.trim().parse::<i64>().ok())
                        .unwrap_or(0);
                    let massless = match self.attr(n, "mass") {
                        Some(_) => zero(n, "mass"),
                        None => zero(n, "density"),
                    };
                    if (lo..=hi).contains(&group) && !massless {
                        return true;
                    }
                }
                "frame" => stack.extend(self.elements(n)),
                _ => {}
            }
        }
        false
    }

    /// The bodies whose mass and inertia MuJoCo infers from their geoms (under
    /// `inertiafromgeom="auto"`): those without an `<inertial>` that have a geom, directly or
    /// in a `<frame>` (or `<replicate>`) inside them.
    pub(crate) fn bodies_inferring_inertia(&self) -> Vec<Node> {
        let has_geom = |body: Node| {
            let mut stack: Vec<Node> = self.elements(body).collect();
            while let Some(n) = stack.pop() {
                match self.tag(n) {
                    "geom" => return true,
                    "frame" | "replicate" => stack.extend(self.elements(n)),
                    _ => {}
                }
            }
            false
        };
        self.descendants(self.root)
            .filter(|&n| self.tag(n) == "body")
            .filter(|&b| !self.elements(b).any(|c| self.tag(c) == "inertial"))
            .filter(|&b| has_geom(b))
            .collect()
    }
}
