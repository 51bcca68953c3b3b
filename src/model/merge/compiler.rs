//! A part's `compiler` settings against the base's: which must agree, which are converted
//! (the part's elements rewritten so that it compiles the same under the base's settings),
//! and why the others cannot be.

use super::angles::angles_checked;
use super::same_value;
use crate::document::Document;
use crate::document::inertia::{CompiledInertia, InertiaCompiler};
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind};

/// Compiler attributes that change the compiled model: a part must agree with the base on
/// them unless `convert_compiler` converts it (value if absent, as MuJoCo's defaults).
/// Not here: `saveinertial` (how MuJoCo saves a model, not what it compiles; checked by
/// experiment in 3.17.0 and 4.0.0) and the settings converted everywhere (`angle`,
/// `eulerseq`, `autolimits`).
pub(super) const MUST_AGREE: [(&str, &str); 11] = [
    ("boundmass", "0"),
    ("boundinertia", "0"),
    ("settotalmass", "-1"),
    ("balanceinertia", "false"),
    ("fitaabb", "false"),
    ("fusestatic", "false"),
    ("discardvisual", "false"),
    ("inertiafromgeom", "auto"),
    ("inertiagrouprange", "0 5"),
    ("alignfree", "false"),
    ("coordinate", "local"),
];

/// Compiler mass settings whose whole effect is the compiled bodies' masses and inertias,
/// with MuJoCo's default (under which they change nothing).
const INERTIA_ONLY: [(&str, &str); 4] = [
    ("boundmass", "0"),
    ("boundinertia", "0"),
    ("settotalmass", "-1"),
    ("balanceinertia", "false"),
];

/// The effective value of each `compiler` attribute (later elements win).
pub(super) fn compiler_settings(doc: &Document) -> Compiler<'_> {
    let compiler = crate::document::names::sym("compiler");
    let mut out = Compiler(Vec::new());
    for c in doc
        .elements(doc.root)
        .filter(|&n| doc.tag_sym(n) == Some(compiler))
    {
        for (k, v) in doc.attrs(c) {
            out.0.retain(|(name, _, _)| *name != k);
            out.0.push((k, v.trim(), c));
        }
    }
    out
}

/// The effective `compiler` settings of a document: (attribute, value, element), the last
/// element that sets an attribute winning. A handful of entries: a list beats a map.
pub(super) struct Compiler<'a>(Vec<(&'a str, &'a str, Node)>);

impl<'a> Compiler<'a> {
    pub(super) fn get(&self, attr: &str) -> Option<(&'a str, Node)> {
        self.0
            .iter()
            .find(|(k, _, _)| *k == attr)
            .map(|&(_, v, n)| (v, n))
    }
}

/// Why a compiler setting that differs between a part and the base cannot be converted
/// (the text after "has no exact conversion"): each of these applies to the whole merged
/// model, and nothing on the part's own elements can stand in for it. `compiles`: whether
/// the merge had a MuJoCo to write the part's inertias out with.
fn no_conversion_reason(attr: &str, base: &str, default: &str, compiles: bool) -> &'static str {
    match attr {
        "boundmass" | "boundinertia" | "settotalmass" | "balanceinertia" | "inertiafromgeom"
        | "inertiagrouprange" => {
            if !same_value(base, default) {
                ": the base's own setting would also change the part's masses and inertias"
            } else if compiles {
                ": the part's inertias could not be written out"
            } else {
                ": writing the part's inertias out needs a build with the `mujoco` feature"
            }
        }
        "fusestatic" => {
            ": the part's static bodies are fused into their parents when it compiles alone, \
             and a base that does not fuse them would keep them"
        }
        "discardvisual" => {
            ": it decides whether visual geoms, and the assets only they use, are dropped, \
             over the whole merged model"
        }
        "fitaabb" => {
            ": it decides how geoms fitted to meshes are sized, over the whole merged model"
        }
        "coordinate" => ": MuJoCo no longer reads global coordinates",
        _ => "",
    }
}

/// An [`InertiaCompiler`] that is a plain function.
type CompileFn = fn(&Document) -> Result<CompiledInertia, crate::Error>;

/// The build's own MuJoCo as an [`InertiaCompiler`], if it has one (the `mujoco` feature).
pub(crate) fn builtin_compiler() -> Option<CompileFn> {
    #[cfg(mjcf_mujoco)]
    {
        Some(|doc: &Document| {
            crate::mujoco::compiled_inertia(doc)
                .map_err(|e| crate::Error::bare(crate::ErrorKind::InertiaCompile(e.to_string())))
        })
    }
    #[cfg(not(mjcf_mujoco))]
    {
        None
    }
}

