//! Merging models into one scene without changing any part's physics.
//!
//! A part's `<worldbody>` children go to the base's worldbody or into a named body of the
//! base (their poses then relative to it); every other section is carried over. Assets with
//! the same tag, name and content become one; the same name with other content is an error
//! naming both. Parts written with other `compiler` settings are converted to the base's
//! (angle units, Euler sequence, automatic limits) or refused where no exact conversion
//! exists. `option`, `size`, `visual` and `statistic` come from the base (conflicts are
//! warnings). Keyframes are remapped onto the merged model's joints, actuators and mocap
//! bodies, each part's values landing on its own objects and everything else taking its
//! default; keys of the same name can be fused into one.

use crate::document::names::Sym;
use crate::document::tree::Node;
use crate::document::{Document, Section};
use crate::error::{Error, ErrorKind, Errors};
use crate::model::geometry::{self, Angles};

use import::Import;
use keys::{implicit_keys, keys_of};
use layout::Layout;

mod assets;
mod defaults;
mod free_joints;
mod import;
mod inertia;
mod keys;
mod layout;
mod settings;

/// How to merge.
#[derive(Clone, Debug, Default)]
pub struct MergeOptions {
    /// Fuse each part key named `part_prefix + N` into the base key named `N` (say, every
    /// part's "home" pose into the scene's "home" key), instead of keeping it separate.
    pub fuse_keys: bool,
    /// The prefix the part's names carry (used to match keys when fusing).
    pub part_prefix: String,
}

/// One part of [`Document::merge_all`]: the document (names already prefixed), the body
/// of the scene it goes into (`None`: the world body), and its prefix (to fuse keys).
#[derive(Clone, Copy, Debug)]
pub struct MergePart<'a> {
    /// The part.
    pub doc: &'a Document,
    /// The body of the scene it goes into; `None` for the world body.
    pub into: Option<&'a str>,
    /// The prefix its names carry.
    pub prefix: &'a str,
}

/// What a merge did besides merging: the settings of the part that the base overrode.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MergeReport {
    /// One line per ignored or adjusted setting, with its position in the part.
    pub warnings: Vec<String>,
    /// How many of the part's assets were already in the base (same tag, name, content).
    pub shared_assets: usize,
}

