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
//!
//! Its files:
//!
//! - [`compiler`]: the part's `compiler` settings against the base's: which must agree, the
//!   rewrites of the part that stand in for the others, and why the rest cannot be converted;
//! - [`angles`]: angle units and Euler sequences (the part converted, or the base when it is
//!   the smaller);
//! - where a body's mass and inertia come from (its `<inertial>` or its geoms) is the
//!   document tier's rule (`document/inertia.rs`), shared with the MuJoCo FFI;
//! - [`free_joints`]: free joints, and which free bodies MuJoCo aligns with their inertial
//!   frames;
//! - [`assets`]: the part's assets the base already has, shared rather than copied;
//! - [`defaults`]: the part's residual default classes;
//! - [`settings`]: `option`, `size`, `visual` and `statistic`, the base's winning;
//! - [`layout`]: what fills the state vectors a keyframe gives, and where;
//! - [`keys`]: keyframes remapped onto the merged model, and fused by name;
//! - copying a part's nodes into the base's arena is the document tier's
//!   (`document/import.rs`), which also records where each node went.
//!
//! Here: the public types, the entry points ([`Document::merge`], [`Document::merge_all`],
//! [`Document::merge_all_mapped`] and `merge_unchecked` for the batch tier) and the few helpers several files share.

mod angles;
mod assets;
mod compiler;
mod defaults;
mod free_joints;
mod keys;
mod layout;
mod settings;

use crate::document::import::{Import, NodeMap};
use crate::document::inertia::InertiaCompiler;
use crate::document::names::Sym;
use crate::document::tree::Node;
use crate::document::{Document, Section};
use crate::error::{Error, ErrorKind, Errors};