impl Document {
    /// When the part fuses static bodies (`fusestatic="true"`: a URDF robot, as MuJoCo's
    /// importer reads one) and this document does not, this document takes the setting
    /// and keeps each of its own bodies with `fuse="false"`, so that both compile as before
    /// (3.17.0 and 4.0.0): the conversion the other way round has no spelling.
    pub(super) fn adopt_static_fusion(&mut self, part: &Document) {
        let fuses = |d: &Document| {
            compiler_settings(d)
                .get("fusestatic")
                .is_some_and(|(v, _)| v == "true")
        };
        if !fuses(part) || fuses(self) {
            return;
        }
        let bodies: Vec<Node> = self
            .descendants(self.root)
            .filter(|&n| self.tag(n) == "body")
            .collect();
        for b in bodies {
            self.set_attr(b, "fuse", "false");
        }
        let compiler = crate::document::names::sym("compiler");
        let last = self
            .elements(self.root)
            .filter(|&n| self.tag_sym(n) == Some(compiler))
            .last();
        match last {
            Some(c) => self.set_attr(c, "fusestatic", "true"),
            None => {
                let c = self.new_element(compiler, None);
                match self.tree.first_child(self.root) {
                    Some(first) => self.tree.insert_before(first, c),
                    None => self.tree.append(self.root, c),
                }
                self.set_attr(c, "fusestatic", "true");
            }
        }
    }

    /// `part` converted as [`Document::merge`] converts it, carrying this document's
    /// `<compiler>` settings instead of its own, so that merging it here later converts
    /// nothing more (the batch tier prepares each object once and merges it into every
    /// variant). `None` when it needs no conversion.
    pub(crate) fn prepared_part(
        &self,
        part: &Document,
        errors: &mut Vec<Error>,
    ) -> Option<Document> {
        let mut conv = self.converted_part(part, errors, None)?;
        let compiler = crate::document::names::sym("compiler");
        let theirs: Vec<Node> = conv
            .elements(conv.root)
            .filter(|&n| conv.tag_sym(n) == Some(compiler))
            .collect();
        for n in theirs {
            conv.remove(n);
        }
        let first = conv.tree.first_child(conv.root);
        for c in self
            .elements(self.root)
            .filter(|&n| self.tag_sym(n) == Some(compiler))
        {
            let copy = conv.new_element(compiler, None);
            for (name, value) in self.attrs(c) {
                conv.set_attr(copy, name, value);
            }
            match first {
                Some(f) => conv.tree.insert_before(f, copy),
                None => conv.tree.append(conv.root, copy),
            }
        }
        Some(conv)
    }