/// Compiler attributes that change the compiled model: a part must agree with the base on
/// them unless `convert_compiler` converts it (value if absent, as MuJoCo's defaults).
/// Not here: `saveinertial` (how MuJoCo saves a model, not what it compiles; checked by
/// experiment in 3.17.0 and 4.0.0) and the settings converted everywhere (`angle`,
/// `eulerseq`, `autolimits`).
const MUST_AGREE: [(&str, &str); 11] = [
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
#[cfg(mjcf_mujoco)]
const INERTIA_ONLY: [(&str, &str); 4] = [
    ("boundmass", "0"),
    ("boundinertia", "0"),
    ("settotalmass", "-1"),
    ("balanceinertia", "false"),
];

/// The effective value of each `compiler` attribute (later elements win).
fn compiler_settings(doc: &Document) -> Compiler<'_> {
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
struct Compiler<'a>(Vec<(&'a str, &'a str, Node)>);

impl<'a> Compiler<'a> {
    fn get(&self, attr: &str) -> Option<(&'a str, Node)> {
        self.0
            .iter()
            .find(|(k, _, _)| *k == attr)
            .map(|&(_, v, n)| (v, n))
    }
}

/// Why a compiler setting that differs between a part and the base cannot be converted
/// (the text after "has no exact conversion"): each of these applies to the whole merged
/// model, and nothing on the part's own elements can stand in for it.
fn no_conversion_reason(attr: &str, base: &str, default: &str) -> &'static str {
    match attr {
        "boundmass" | "boundinertia" | "settotalmass" | "balanceinertia" | "inertiafromgeom"
        | "inertiagrouprange" => {
            if !same_value(base, default) {
                ": the base's own setting would also change the part's masses and inertias"
            } else if cfg!(mjcf_mujoco) {
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

fn same_value(a: &str, b: &str) -> bool {
    let ta: Vec<&str> = a.split_ascii_whitespace().collect();
    let tb: Vec<&str> = b.split_ascii_whitespace().collect();
    ta.len() == tb.len()
        && ta
            .iter()
            .zip(&tb)
            .all(|(x, y)| match (x.parse::<f64>(), y.parse::<f64>()) {
                (Ok(p), Ok(q)) => p == q,
                _ => x == y,
            })
}

/// The shortest text that reads back as `x` (plain or with an exponent).
pub(crate) fn fmt_num(x: f64) -> String {
    let plain = format!("{x}");
    let exp = format!("{x:e}");
    if exp.len() < plain.len() { exp } else { plain }
}

/// Names this module looks up often, interned once.
struct Syms {
    name: Sym,
    file: Sym,
    euler: Sym,
    axisangle: Sym,
    joint: Sym,
    ty: Sym,
    range: Sym,
    reference: Sym,
    springref: Sym,
}

fn syms() -> &'static Syms {
    static SYMS: std::sync::OnceLock<Syms> = std::sync::OnceLock::new();
    SYMS.get_or_init(|| {
        let s = crate::document::names::sym;
        Syms {
            name: s("name"),
            file: s("file"),
            euler: s("euler"),
            axisangle: s("axisangle"),
            joint: s("joint"),
            ty: s("type"),
            range: s("range"),
            reference: s("ref"),
            springref: s("springref"),
        }
    })
}

impl Document {
    /// The level of `node` (the root is level 1).
    fn depth_of(&self, node: Node) -> usize {
        std::iter::successors(Some(node), |&n| self.parent(n)).count()
    }

    /// How many levels the deepest element below `node` is under it (0 for a leaf).
    fn depth_below(&self, node: Node) -> usize {
        let mut deepest = 0;
        let mut stack = vec![(node, 0)];
        while let Some((n, d)) = stack.pop() {
            deepest = deepest.max(d);
            stack.extend(self.children(n).map(|k| (k, d + 1)));
        }
        deepest
    }
}

/// A document's angle settings ([`Angles::of`]) where it must be used to convert angles:
/// errors at the `<compiler>` at fault, quoting at most a little of a value; and an
/// `eulerseq` with letters other than `xyzXYZ` refused when an `euler` attribute would be
/// read under it, which MuJoCo refuses too (converting it would give a wrong rotation).
fn angles_checked(doc: &Document) -> Result<Angles, Error> {
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
    /// Merges `part` into this document (see the module documentation): into the world
    /// body, or into the body named `into`. On error nothing changes and every problem found
    /// is reported.
    ///
    /// ```
    /// use mjcf_forge::{Document, MergeOptions};
    /// let mut arm = Document::from_str(
    ///     r#"<mujoco><worldbody><body name="hand"><joint name="wrist"/><geom size="0.1"/></body></worldbody></mujoco>"#,
    ///     ".",
    /// )?;
    /// let mut gripper = Document::from_str(
    ///     r#"<mujoco><worldbody><body name="finger"><joint name="slide" type="slide"/><geom size="0.01"/></body></worldbody></mujoco>"#,
    ///     ".",
    /// )?;
    /// gripper.apply_prefix("g0_")?;
    /// arm.merge(&gripper, Some("hand"), &MergeOptions::default())?;
    /// assert!(arm.to_xml_string().contains(r#"<body name="hand"><joint name="wrist"/><geom size="0.1"/><body name="g0_finger">"#));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn merge(
        &mut self,
        part: &Document,
        into: Option<&str>,
        options: &MergeOptions,
    ) -> Result<MergeReport, Errors> {
        let part = MergePart {
            doc: part,
            into,
            prefix: &options.part_prefix,
        };
        self.merge_all(&[part], options.fuse_keys)
    }

    /// Merges several parts in order, as [`Document::merge`] does one by one, but checks
    /// every name of every part against the base and each other once, up front (the base is
    /// walked once, not once per part). On error nothing changes.
    ///
    /// ```
    /// use mjcf_forge::{Document, MergePart};
    /// let mut scene = Document::from_str(r#"<mujoco><worldbody><geom type="plane" size="1 1 1"/></worldbody></mujoco>"#, ".")?;
    /// let mut cube = Document::from_str(r#"<mujoco><worldbody><body name="cube"><freejoint/><geom type="box" size="0.1 0.1 0.1"/></body></worldbody></mujoco>"#, ".")?;
    /// let mut a = cube.clone();
    /// a.apply_prefix("a_")?;
    /// cube.apply_prefix("b_")?;
    /// let parts = [MergePart { doc: &a, into: None, prefix: "a_" }, MergePart { doc: &cube, into: None, prefix: "b_" }];
    /// scene.merge_all(&parts, false)?;
    /// assert!(scene.find_body("a_cube").is_some() && scene.find_body("b_cube").is_some());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn merge_all(
        &mut self,
        parts: &[MergePart<'_>],
        fuse_keys: bool,
    ) -> Result<MergeReport, Errors> {
        let clashes = self.name_clashes(&parts.iter().map(|p| p.doc).collect::<Vec<_>>());
        if !clashes.is_empty() {
            return Err(Errors(clashes));
        }
        // Every check runs before the document changes, except keyframe remapping: with
        // keys, or with several parts, work on a copy so that a failure changes nothing.
        let has_keys = |d: &Document| !keys_of(d).is_empty() || implicit_keys(d) > 0;
        let keys = has_keys(self) || parts.iter().any(|p| has_keys(p.doc));
        // A base smaller than its part may adopt the part's angle unit before the checks
        // (`adopt_angle_unit_if_smaller`): then it too works on a copy (a small one).
        if !keys && parts.len() == 1 && self.node_count() >= parts[0].doc.node_count() {
            self.merge_unchecked(parts, fuse_keys)
        } else {
            let mut merged = self.clone();
            let report = merged.merge_unchecked(parts, fuse_keys)?;
            *self = merged;
            Ok(report)
        }
    }

    /// [`Document::merge_all`] without its two guards: no name check up front, and on error
    /// the document is left half merged. For callers that checked the names themselves
    /// and drop the document on error (the batch tier, which merges objects into a fresh
    /// copy of its template for every variant).
    pub(crate) fn merge_unchecked(
        &mut self,
        parts: &[MergePart<'_>],
        fuse_keys: bool,
    ) -> Result<MergeReport, Errors> {
        // Room for every part at once: reserving per part would reallocate (and copy) the
        // whole scene once per part.
        let nodes: usize = parts.iter().map(|p| p.doc.node_count()).sum();
        self.tree.reserve(nodes);
        self.attrs
            .reserve(parts.iter().map(|p| p.doc.attrs.len()).sum());
        self.strings
            .reserve(parts.iter().map(|p| p.doc.strings.len()).sum());
        self.spans.reserve(nodes);
        let mut report = MergeReport::default();
        for p in parts {
            let options = MergeOptions {
                fuse_keys,
                part_prefix: p.prefix.to_string(),
            };
            let r = self.merge_in_place(p.doc, p.into, &options)?;
            report.warnings.extend(r.warnings);
            report.shared_assets += r.shared_assets;
        }
        Ok(report)
    }

    fn merge_in_place(
        &mut self,
        part: &Document,
        into: Option<&str>,
        options: &MergeOptions,
    ) -> Result<MergeReport, Errors> {
        let mut report = MergeReport::default();
        let mut errors: Vec<Error> = Vec::new();
        self.adopt_angle_unit_if_smaller(part);
        let converted = self.converted_part(part, &mut errors);
        if !errors.is_empty() {
            return Err(Errors(errors));
        }
        let mut part: &Document = converted.as_ref().unwrap_or(part);

        // Keys that `<size nkey>` adds become `<key/>`s, in the base too when the part
        // brings keys (else the base's `nkey` would count them): see `implicit_keys`.
        let with_keys;
        if implicit_keys(part) > 0 {
            let mut p = part.clone();
            p.write_implicit_keys();
            with_keys = p;
            part = &with_keys;
        }
        if !keys_of(part).is_empty() {
            self.write_implicit_keys();
        }

        // Keyframes are remapped from the layouts before the merge.
        let base_keys = keys_of(self);
        let part_keys = keys_of(part);
        let has_keys = !base_keys.is_empty() || !part_keys.is_empty();
        let (base_layout, part_layout) = if has_keys {
            (Layout::of(self), Layout::of(part))
        } else {
            (Layout::default(), Layout::default())
        };

        let target = match into {
            None => None,
            Some(name) => match self.find_body(name) {
                Some(b) => Some(b),
                None => {
                    return Err(Error::at(
                        self.location(self.root),
                        ErrorKind::Invalid(format!(
                            "merge target body '{name}' is not in the base model"
                        )),
                    )
                    .into());
                }
            },
        };

        // Checks before changes: free bodies, assets, residual classes.
        let assets = self.asset_decisions(part, &mut errors);
        if let (Some(into), Some(world)) = (into, part.find_section(Section::Worldbody)) {
            for child in part.elements(world) {
                if part.has_free_joint(child) {
                    errors.push(part.error_at(
                        child,
                        ErrorKind::Invalid(format!(
                            "<{}> has a free joint: it can only be merged into the world body, not into '{into}'",
                            part.tag(child)
                        )),
                    ));
                }
            }
        }
        self.check_residual_defaults(part, &mut errors);
        // What is merged must load again: a part nested into a deep body can pass the depth
        // a load accepts (and MuJoCo's own, which is lower).
        if let Some(world) = part.find_section(Section::Worldbody) {
            let at = target.map_or(2, |t| self.depth_of(t));
            let depth = at + part.depth_below(world);
            if depth > self.limits.max_depth as usize {
                let msg = format!(
                    "merged here, the part would nest elements {depth} levels deep, more than {} (Limits::max_depth)",
                    self.limits.max_depth
                );
                errors.push(part.error_at(world, ErrorKind::Invalid(msg)));
            }
        }
        if !errors.is_empty() {
            return Err(Errors(errors));
        }
        let target = match target {
            Some(t) => t,
            None => self.section(Section::Worldbody),
        };

        // Room for the part up front: growing these one push at a time reallocates (and
        // copies) the whole scene again and again.
        self.tree.reserve(part.node_count());
        self.attrs.reserve(part.attrs.len());
        self.strings.reserve(part.strings.len());
        self.spans.reserve(part.node_count());
        let file_offset = self.adopt_files(part);
        let mut imp = Import::new(file_offset, has_keys);
        let top: Vec<Node> = part.elements(part.root).collect();
        for section in top {
            let tag = part.tag(section).to_string();
            let imp = &mut imp;
            match tag.as_str() {
                "compiler" => {}
                "option" | "size" | "visual" | "statistic" => {
                    self.settings_from_part(part, section, &mut report);
                }
                "default" => self.merge_residual_defaults(part, section, file_offset),
                "asset" => {
                    let dest = self.section(Section::Asset);
                    for (a, shared) in part.elements(section).zip(assets.iter()) {
                        if *shared {
                            report.shared_assets += 1;
                        } else {
                            self.import(part, a, dest, imp);
                        }
                    }
                }
                "worldbody" => {
                    for child in part.elements(section).collect::<Vec<_>>() {
                        self.import(part, child, target, imp);
                    }
                }
                "keyframe" => {}
                other => {
                    let dest = match Section::from_tag(other) {
                        Some(s) => self.section(s),
                        None => {
                            let root = self.root;
                            self.import(part, section, root, imp);
                            continue;
                        }
                    };
                    for child in part.elements(section).collect::<Vec<_>>() {
                        self.import(part, child, dest, imp);
                    }
                }
            }
        }
        if has_keys {
            let map = imp.map.take().unwrap_or_default();
            self.remap_keys(
                &base_layout,
                &base_keys,
                part,
                &part_layout,
                &part_keys,
                &map,
                options,
            )?;
        }
        Ok(report)
    }

    /// The body named `name` anywhere in the kinematic tree.
    pub fn find_body(&self, name: &str) -> Option<Node> {
        static SYMS: std::sync::OnceLock<(Sym, Sym)> = std::sync::OnceLock::new();
        let world = self.find_section(Section::Worldbody)?;
        let &(body, name_sym) = SYMS.get_or_init(|| {
            (
                crate::document::names::sym("body"),
                crate::document::names::sym("name"),
            )
        });
        self.descendants(world)
            .find(|&n| self.tag_sym(n) == Some(body) && self.attr_sym(n, name_sym) == Some(name))
    }
}

impl Document {
    /// When the part differs from this document only in the angle unit and this document is
    /// the smaller, converts this document to the part's unit instead (the same compiled
    /// model, less to rewrite: an arena receiving a robot, say).
    fn adopt_angle_unit_if_smaller(&mut self, part: &Document) {
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

    /// The part brought to this document's compiler settings (`None`: it already is), or
    /// the reasons it cannot be.
    /// `part` converted as [`Document::merge`] converts it, carrying this document's
    /// `<compiler>` settings instead of its own, so that merging it here later converts
    /// nothing more (the batch tier prepares each object once and merges it into every
    /// variant). `None` when it needs no conversion.
    pub(crate) fn prepared_part(
        &self,
        part: &Document,
        errors: &mut Vec<Error>,
    ) -> Option<Document> {
        let mut conv = self.converted_part(part, errors)?;
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

    fn converted_part(&self, part: &Document, errors: &mut Vec<Error>) -> Option<Document> {
        let ours = compiler_settings(self);
        let theirs = compiler_settings(part);
        let same = |k: &str| ours.get(k).map(|v| v.0) == theirs.get(k).map(|v| v.0);
        let relevant = ["angle", "eulerseq", "autolimits", "inertiafromgeom"];
        let agree = MUST_AGREE.iter().all(|(k, _)| same(k)) && relevant.iter().all(|k| same(k));
        if agree {
            return None;
        }
        let mut part = part.clone();
        self.convert_compiler(&mut part, errors);
        Some(part)
    }

    /// Brings `part` to this document's compiler settings, or reports why it cannot be.
    fn convert_compiler(&self, part: &mut Document, errors: &mut Vec<Error>) {
        // A part's inertiafromgeom="true" alone becomes "auto" below, in every build, by
        // dropping the <inertial>s that "true" overrides. With mass settings, another
        // inertiagrouprange or a base with "false" as well, builds with MuJoCo first make it
        // "auto" with every body's compiled inertia written out
        // (`mujoco::write_all_inertials_from_geoms`), after which those settings have nothing
        // left to change: a locomotion model with `inertiafromgeom="true"
        // settotalmass="14"` (Gymnasium's half_cheetah) merges exactly into a base with
        // MuJoCo's defaults.
        #[cfg(mjcf_mujoco)]
        {
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
                if let Err(e) = crate::mujoco::write_all_inertials_from_geoms(part) {
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
        // Builds with MuJoCo convert mass settings: each body's inertia is written out as
        // MuJoCo compiles the part alone, after which the setting changes nothing. That is
        // exact when the merged model reads <inertial> (inertiafromgeom not "true") and the
        // base leaves the setting at MuJoCo's default (no bound, no rescaling of its own).
        #[cfg(mjcf_mujoco)]
        let converted: Vec<&str> = {
            let mut all = Vec::new();
            let mut converted = Vec::new();
            if bi != "true" && pi != "true" {
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
                    let written = if all.is_empty() {
                        crate::mujoco::write_inertials(part)
                    } else {
                        crate::mujoco::write_all_inertials(part)
                    };
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
        #[cfg(not(mjcf_mujoco))]
        let mut converted: Vec<&str> = Vec::new();
        #[cfg(mjcf_mujoco)]
        let mut converted = converted;
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
                    _ => no_conversion_reason(attr, &b, default).to_string(),
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

    /// Every `euler` becomes the `quat` it means under `angles` (for a base with another
    /// Euler sequence).
    fn rewrite_euler_as_quat(&mut self, angles: &Angles) {
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
    fn convert_angles(&mut self, from_degrees: bool, to_degrees: bool) {
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

    /// Whether two elements (here and in `other`) have the same tag, attributes (in any
    /// order) and children.
    fn same_subtree(&self, a: Node, other: &Document, b: Node) -> bool {
        // Pairs still to compare, from a stack (no recursion on input depth).
        let mut pairs = vec![(a, b)];
        while let Some((a, b)) = pairs.pop() {
            if self.tag(a) != other.tag(b) || self.text(a) != other.text(b) {
                return false;
            }
            let mut x: Vec<(&str, &str)> = self.attrs(a).collect();
            let mut y: Vec<(&str, &str)> = other.attrs(b).collect();
            x.sort_unstable();
            y.sort_unstable();
            if x != y {
                return false;
            }
            let at = pairs.len();
            pairs.extend(self.children(a).zip(other.children(b)));
            if pairs.len() - at != self.children(a).count()
                || pairs.len() - at != other.children(b).count()
            {
                return false;
            }
        }
        true
    }
}