pub(crate) use compiler::builtin_compiler;
use keys::{implicit_keys, keys_of};
use layout::Layout;

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
        self.merge_checked(parts, fuse_keys, false, None)
            .map(|(report, _)| report)
    }

    /// [`Document::merge_all`], also telling where each part's nodes went: one [`NodeMap`]
    /// per part, from the part's nodes to this document's copies of them (what a caller
    /// holding handles to a part's elements follows). A part's asset that this document
    /// already had maps to that asset; what a merge folds in rather than copies (a part's
    /// `<compiler>`, `<option>`, keyframes) is not in the map.
    ///
    /// ```
    /// use mjcf_forge::{Document, MergePart};
    /// let mut scene = Document::from_str("<mujoco><worldbody/></mujoco>", ".")?;
    /// let cube = Document::from_str(r#"<mujoco><worldbody><body name="cube"><geom size="1"/></body></worldbody></mujoco>"#, ".")?;
    /// let body = cube.descendants(cube.root()).find(|&n| cube.tag(n) == "body").unwrap();
    /// let part = MergePart { doc: &cube, into: None, prefix: "" };
    /// let (_, maps) = scene.merge_all_mapped(&[part], false)?;
    /// assert_eq!(maps[0].get(body), scene.find_body("cube"));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn merge_all_mapped(
        &mut self,
        parts: &[MergePart<'_>],
        fuse_keys: bool,
    ) -> Result<(MergeReport, Vec<NodeMap>), Errors> {
        self.merge_checked(parts, fuse_keys, true, None)
    }

    /// [`Document::merge_all_mapped`], with the inertias only MuJoCo knows coming from
    /// `compile` rather than from the build's own MuJoCo: a part whose compiler settings for
    /// masses and inertias (`inertiagrouprange`, `settotalmass`, `boundmass`,
    /// `boundinertia`, `balanceinertia`, `inertiafromgeom`) differ from this document's is
    /// converted by writing out, as explicit `<inertial>`s, what `compile` says MuJoCo
    /// compiles it to alone ([`Document::write_compiled_inertials`]). `compile` is called
    /// only for such parts. This is how the Python package merges with the user's own
    /// `mujoco` in builds without the `mujoco` feature.
    ///
    /// ```
    /// use mjcf_forge::{CompiledInertia, Document, MergePart};
    ///
    /// let mut world = Document::from_str(
    ///     r#"<mujoco><compiler inertiagrouprange="0 0"/><worldbody/></mujoco>"#, ".")?;
    /// let table = Document::from_str(
    ///     r#"<mujoco><worldbody><body name="t"><geom size="0.1"/><geom size="0.1" group="1"/></body></worldbody></mujoco>"#,
    ///     ".",
    /// )?;
    /// let mut compile = |_: &Document| -> Result<CompiledInertia, mjcf_forge::Error> {
    ///     // What MuJoCo compiles the table to alone: both spheres count under "0 5".
    ///     Ok(CompiledInertia {
    ///         body_names: vec!["world".into(), "t".into()],
    ///         mass: vec![0.0, 8.377580409572781],
    ///         ipos: vec![0.0; 6],
    ///         iquat: vec![1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
    ///         inertia: vec![0.0, 0.0, 0.0, 0.033510321638291124, 0.033510321638291124, 0.033510321638291124],
    ///     })
    /// };
    /// let part = MergePart { doc: &table, into: None, prefix: "" };
    /// world.merge_all_mapped_with(&[part], false, &mut compile)?;
    /// assert!(world.to_xml_string().contains(r#"mass="8.377580409572781""#));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn merge_all_mapped_with(
        &mut self,
        parts: &[MergePart<'_>],
        fuse_keys: bool,
        compile: &mut InertiaCompiler<'_>,
    ) -> Result<(MergeReport, Vec<NodeMap>), Errors> {
        self.merge_checked(parts, fuse_keys, true, Some(compile))
    }

    /// The merge behind [`Document::merge_all`] and [`Document::merge_all_mapped`]: the
    /// maps are kept when `keep_maps`; inertias come from `compile`, else from the build's
    /// MuJoCo if it has one.
    pub(crate) fn merge_checked(
        &mut self,
        parts: &[MergePart<'_>],
        fuse_keys: bool,
        keep_maps: bool,
        compile: Option<&mut InertiaCompiler<'_>>,
    ) -> Result<(MergeReport, Vec<NodeMap>), Errors> {
        let clashes = self.merge_name_clashes(&parts.iter().map(|p| p.doc).collect::<Vec<_>>());
        if !clashes.is_empty() {
            return Err(Errors(clashes));
        }
        // Every check runs before the document changes, except keyframe remapping: with
        // keys, or with several parts, work on a copy so that a failure changes nothing.
        // (A copy keeps every node's handle: the maps and the caller's handles stay good.)
        let has_keys = |d: &Document| !keys_of(d).is_empty() || implicit_keys(d) > 0;
        let keys = has_keys(self) || parts.iter().any(|p| has_keys(p.doc));
        // A base smaller than its part may adopt the part's angle unit before the checks
        // (`adopt_angle_unit_if_smaller`): then it too works on a copy (a small one).
        if !keys && parts.len() == 1 && self.node_count() >= parts[0].doc.node_count() {
            self.merge_parts(parts, fuse_keys, keep_maps, compile)
        } else {
            let mut merged = self.clone();
            let out = merged.merge_parts(parts, fuse_keys, keep_maps, compile)?;
            *self = merged;
            Ok(out)
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
        self.merge_parts(parts, fuse_keys, false, None)
            .map(|(report, _)| report)
    }

    fn merge_parts(
        &mut self,
        parts: &[MergePart<'_>],
        fuse_keys: bool,
        keep_maps: bool,
        mut compile: Option<&mut InertiaCompiler<'_>>,
    ) -> Result<(MergeReport, Vec<NodeMap>), Errors> {
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
        let mut maps = Vec::new();
        for p in parts {
            let options = MergeOptions {
                fuse_keys,
                part_prefix: p.prefix.to_string(),
            };
            let (r, map) =
                self.merge_in_place(p.doc, p.into, &options, keep_maps, compile.as_deref_mut())?;
            report.warnings.extend(r.warnings);
            report.shared_assets += r.shared_assets;
            if keep_maps {
                maps.push(map);
            }
        }
        Ok((report, maps))
    }

    fn merge_in_place(
        &mut self,
        part: &Document,
        into: Option<&str>,
        options: &MergeOptions,
        keep_map: bool,
        compile: Option<&mut InertiaCompiler<'_>>,
    ) -> Result<(MergeReport, NodeMap), Errors> {
        let mut report = MergeReport::default();
        let mut errors: Vec<Error> = Vec::new();
        self.adopt_static_fusion(part);
        self.adopt_angle_unit_if_smaller(part);
        let converted = self.converted_part(part, &mut errors, compile);
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
                            "merge target body '{name}' is not in the base model{}",
                            did_you_mean(name, &self.body_names())
                        )),
                    )
                    .into());
                }
            },
        };

        // Checks before changes: free bodies, assets, residual classes.
        let assets = self.asset_matches(part, &mut errors);
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
        let mut imp = Import::new(file_offset, has_keys || keep_map);
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
                        if let Some(same) = *shared {
                            report.shared_assets += 1;
                            if let Some(map) = imp.map.as_mut() {
                                map.insert(a, same);
                            }
                        } else {
                            self.import(part, a, Some(dest), imp);
                        }
                    }
                }
                "worldbody" => {
                    for child in part.elements(section).collect::<Vec<_>>() {
                        self.import(part, child, Some(target), imp);
                    }
                }
                "keyframe" => {}
                other => {
                    let dest = match Section::from_tag(other) {
                        Some(s) => self.section(s),
                        None => {
                            let root = self.root;
                            self.import(part, section, Some(root), imp);
                            continue;
                        }
                    };
                    for child in part.elements(section).collect::<Vec<_>>() {
                        self.import(part, child, Some(dest), imp);
                    }
                }
            }
        }
        let map = imp.map.take().unwrap_or_default();
        if has_keys {
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
        Ok((report, map))
    }

    /// The names of the model's named bodies, in document order.
    fn body_names(&self) -> Vec<&str> {
        self.declared_names()
            .into_iter()
            .filter(|(ns, _, _)| *ns == crate::document::vocab::Ns::Body)
            .map(|(_, name, _)| name)
            .collect()
    }

    /// The names the parts would bring in twice, one error per part: a part with one
    /// clash gets the usual `duplicate ... name` line; a part with several (most often the
    /// same model merged twice, or an instance without a prefix of its own, where every
    /// name clashes) gets one line that says so, with the fix, rather than a line per name.
    fn merge_name_clashes(&self, parts: &[&Document]) -> Vec<Error> {
        /// Names listed in a summary before "and N more".
        const LISTED: usize = 5;
        let clashes = self.name_clash_list(parts);
        let mut errors = Vec::new();
        let mut rest = clashes.as_slice();
        while let Some(first) = rest.first() {
            let n = rest.iter().take_while(|c| c.part == first.part).count();
            let (mine, after) = rest.split_at(n);
            rest = after;
            let part = parts[first.part];
            let msg = if let [one] = mine {
                format!(
                    "duplicate {} name '{}' (first at {})",
                    one.ns.as_str(),
                    one.name,
                    one.first
                )
            } else {
                let mut listed: Vec<String> = mine
                    .iter()
                    .take(LISTED)
                    .enumerate()
                    .map(|(k, c)| {
                        if k == 0 {
                            format!("{} '{}' first at {}", c.ns.as_str(), c.name, c.first)
                        } else {
                            format!("{} '{}'", c.ns.as_str(), c.name)
                        }
                    })
                    .collect();
                if n > LISTED {
                    listed.push(format!("and {} more", n - LISTED));
                }
                let (how_many, fix) = if n == first.declared {
                    (
                        format!("all {n} names this part declares are"),
                        "is it merged twice, or without a prefix of its own? give each \
                         instance its own name prefix",
                    )
                } else {
                    (
                        format!("{n} of the {} names this part declares are", first.declared),
                        "rename them, or give the part a name prefix of its own",
                    )
                };
                format!(
                    "duplicate names: {how_many} already in the model ({}); {fix}",
                    listed.join(", ")
                )
            };
            errors.push(part.error_at(first.node, ErrorKind::Invalid(msg)));
        }
        errors
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

/// Whether two attribute values are the same, number tokens compared as numbers ("0" and
/// "0.0" are the same value to MuJoCo).
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

/// ` (did you mean 'x'?)` for a name that is not among `names` but close to one: one that
/// ends with it (the name given without its instance's prefix: `hand` for `robot0_hand`),
/// else the nearest by edit distance, within a third of the name's length (at least 2: a
/// swap of two letters); empty when none is close.
fn did_you_mean(name: &str, names: &[&str]) -> String {
    let suffixed: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| n.len() > name.len() && n.ends_with(name))
        .collect();
    let close: Vec<&str> = if suffixed.is_empty() {
        let bound = (name.chars().count() / 3).max(2);
        let scored: Vec<(usize, &str)> = names
            .iter()
            .map(|n| (edit_distance(name, n), *n))
            .filter(|(d, _)| *d <= bound)
            .collect();
        let best = scored.iter().map(|(d, _)| *d).min();
        scored
            .into_iter()
            .filter(|(d, _)| Some(*d) == best)
            .map(|(_, n)| n)
            .collect()
    } else {
        suffixed
    };
    match close.as_slice() {
        [] => String::new(),
        names => {
            let quoted: Vec<String> = names.iter().take(3).map(|n| format!("'{n}'")).collect();
            format!(" (did you mean {}?)", quoted.join(" or "))
        }
    }
}

/// Levenshtein distance in characters (names are short: one row of memory).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != *cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod did_you_mean_tests {
    use super::*;

    #[test]
    fn close_names_and_missing_prefixes_are_suggested() {
        let names = ["robot0_base", "robot0_right_hand", "table"];
        assert_eq!(did_you_mean("tabel", &names), " (did you mean 'table'?)");
        assert_eq!(
            did_you_mean("right_hand", &names),
            " (did you mean 'robot0_right_hand'?)"
        );
        assert_eq!(did_you_mean("zzz", &names), "");
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }
}