    /// The part brought to this document's compiler settings (`None`: it already is), or
    /// the reasons it cannot be. Inertias that only MuJoCo knows come from `compile`, else
    /// from the build's own MuJoCo if it has one.
    pub(super) fn converted_part(
        &self,
        part: &Document,
        errors: &mut Vec<Error>,
        compile: Option<&mut InertiaCompiler<'_>>,
    ) -> Option<Document> {
        let ours = compiler_settings(self);
        let theirs = compiler_settings(part);
        let same = |k: &str| ours.get(k).map(|v| v.0) == theirs.get(k).map(|v| v.0);
        let relevant = ["angle", "eulerseq", "autolimits", "inertiafromgeom"];
        let agree = MUST_AGREE.iter().all(|(k, _)| same(k)) && relevant.iter().all(|k| same(k));
        if agree {
            return None;
        }
        let mut part = part.clone();
        let mut builtin = builtin_compiler();
        let compile = match compile {
            Some(c) => Some(c),
            None => builtin.as_mut().map(|f| f as &mut InertiaCompiler<'_>),
        };
        self.convert_compiler(&mut part, errors, compile);
        Some(part)
    }

    /// Brings `part` to this document's compiler settings, or reports why it cannot be.
    /// The mass settings are converted only with a `compile` (MuJoCo) to write the part's
    /// inertias out with.
    fn convert_compiler(
        &self,
        part: &mut Document,
        errors: &mut Vec<Error>,
        mut compile: Option<&mut InertiaCompiler<'_>>,
    ) {
        let compiles = compile.is_some();
        // A part's inertiafromgeom="true" alone becomes "auto" below, in every build, by
        // dropping the <inertial>s that "true" overrides. With mass settings, another
        // inertiagrouprange or a base with "false" as well, a merge with MuJoCo (the build's,
        // or the caller's `compile`) first makes it "auto" with every body's compiled inertia
        // written out (`write_compiled_inertials_from_geoms`), after which those settings have nothing
        // left to change: a locomotion model with `inertiafromgeom="true"
        // settotalmass="14"` (Gymnasium's half_cheetah) merges exactly into a base with
        // MuJoCo's defaults.
        if let Some(compile) = compile.as_deref_mut() {
            let (ours, theirs) = (compiler_settings(self), compiler_settings(part));
            let setting = |m: &Compiler<'_>, k: &str, d: &str| {
                m.get(k)
                    .map_or_else(|| d.to_string(), |(v, _)| v.to_string())
            };
            let differs =
                |k: &str, d: &str| !same_value(&setting(&ours, k, d), &setting(&theirs, k, d));
            let (bi, pi) = (
                setting(&ours, "inertiafromgeom", "auto"),
                setting(&theirs, "inertiafromgeom", "auto"),
            );
            let more = INERTIA_ONLY.iter().any(|&(k, d)| differs(k, d))
                || differs("inertiagrouprange", "0 5")
                || bi == "false";
            drop((ours, theirs));
            if pi == "true" && bi != "true" && more {
                let at = part.location(part.root);
                if let Err(e) = part.write_compiled_inertials_from_geoms(compile) {
                    errors.push(Error::at(
                        at,
                        ErrorKind::Invalid(format!(
                            "cannot merge: compiler inertiafromgeom=\"true\" differs from the \
                             base's and the part's inertias could not be written out: {e}"
                        )),
                    ));
                    return;
                }
            }
        }
        let base = compiler_settings(self);
        let theirs = compiler_settings(part);
        let value = |m: &Compiler<'_>, k: &str, d: &str| {
            m.get(k)
                .map_or_else(|| d.to_string(), |(v, _)| v.to_string())
        };
        // inertiafromgeom "true" ignores <inertial>; under the base's "auto" the same model is
        // the part without its <inertial> elements.
        let (bi, pi) = (
            value(&base, "inertiafromgeom", "auto"),
            value(&theirs, "inertiafromgeom", "auto"),
        );
        let drop_inertials = pi == "true" && bi == "auto";
        // With MuJoCo, mass settings are converted: each body's inertia is written out as
        // MuJoCo compiles the part alone, after which the setting changes nothing. That is
        // exact when the merged model reads <inertial> (inertiafromgeom not "true") and the
        // base leaves the setting at MuJoCo's default (no bound, no rescaling of its own).
        let mut converted: Vec<&str> = {
            let mut all = Vec::new();
            let mut converted = Vec::new();
            if let Some(compile) = compile
                && bi != "true"
                && pi != "true"
            {
                for (attr, default) in INERTIA_ONLY {
                    let (b, p) = (value(&base, attr, default), value(&theirs, attr, default));
                    if !same_value(&b, &p) && same_value(&b, default) {
                        all.push(attr);
                    }
                }
                if pi == "false" && bi == "auto" {
                    all.push("inertiafromgeom");
                }
                let (b, p) = (
                    value(&base, "inertiagrouprange", "0 5"),
                    value(&theirs, "inertiagrouprange", "0 5"),
                );
                let range = !same_value(&b, &p);
                // A base with "false" reads only <inertial>: the part's inferred ones suffice.
                let auto_to_false = pi == "auto" && bi == "false";
                if range || auto_to_false || !all.is_empty() {
                    let names = all
                        .iter()
                        .copied()
                        .chain(range.then_some("inertiagrouprange"))
                        .chain(auto_to_false.then_some("inertiafromgeom"))
                        .collect::<Vec<_>>();
                    let at = part.location(theirs.get(names[0]).map_or(part.root, |(_, n)| n));
                    let written = part.write_compiled_inertials(!all.is_empty(), true, compile);
                    if let Err(e) = written {
                        errors.push(Error::at(
                            at,
                            ErrorKind::Invalid(format!(
                                "cannot merge: compiler {} differ(s) from the base's and the \
                                 part's inertias could not be written out: {e}",
                                names.join(", ")
                            )),
                        ));
                        return;
                    }
                    converted = names;
                }
            }
            converted
        };
        let theirs = compiler_settings(part);
        // alignfree is the default of each <freejoint>'s own `align`: a part's free joints
        // keep its setting when they say it themselves. A <joint type="free"> has no
        // `align`, so a part with one on a body MuJoCo would align is refused (below).
        let align = value(&theirs, "alignfree", "false");
        // The first <joint type="free"> MuJoCo would align, which no `align` can reach.
        let unalignable = part
            .descendants(part.root)
            .find(|&n| part.is_free_joint_element(n));
        let align_free_joints =
            !same_value(&value(&base, "alignfree", "false"), &align) && unalignable.is_none();
        if align_free_joints {
            converted.push("alignfree");
        }
        // A base that fuses static bodies would fuse the part's too; `fuse="false"` on each
        // of the part's bodies keeps them (3.17.0 and 4.0.0). The other way round (a part
        // that fuses its own, into a base that does not) has no conversion.
        let keep_bodies = value(&base, "fusestatic", "false") == "true"
            && value(&theirs, "fusestatic", "false") == "false";
        if keep_bodies {
            converted.push("fusestatic");
        }
        for (attr, default) in MUST_AGREE {
            if (attr == "inertiafromgeom" && drop_inertials) || converted.contains(&attr) {
                continue;
            }
            let (b, p) = (value(&base, attr, default), value(&theirs, attr, default));
            // inertiagrouprange only picks the geoms a body's inertia is inferred from: a part
            // none of whose bodies infers one (each body with geoms has its <inertial>, and
            // <inertial> counts in the merged model: inertiafromgeom is not "true") compiles
            // the same under any range. `mujoco::write_inertials` makes a part so.
            if attr == "inertiagrouprange"
                && !same_value(&b, &p)
                && bi != "true"
                && pi != "true"
                && part.bodies_inferring_inertia().is_empty()
            {
                continue;
            }
            if !same_value(&b, &p) {
                let at = theirs.get(attr).map(|(_, n)| n).unwrap_or(part.root);
                let why = match attr {
                    "alignfree" => unalignable
                        .map(|j| {
                            let l = part.location(j);
                            format!(
                                ": the <joint type=\"free\"> at {}:{}:{} has no `align` of its \
                                 own to keep the part's setting (only <freejoint> has one)",
                                l.file.display(),
                                l.line,
                                l.col
                            )
                        })
                        .unwrap_or_default(),
                    _ => no_conversion_reason(attr, &b, default, compiles).to_string(),
                };
                errors.push(part.error_at(
                    at,
                    ErrorKind::Invalid(format!(
                        "cannot merge: compiler {attr}=\"{p}\" differs from the base's \"{b}\" and has no exact conversion{why}"
                    )),
                ));
            }
        }
        let (ba, pa) = (
            value(&base, "autolimits", "true"),
            value(&theirs, "autolimits", "true"),
        );
        drop(theirs);
        if !errors.is_empty() {
            return;
        }
        if keep_bodies {
            let bodies: Vec<Node> = part
                .descendants(part.root)
                .filter(|&n| part.tag(n) == "body")
                .collect();
            for b in bodies {
                part.set_attr(b, "fuse", "false");
            }
        }
        if align_free_joints {
            let free: Vec<Node> = part
                .descendants(part.root)
                .filter(|&n| part.tag(n) == "freejoint")
                .filter(|&n| part.attr(n, "align").is_none_or(|a| a.trim() == "auto"))
                .collect();
            for n in free {
                part.set_attr(n, "align", &align);
            }
        }
        if drop_inertials {
            let range = value(&compiler_settings(part), "inertiagrouprange", "0 5");
            let inertials: Vec<Node> = part
                .descendants(part.root)
                .filter(|&n| part.tag(n) == "inertial")
                .filter(|&n| {
                    part.parent(n)
                        .is_some_and(|b| part.has_massive_geom_in_range(b, &range))
                })
                .collect();
            for n in inertials {
                part.remove(n);
            }
        }
        let (base_angles, part_angles) = match (angles_checked(self), angles_checked(part)) {
            (Ok(b), Ok(p)) => (b, p),
            (b, p) => return errors.extend(b.err().into_iter().chain(p.err())),
        };
        if base_angles.seq != part_angles.seq {
            part.rewrite_euler_as_quat(&part_angles);
        }
        if base_angles.degrees != part_angles.degrees {
            part.convert_angles(part_angles.degrees, base_angles.degrees);
        }
        if ba != pa {
            part.make_limits_explicit(pa == "true");
        }
    }

    /// Writes `limited`-style flags explicitly where a range is given without one, with the
    /// meaning they had under `autolimits` (for a base with the other setting).
    fn make_limits_explicit(&mut self, autolimits: bool) {
        const PAIRS: [(&str, &str); 5] = [
            ("range", "limited"),
            ("ctrlrange", "ctrllimited"),
            ("forcerange", "forcelimited"),
            ("actrange", "actlimited"),
            ("actuatorfrcrange", "actuatorfrclimited"),
        ];
        let value = if autolimits { "true" } else { "false" };
        let nodes: Vec<Node> = self.descendants(self.root).collect();
        for n in nodes {
            if !matches!(self.tag(n), "joint" | "spatial" | "fixed")
                && self.parent(n).is_none_or(|p| self.tag(p) != "actuator")
            {
                continue;
            }
            for (range, flag) in PAIRS {
                if self.attr(n, range).is_some() && self.attr(n, flag).is_none() {
                    self.set_attr(n, flag, value);
                }
            }
        }
    }
}
