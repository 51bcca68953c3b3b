//! Actuator shortcuts and `<general>`'s raw control model, translated both ways: a
//! shortcut's parameters spelled out as its documented table, and read back off a `general`
//! dummy the way MuJoCo pre-reads them.

use super::Resolver;
use super::classes::AttrSet;
use crate::document::Document;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind};

impl Resolver<'_> {
    /// A shortcut's documented table of `general` attributes (XMLreference, actuator
    /// shortcuts), for parameters `s` over the shortcut's documented defaults.
    pub(super) fn shortcut_table(
        &mut self,
        tag: &str,
        s: &AttrSet,
        node: Node,
    ) -> Result<AttrSet, Error> {
        let get = |doc: &Document, k: &str| -> Option<Vec<f64>> {
            let sym = crate::document::names::known(k)?;
            let r = s.get(sym)?;
            Some(
                doc.str(r)
                    .split_ascii_whitespace()
                    .map(|t| t.parse().unwrap_or(0.0))
                    .collect(),
            )
        };
        let one = |doc: &Document, k: &str, d: f64| {
            get(doc, k).and_then(|v| v.first().copied()).unwrap_or(d)
        };
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let damping = |doc: &Document| -> f64 {
            if let Some(dr) = get(doc, "dampratio").and_then(|v| v.first().copied()) {
                dr
            } else {
                -one(doc, "kv", 0.0)
            }
        };
        let mut out: Vec<(&str, String)> = Vec::new();
        match tag {
            "motor" => {
                out.extend([("dyntype", "none".into()), ("dynprm", "1 0 0".into())]);
                out.extend([("gaintype", "fixed".into()), ("gainprm", "1 0 0".into())]);
                out.extend([("biastype", "none".into()), ("biasprm", "0 0 0".into())]);
            }
            "position" | "intvelocity" => {
                let kp = one(self.doc, "kp", 1.0);
                if tag == "intvelocity" {
                    out.extend([("dyntype", "integrator".into()), ("dynprm", "1 0 0".into())]);
                } else if let Some(tc) = get(self.doc, "timeconst").and_then(|v| v.first().copied())
                {
                    out.extend([
                        ("dyntype", "filterexact".into()),
                        ("dynprm", list(&[tc, 0.0, 0.0])),
                    ]);
                } else {
                    out.extend([("dyntype", "none".into()), ("dynprm", "1 0 0".into())]);
                }
                out.extend([
                    ("gaintype", "fixed".into()),
                    ("gainprm", list(&[kp, 0.0, 0.0])),
                ]);
                out.extend([
                    ("biastype", "affine".into()),
                    ("biasprm", list(&[0.0, -kp, damping(self.doc)])),
                ]);
                out.push((
                    "input",
                    if tag == "position" { "pos" } else { "vel" }.into(),
                ));
                if let Some(ir) = get(self.doc, "inheritrange") {
                    out.push(("inheritrange", list(&ir)));
                }
            }
            "velocity" => {
                let kv = one(self.doc, "kv", 1.0);
                out.extend([("dyntype", "none".into()), ("dynprm", "1 0 0".into())]);
                out.extend([
                    ("gaintype", "fixed".into()),
                    ("gainprm", list(&[kv, 0.0, 0.0])),
                ]);
                out.extend([
                    ("biastype", "affine".into()),
                    ("biasprm", list(&[0.0, 0.0, -kv])),
                ]);
                out.push(("input", "vel".into()));
            }
            "damper" => {
                let kv = one(self.doc, "kv", 0.0);
                out.extend([("dyntype", "none".into()), ("dynprm", "1 0 0".into())]);
                out.extend([
                    ("gaintype", "affine".into()),
                    ("gainprm", list(&[0.0, 0.0, -kv])),
                ]);
                out.extend([("biastype", "none".into()), ("biasprm", "0 0 0".into())]);
                out.push(("ctrllimited", "true".into()));
            }
            "cylinder" => {
                let tc = one(self.doc, "timeconst", 1.0);
                let mut area = one(self.doc, "area", 1.0);
                let diameter = one(self.doc, "diameter", -1.0);
                if diameter >= 0.0 {
                    area = std::f64::consts::PI / 4.0 * diameter * diameter;
                }
                let mut bias = get(self.doc, "bias").unwrap_or_default();
                bias.resize(3, 0.0);
                out.extend([
                    ("dyntype", "filter".into()),
                    ("dynprm", list(&[tc, 0.0, 0.0])),
                ]);
                out.extend([
                    ("gaintype", "fixed".into()),
                    ("gainprm", list(&[area, 0.0, 0.0])),
                ]);
                out.extend([("biastype", "affine".into()), ("biasprm", list(&bias))]);
                out.push(("input", "pressure".into()));
            }
            "muscle" => {
                let mut tc = get(self.doc, "timeconst").unwrap_or_else(|| vec![0.01, 0.04]);
                tc.resize(2, 0.0);
                let mut range = get(self.doc, "range").unwrap_or_else(|| vec![0.75, 1.05]);
                range.resize(2, 0.0);
                let prm = [
                    range[0],
                    range[1],
                    one(self.doc, "force", -1.0),
                    one(self.doc, "scale", 200.0),
                    one(self.doc, "lmin", 0.5),
                    one(self.doc, "lmax", 1.6),
                    one(self.doc, "vmax", 1.5),
                    one(self.doc, "fpmax", 1.3),
                    one(self.doc, "fvmax", 1.2),
                ];
                let tausmooth = one(self.doc, "tausmooth", 0.0);
                out.extend([
                    ("dyntype", "muscle".into()),
                    ("dynprm", list(&[tc[0], tc[1], tausmooth])),
                ]);
                out.extend([("gaintype", "muscle".into()), ("gainprm", list(&prm))]);
                out.extend([("biastype", "muscle".into()), ("biasprm", list(&prm))]);
            }
            "adhesion" => {
                let gain = one(self.doc, "gain", 1.0);
                out.extend([("dyntype", "none".into()), ("dynprm", "1 0 0".into())]);
                out.extend([
                    ("gaintype", "fixed".into()),
                    ("gainprm", list(&[gain, 0.0, 0.0])),
                ]);
                out.extend([("biastype", "none".into()), ("biasprm", "0 0 0".into())]);
                out.push(("ctrllimited", "true".into()));
            }
            other => {
                return Err(self.doc.error_at(
                    node,
                    ErrorKind::Inexpressible(format!(
                        "the <{other}> shortcut cannot be rewritten as <general> yet"
                    )),
                ));
            }
        }
        Ok(self.attr_set(out))
    }

    /// Attribute pairs as a class dummy, their values added to the document's strings.
    fn attr_set(&mut self, pairs: Vec<(&str, String)>) -> AttrSet {
        let mut set = AttrSet::default();
        for (k, v) in pairs {
            let name = self.doc.intern(k);
            let value = self.doc.push_str(&v);
            set.set(name, value);
        }
        set
    }

    /// A shortcut's parameters read off a `general` dummy's raw control model, the way
    /// MuJoCo pre-reads them (gain, bias and dynamics parameters in the shortcut's layout).
    pub(super) fn params_from_general(
        &mut self,
        control: &AttrSet,
        tag: &str,
        node: Node,
    ) -> Result<AttrSet, Error> {
        let nums = |doc: &Document, name: &str, builtin: &[f64]| -> Vec<f64> {
            let mut v = builtin.to_vec();
            v.resize(10, 0.0);
            if let Some(r) = crate::document::names::known(name).and_then(|s| control.get(s)) {
                for (i, t) in doc.str(r).split_ascii_whitespace().enumerate().take(10) {
                    v[i] = t.parse().unwrap_or(0.0);
                }
            }
            v
        };
        let g = nums(self.doc, "gainprm", &[1.0]);
        let b = nums(self.doc, "biasprm", &[0.0]);
        let d = nums(self.doc, "dynprm", &[1.0]);
        let dyntype = crate::document::names::known("dyntype")
            .and_then(|s| control.get(s))
            .map(|r| self.doc.str(r).trim().to_string())
            .unwrap_or_else(|| "none".into());
        let inheritrange = crate::document::names::known("inheritrange")
            .and_then(|s| control.get(s))
            .map(|r| self.doc.str(r).to_string());
        let mut out: Vec<(&str, String)> = Vec::new();
        let num = |x: f64| format!("{x}");
        let damping = |out: &mut Vec<(&str, String)>| {
            if b[2] < 0.0 {
                out.push(("kv", num(-b[2])));
            } else if b[2] > 0.0 {
                out.push(("dampratio", num(b[2])));
            }
        };
        match tag {
            "motor" => {}
            "position" | "intvelocity" => {
                out.push(("kp", num(g[0])));
                damping(&mut out);
                if dyntype == "filterexact" {
                    out.push(("timeconst", num(d[0])));
                }
                if let Some(r) = inheritrange {
                    out.push(("inheritrange", r));
                }
            }
            "velocity" => out.push(("kv", num(g[0]))),
            "damper" => out.push(("kv", num(-g[2]))),
            "adhesion" => out.push(("gain", num(g[0]))),
            "cylinder" => {
                out.push(("timeconst", num(d[0])));
                out.push(("area", num(g[0])));
                out.push(("bias", format!("{} {} {}", num(b[0]), num(b[1]), num(b[2]))));
            }
            "muscle" => {
                out.push(("timeconst", format!("{} {}", num(d[0]), num(d[1]))));
                out.push(("tausmooth", num(d[2])));
                out.push(("range", format!("{} {}", num(g[0]), num(g[1]))));
                for (i, k) in ["force", "scale", "lmin", "lmax", "vmax", "fpmax", "fvmax"]
                    .iter()
                    .enumerate()
                {
                    out.push((k, num(g[2 + i])));
                }
            }
            other => {
                return Err(self.doc.error_at(
                    node,
                    ErrorKind::Inexpressible(format!(
                        "<{other}> would pre-read its parameters from a <general> class default, \
                         through a mapping of gain, bias and dynamics parameters that is not \
                         reproduced for <{other}> (give them on the <{other}> or in a <{other}> \
                         default)"
                    )),
                ));
            }
        }
        Ok(self.attr_set(out))
    }
}
