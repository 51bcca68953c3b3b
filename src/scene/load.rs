//! From a scene description to a [`Scene`]: models loaded once, the template assembled,
//! every name, body, attribute and distribution checked, with the scene file's positions.

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use toml::Spanned;

use crate::document::Document;
use crate::document::tree::{Node, Tree};
use crate::document::vocab::{self, AttrKind};
use crate::error::{Error, ErrorKind, Errors, Location};
use crate::model::geometry::{self, Angles, Pose};
use crate::model::merge::MergeOptions;
use crate::model::{XmlModel, XmlModelOptions};

use super::place::{self, Placement, Rotation};
use super::randomize::{self, Dist, Randomizer};
use super::spec::{self, SceneSpec};
use super::{Group, Instance, PoolModel, Scene, splice};

/// The largest count a group, and all groups together, may ask for per variant (each slot
/// keeps its prefixed instances; placement compares every object with the ones before).
const MAX_COUNT: u32 = 10_000;

/// Where model files come from: the disk, or the demo's built-in texts.
pub(crate) trait ModelSource: Sync {
    /// Loads `file` (as the scene names it) relative to `dir`; also returns its absolute
    /// path when it is a file on disk.
    fn load(&self, dir: &Path, file: &str) -> Result<(Document, Option<PathBuf>), Errors>;
}

/// Model files on disk.
pub(crate) struct Files;

impl ModelSource for Files {
    fn load(&self, dir: &Path, file: &str) -> Result<(Document, Option<PathBuf>), Errors> {
        let path = dir.join(file);
        let doc = Document::load(&path)?;
        let abs = std::path::absolute(&path).unwrap_or(path);
        Ok((doc, Some(abs)))
    }
}

/// The scene file's text, to turn byte spans into positions.
struct Source<'a> {
    text: &'a str,
    file: Arc<Path>,
}

impl Source<'_> {
    fn location(&self, span: std::ops::Range<usize>) -> Location {
        let upto = &self.text[..span.start.min(self.text.len())];
        let line = upto.matches('\n').count() as u32 + 1;
        let col = (upto.len() - upto.rfind('\n').map_or(0, |i| i + 1)) as u32 + 1;
        Location::new(self.file.clone(), line, col)
    }

    fn error<T>(&self, at: &Spanned<T>, msg: impl Into<String>) -> Error {
        Error::at(self.location(at.span()), ErrorKind::Invalid(msg.into()))
    }

    /// A model's own errors pass through (they point into the model); a model file that
    /// cannot be read at all is reported where the scene names it.
    fn model_errors(&self, at: &Spanned<String>, errors: Errors) -> Errors {
        Errors(
            errors
                .0
                .into_iter()
                .map(|e| match e.location {
                    None => Error::at(self.location(at.span()), e.kind),
                    Some(_) => e,
                })
                .collect(),
        )
    }
}

/// Builds a scene from TOML text named `file` (its folder holds the models). Problems in
/// the scene file come in the order of their positions.
pub(crate) fn from_toml(
    text: &str,
    file: Arc<Path>,
    models: &dyn ModelSource,
) -> Result<Scene, Errors> {
    build(text, file.clone(), models).map_err(|mut e| {
        e.0.sort_by_key(|e| match &e.location {
            Some(l) if l.file == file => (0, l.line, l.col),
            _ => (1, 0, 0),
        });
        e
    })
}

fn build(text: &str, file: Arc<Path>, models: &dyn ModelSource) -> Result<Scene, Errors> {
    let src = Source {
        text,
        file: file.clone(),
    };
    let spec: SceneSpec = toml::from_str(text).map_err(|e| {
        let location = src.location(e.span().unwrap_or(0..0));
        Error::at(location, ErrorKind::Invalid(e.message().trim().to_string()))
    })?;
    let dir = file.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mut files = Vec::new();
    let mut errors = Vec::new();

    // The template: the base, then each fixture where it goes.
    let (mut template, base_file) = models
        .load(&dir, spec.base.as_ref())
        .map_err(|e| src.model_errors(&spec.base, e))?;
    files.extend(base_file);
    // Parts of the template by arena slot: [start, end) of each, with label and prefix.
    let mut parts: Vec<(usize, usize, Arc<str>, Arc<str>)> = Vec::new();
    let base_end = slot_end(&template);
    parts.push((0, base_end, Arc::from("base"), Arc::from("")));
    let mut prefixes: Vec<&str> = Vec::new();
    for f in &spec.fixture {
        let (doc, path) = match models.load(&dir, f.model.as_ref()) {
            Ok(x) => x,
            Err(e) => {
                errors.extend(src.model_errors(&f.model, e).0);
                continue;
            }
        };
        files.extend(path);
        if prefixes.contains(&f.prefix.as_ref().as_str()) {
            errors.push(src.error(
                &f.prefix,
                format!(
                    "prefix '{}' is already used by another fixture",
                    f.prefix.as_ref()
                ),
            ));
            continue;
        }
        prefixes.push(f.prefix.as_ref());
        let options = model_options(f.collision_rgba, f.name_unnamed_geoms);
        let mut model = match XmlModel::with_prefix(doc, f.prefix.as_ref(), options) {
            Ok(m) => m,
            Err(e) => {
                errors.extend(e.0);
                continue;
            }
        };
        if f.pos.is_some() || f.quat.is_some() {
            let doc = model.document_mut();
            let root = root_body(doc).expect("an XmlModel has one root body");
            if let Some(pos) = f.pos {
                doc.set_attr(root, "pos", &place::join(&pos));
            }
            if let Some(q) = &f.quat {
                let n = q.as_ref().iter().map(|x| x * x).sum::<f64>().sqrt();
                if !(n > 0.0 && n.is_finite()) {
                    errors.push(src.error(q, "quat must be a non-zero quaternion (w x y z)"));
                    continue;
                }
                let quat = q.as_ref().map(|x| x / n);
                place::write_pose(
                    doc,
                    root,
                    &Pose {
                        pos: f.pos.unwrap_or_else(|| {
                            doc.attr(root, "pos")
                                .and_then(randomize::parse_numbers)
                                .and_then(|v| v.try_into().ok())
                                .unwrap_or([0.0; 3])
                        }),
                        quat,
                    },
                );
            }
        }
        let into = f.into.as_ref().map(|s| s.as_ref().as_str());
        if let Some(name) = &f.into
            && template.find_body(name.as_ref()).is_none()
        {
            errors.push(src.error(
                name,
                format!(
                    "no body '{}' in the scene so far (the base and the fixtures above)",
                    name.as_ref()
                ),
            ));
            continue;
        }
        let start = slot_end(&template);
        let options = MergeOptions {
            fuse_keys: false,
            part_prefix: f.prefix.as_ref().clone(),
        };
        if let Err(e) = template.merge(model.document(), into, &options) {
            errors.extend(e.0);
            continue;
        }
        let label: Arc<str> = Arc::from(f.prefix.as_ref().as_str());
        parts.push((start, slot_end(&template), label.clone(), label));
    }
    if !errors.is_empty() {
        return Err(Errors(errors));
    }

    // Randomizers (checked before the groups, which select their elements).
    let group_names: Vec<&str> = spec
        .objects
        .iter()
        .map(|g| g.name.as_ref().as_str())
        .collect();
    let mut randomizers = Vec::new();
    for (k, r) in spec.randomize.iter().enumerate() {
        match randomizer(&src, &dir, k, r, &prefixes, &group_names) {
            Ok(x) => randomizers.push(x),
            Err(e) => errors.push(e),
        }
    }

    // Groups.
    let angles = Angles::of(&template)
        .map_err(|e| Error::at(src.location(spec.base.span()), ErrorKind::Invalid(e)))?;
    let mut groups: Vec<Group> = Vec::new();
    for g in &spec.objects {
        match group(
            &src, &dir, g, &groups, &template, &angles, models, &mut files,
        ) {
            Ok(x) => groups.push(x),
            Err(e) => errors.extend(e.0),
        }
    }
    if !errors.is_empty() {
        return Err(Errors(errors));
    }

    // What each randomizer selects in the template.
    let mut selected = vec![0usize; randomizers.len()];
    let mut template_targets = Vec::with_capacity(randomizers.len());
    for (k, r) in randomizers.iter().enumerate() {
        let mut targets = Vec::new();
        for (start, end, label, prefix) in &parts {
            if !r.applies_to_part(label) {
                continue;
            }
            let nodes = template
                .descendants(template.root())
                .filter(|&n| (*start..*end).contains(&Tree::index(n)));
            match r.select(&template, nodes, prefix, label) {
                Ok(t) => targets.extend(t),
                Err(e) => errors.extend(e.0),
            }
        }
        selected[k] += targets.len();
        template_targets.push(targets);
    }
    let prefixes_apart = prefixes_apart(&groups);
    // The template as variants are written: with `discardvisual` when the scene asks
    // (set on the written text only: merging compares parts' settings with the template's).
    let splice = if spec.discard_visual {
        let mut written = template.clone();
        super::set_discard_visual(&mut written);
        splice::Template::build(&written, &template_targets, &randomizers)
    } else {
        splice::Template::build(&template, &template_targets, &randomizers)
    };
    let mut scene = Scene {
        splice,
        structure: OnceLock::new(),
        discard_visual: spec.discard_visual,
        prefixes_apart,
        seed: spec.seed,
        file,
        template,
        template_targets,
        groups,
        randomizers,
        model_files: files,
    };
    // Every pool model made once for slot 0: checks that it makes an instance and what
    // each randomizer selects in it.
    for group in &scene.groups {
        for m in 0..group.pool.len() {
            match make_instance(&scene, group, 0, m) {
                Ok(inst) => {
                    for (k, t) in &inst.targets {
                        selected[*k] += t.len();
                    }
                    let _ = group.instances[m].set(Ok(inst));
                }
                Err(e) => errors.extend(e.0),
            }
        }
    }
    for (r, spec) in scene.randomizers.iter().zip(&spec.randomize) {
        if selected[r.index] == 0 && errors.is_empty() {
            errors.push(src.error(
                &spec.kind,
                format!(
                    "this randomizer selects no element (kind '{}'{}{})",
                    r.kind,
                    r.name.as_ref().map_or(String::new(), |n| format!(", name '{n}'")),
                    r.part.as_ref().map_or(String::new(), |p| format!(", part '{p}'"))
                ),
            ));
        }
    }
    if !errors.is_empty() {
        return Err(Errors(errors));
    }
    scene.model_files.sort();
    scene.model_files.dedup();
    Ok(scene)
}

/// Whether no prefix that an instance of any group can get begins another one (then two
/// names with different prefixes always differ).
fn prefixes_apart(groups: &[Group]) -> bool {
    let mut all: Vec<String> = groups
        .iter()
        .flat_map(|g| (0..g.count.1).map(move |i| g.prefix_pattern.replace("{i}", &i.to_string())))
        .collect();
    all.sort();
    // Sorted, a prefix of another string comes right before some string it begins.
    all.windows(2).all(|w| !w[1].starts_with(w[0].as_str()))
}

/// One past the largest arena slot in use.
fn slot_end(doc: &Document) -> usize {
    doc.descendants(doc.root())
        .map(Tree::index)
        .max()
        .unwrap_or(0)
        + 1
}

fn model_options(collision_rgba: Option<[f64; 4]>, name_unnamed_geoms: bool) -> XmlModelOptions {
    XmlModelOptions {
        name: None,
        contact_geom_rgba: collision_rgba,
        name_unnamed_geoms,
        exclude_from_prefixing: Vec::new(),
    }
}

fn root_body(doc: &Document) -> Option<Node> {
    let world = doc.worldbody()?;
    let roots = doc.top_level_bodies(world);
    (roots.len() == 1).then(|| roots[0])
}

#[allow(clippy::too_many_arguments)]
fn group(
    src: &Source<'_>,
    dir: &Path,
    g: &spec::GroupSpec,
    earlier: &[Group],
    template: &Document,
    angles: &Angles,
    models: &dyn ModelSource,
    files: &mut Vec<PathBuf>,
) -> Result<Group, Errors> {
    let mut errors = Vec::new();
    let name = g.name.as_ref().clone();
    if earlier.iter().any(|e| e.name == name) {
        errors.push(src.error(&g.name, format!("group '{name}' is defined twice")));
    }
    let count = match *g.count.as_ref() {
        spec::Count::Fixed(n) => (n, n),
        spec::Count::Range([a, b]) => (a, b),
    };
    if count.0 > count.1 || count.1 > MAX_COUNT {
        errors.push(src.error(
            &g.count,
            format!("count must be n or [min, max] with min <= max <= {MAX_COUNT}"),
        ));
    } else {
        // All groups together: placement compares every object with the ones before it.
        let before: u64 = earlier.iter().map(|e| u64::from(e.count.1)).sum();
        if before + u64::from(count.1) > u64::from(MAX_COUNT) {
            errors.push(src.error(
                &g.count,
                format!(
                    "the groups would place up to {} objects per variant; at most {MAX_COUNT} \
                     in all",
                    before + u64::from(count.1)
                ),
            ));
        }
    }
    let prefix_pattern = match &g.prefix {
        Some(p) if !p.as_ref().contains("{i}") => {
            errors.push(src.error(
                p,
                "the prefix must contain {i} (the slot index), so that instances differ",
            ));
            String::new()
        }
        Some(p) => p.as_ref().clone(),
        None => format!("{name}{{i}}_"),
    };
    if let Some(e) = earlier.iter().find(|e| e.prefix_pattern == prefix_pattern) {
        let at = g.prefix.as_ref().map_or(g.name.span(), |p| p.span());
        errors.push(Error::at(
            src.location(at),
            ErrorKind::Invalid(format!(
                "group '{}' already uses the prefix '{prefix_pattern}'",
                e.name
            )),
        ));
    }
    if g.pool.as_ref().is_empty() {
        errors.push(src.error(&g.pool, "the pool is empty"));
    }
    let mut pool = Vec::new();
    let mut weights = Vec::new();
    for entry in g.pool.as_ref() {
        let w = entry.as_ref().weight();
        if !(w.is_finite() && w >= 0.0) {
            errors.push(src.error(entry, "a weight must be a finite number >= 0"));
        }
        weights.push(w);
        let file = entry.as_ref().model().to_string();
        let at = Spanned::new(entry.span(), file.clone());
        let (mut doc, path) = match models.load(dir, &file) {
            Ok(x) => x,
            Err(e) => {
                errors.extend(src.model_errors(&at, e).0);
                continue;
            }
        };
        files.extend(path);
        let Some(root) = root_body(&doc) else {
            errors.push(src.error(
                &at,
                format!("'{file}' must have exactly one top-level body to be placed"),
            ));
            continue;
        };
        if doc.attr(root, "name").is_none() {
            // The manifest names each object by its root body; an unnamed one gets the
            // first of root, root1, root2... that no body uses (robosuite's objects
            // wrap a body named "object" in an unnamed one).
            let taken: Vec<&str> = doc
                .descendants(root)
                .filter(|&n| doc.tag(n) == "body")
                .filter_map(|n| doc.attr(n, "name"))
                .collect();
            let name = (0..)
                .map(|k| {
                    if k == 0 {
                        "root".to_string()
                    } else {
                        format!("root{k}")
                    }
                })
                .find(|n| !taken.contains(&n.as_str()))
                .expect("a free name exists");
            doc.set_attr(root, "name", &name);
        }
        let has_joint = doc
            .elements(root)
            .any(|k| matches!(doc.tag(k), "joint" | "freejoint"));
        if g.free_joint && !has_joint {
            // Named joint0 as robosuite names an object's first joint, or the first free
            // jointN when the model already uses that name.
            let taken: Vec<&str> = doc
                .descendants(doc.root())
                .filter(|&n| matches!(doc.tag(n), "joint" | "freejoint"))
                .filter_map(|n| doc.attr(n, "name"))
                .collect();
            let name = (0..)
                .map(|k| format!("joint{k}"))
                .find(|n| !taken.contains(&n.as_str()))
                .expect("a free name exists");
            doc.append_element(root, "freejoint", &[("name", &name)]);
        }
        let bounds = match geometry::subtree_bounds(&doc, root, |_, _| true) {
            Ok(b) if b.min.iter().chain(&b.max).all(|x| x.is_finite()) => b,
            Ok(_) => {
                errors.push(src.error(
                    &at,
                    format!("'{file}' has no geometry with a finite extent to place"),
                ));
                continue;
            }
            Err(e) => {
                errors.push(src.error(&at, format!("cannot measure '{file}': {e}")));
                continue;
            }
        };
        pool.push(PoolModel { file, doc, bounds });
    }
    if !weights.is_empty() && weights.iter().all(|&w| w == 0.0) {
        errors.push(src.error(&g.pool, "at least one weight must be positive"));
    }
    let p = &g.placement;
    let mut frame = Pose::IDENTITY;
    let mut frame_label = String::new();
    if let Some(on) = &p.on {
        let found = template.descendants(template.root()).find(|&n| {
            matches!(template.tag(n), "body" | "site")
                && template.attr(n, "name") == Some(on.as_ref())
        });
        match found {
            Some(n) => match world_pose(template, n, angles) {
                Ok(f) => {
                    frame = f;
                    frame_label = format!(" on '{}'", on.as_ref());
                }
                Err(e) => errors.push(src.error(on, e)),
            },
            None => errors.push(src.error(
                on,
                format!(
                    "no body or site '{}' in the base or the fixtures",
                    on.as_ref()
                ),
            )),
        }
    }
    let on_top_of = match &p.on_top_of {
        None => None,
        Some(t) => match earlier.iter().position(|e| e.name == *t.as_ref()) {
            Some(i) => Some(i),
            None => {
                errors.push(src.error(
                    t,
                    format!("no group '{}' above this one to stack on", t.as_ref()),
                ));
                None
            }
        },
    };
    for (axis, range) in [("x", &p.x), ("y", &p.y)] {
        let [lo, hi] = *range.as_ref();
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            errors.push(src.error(range, format!("{axis} must be [min, max] with min <= max")));
        }
    }
    let rotation = match &p.rotation {
        None => Rotation {
            axis: [0.0, 0.0, 1.0],
            angles: place::Angles::None,
        },
        Some(r) => match rotation(src, &g.name, r) {
            Ok(r) => r,
            Err(e) => {
                errors.push(e);
                Rotation {
                    axis: [0.0, 0.0, 1.0],
                    angles: place::Angles::None,
                }
            }
        },
    };
    if p.max_tries == 0 {
        errors.push(src.error(&g.name, "max_tries must be at least 1"));
    }
    if !errors.is_empty() {
        return Err(Errors(errors));
    }
    // Slot 0 exists even for a group that may place nothing: it is made once at load to
    // check the pool models.
    let slots = count.1.max(1) as usize;
    let instances = (0..slots * pool.len()).map(|_| OnceLock::new()).collect();
    Ok(Group {
        name,
        location: src.location(g.name.span()),
        count,
        prefix_pattern,
        pool,
        weights,
        placement: Placement {
            frame,
            frame_label,
            x: *p.x.as_ref(),
            y: *p.y.as_ref(),
            z: p.z,
            gap: p.gap,
            rotation,
            check_overlap: p.overlap == spec::Overlap::Radius,
            max_tries: p.max_tries,
        },
        on_top_of,
        instances,
        options: model_options(g.collision_rgba, g.name_unnamed_geoms),
    })
}

fn rotation(
    src: &Source<'_>,
    group: &Spanned<String>,
    r: &spec::RotationSpec,
) -> Result<Rotation, Error> {
    let axis = match r.axis.as_ref().map(|a| (a, a.as_ref())) {
        None => [0.0, 0.0, 1.0],
        Some((_, spec::Axis::Named(n))) if n == "x" => [1.0, 0.0, 0.0],
        Some((_, spec::Axis::Named(n))) if n == "y" => [0.0, 1.0, 0.0],
        Some((_, spec::Axis::Named(n))) if n == "z" => [0.0, 0.0, 1.0],
        Some((at, spec::Axis::Vector(v))) => {
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !(n > 0.0 && n.is_finite()) {
                return Err(src.error(at, "the axis must be a non-zero vector"));
            }
            v.map(|x| x / n)
        }
        Some((at, _)) => return Err(src.error(at, "axis must be \"x\", \"y\", \"z\" or [x, y, z]")),
    };
    let given = [
        r.range_deg.is_some(),
        r.range_rad.is_some(),
        r.values_deg.is_some(),
        r.values_rad.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(src.error(
            group,
            "rotation needs exactly one of range_deg, range_rad, values_deg, values_rad",
        ));
    }
    let angles = if let Some([a, b]) = r.range_deg {
        place::Angles::Range(a.to_radians(), b.to_radians())
    } else if let Some([a, b]) = r.range_rad {
        place::Angles::Range(a, b)
    } else if let Some(v) = &r.values_deg {
        place::Angles::Values(v.iter().map(|x| x.to_radians()).collect())
    } else {
        place::Angles::Values(r.values_rad.clone().unwrap_or_default())
    };
    let ok = match &angles {
        place::Angles::Range(a, b) => a.is_finite() && b.is_finite() && a <= b,
        place::Angles::Values(v) => !v.is_empty() && v.iter().all(|x| x.is_finite()),
        place::Angles::None => true,
    };
    if !ok {
        return Err(src.error(group, "rotation angles must be finite, a range [min, max] with min <= max or a non-empty list"));
    }
    Ok(Rotation { axis, angles })
}

/// The pose of a body or site in the world: its pose in its body, composed up the tree.
fn world_pose(doc: &Document, node: Node, angles: &Angles) -> Result<Pose, String> {
    let mut pose = geometry::body_relative_pose(doc, node, angles)?;
    let mut up = enclosing_body(doc, node);
    while let Some(body) = up {
        pose = geometry::body_relative_pose(doc, body, angles)?.compose(&pose);
        up = enclosing_body(doc, body);
    }
    Ok(pose)
}

/// The body holding `node` (through frames); `None` at the world body.
fn enclosing_body(doc: &Document, node: Node) -> Option<Node> {
    let mut up = doc.parent(node);
    while let Some(p) = up {
        match doc.tag(p) {
            "body" => return Some(p),
            "worldbody" => return None,
            _ => up = doc.parent(p),
        }
    }
    None
}

fn randomizer(
    src: &Source<'_>,
    dir: &Path,
    index: usize,
    r: &spec::RandomizerSpec,
    fixtures: &[&str],
    groups: &[&str],
) -> Result<Randomizer, Error> {
    let kind = r.kind.as_ref().as_str();
    let attribute = r.attribute.as_ref().as_str();
    let specs: Vec<&vocab::ElementSpec> = vocab::elements()
        .iter()
        .filter(|e| e.tag == kind && !e.name.starts_with("default"))
        .collect();
    if specs.is_empty() {
        return Err(src.error(&r.kind, format!("MJCF has no element <{kind}>")));
    }
    let attr_on = if kind == "body" && attribute == "mass" {
        "inertial"
    } else {
        kind
    };
    let attr_spec = vocab::elements()
        .iter()
        .filter(|e| e.tag == attr_on && !e.name.starts_with("default"))
        .find_map(|e| e.attrs.iter().find(|a| a.name == attribute));
    let Some(attr_spec) = attr_spec else {
        return Err(src.error(
            &r.attribute,
            format!("<{kind}> has no attribute '{attribute}'"),
        ));
    };
    if matches!(attr_spec.kind, AttrKind::Id(_)) || attribute == "class" {
        return Err(src.error(
            &r.attribute,
            format!("'{attribute}' is a name, which randomizers do not change"),
        ));
    }
    if let Some(p) = &r.part {
        let p = p.as_ref().as_str();
        if p != "base" && !fixtures.contains(&p) && !groups.contains(&p) {
            return Err(src.error(
                r.part.as_ref().expect("checked"),
                format!("no part '{p}': a part is \"base\", a fixture's prefix or an object group's name"),
            ));
        }
    }
    let given = [
        r.uniform.is_some(),
        r.log_uniform.is_some(),
        r.normal.is_some(),
        r.choice.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(src.error(
            &r.attribute,
            "a randomizer needs exactly one of uniform, log_uniform, normal, choice",
        ));
    }
    let numbers = |v: &spec::Values| v.as_slice().to_vec();
    let check = |at: std::ops::Range<usize>, ok: bool, msg: &str| -> Result<(), Error> {
        if ok {
            Ok(())
        } else {
            Err(Error::at(
                src.location(at),
                ErrorKind::Invalid(msg.to_string()),
            ))
        }
    };
    let finite = |v: &[f64]| !v.is_empty() && v.iter().all(|x| x.is_finite());
    let dist = if let Some(u) = &r.uniform {
        let [lo, hi] = u.as_ref();
        let (lo, hi) = (numbers(lo), numbers(hi));
        check(
            u.span(),
            finite(&lo) && finite(&hi) && pairwise(&lo, &hi, |a, b| a <= b),
            "uniform needs [low, high] with low <= high (numbers or lists of one length)",
        )?;
        Dist::Uniform { lo, hi }
    } else if let Some(u) = &r.log_uniform {
        let [lo, hi] = u.as_ref();
        let (lo, hi) = (numbers(lo), numbers(hi));
        check(
            u.span(),
            finite(&lo)
                && finite(&hi)
                && lo.iter().all(|&x| x > 0.0)
                && pairwise(&lo, &hi, |a, b| a <= b),
            "log_uniform needs [low, high] with 0 < low <= high",
        )?;
        Dist::LogUniform { lo, hi }
    } else if let Some(n) = &r.normal {
        let s = n.as_ref();
        let (mean, std, min, max) = (
            numbers(&s.mean),
            numbers(&s.std),
            numbers(&s.min),
            numbers(&s.max),
        );
        check(
            n.span(),
            [&mean, &std, &min, &max].iter().all(|v| finite(v))
                && std.iter().all(|&x| x >= 0.0)
                && pairwise(&min, &max, |a, b| a <= b),
            "normal needs finite mean, std >= 0, and min <= max",
        )?;
        Dist::Normal {
            mean,
            std,
            min,
            max,
        }
    } else {
        let c = r.choice.as_ref().expect("one distribution is given");
        let entries = c.as_ref();
        check(
            c.span(),
            !entries.is_empty()
                && entries
                    .iter()
                    .all(|e| e.weight().is_finite() && e.weight() >= 0.0)
                && entries.iter().any(|e| e.weight() > 0.0),
            "choice needs a non-empty list with weights >= 0, one of them positive",
        )?;
        // Chosen strings are written into the XML as they are: refuse what XML 1.0 cannot
        // carry (a TOML escape such as \e gives one).
        if let Some(bad) = entries
            .iter()
            .find_map(|e| e.value().chars().find(|&ch| !is_xml_char(ch)))
        {
            return Err(Error::at(
                src.location(c.span()),
                ErrorKind::Invalid(format!(
                    "choice holds the character U+{:04X}, which XML cannot carry",
                    bad as u32
                )),
            ));
        }
        let file = matches!(attr_spec.kind, AttrKind::File);
        let values = entries
            .iter()
            .map(|e| {
                if file {
                    dir.join(e.value()).to_string_lossy().into_owned()
                } else {
                    e.value().to_string()
                }
            })
            .collect();
        Dist::Choice {
            values,
            weights: entries.iter().map(|e| e.weight()).collect(),
            prefixed: matches!(attr_spec.kind, AttrKind::Ref(_)),
        }
    };
    let numeric = !matches!(dist, Dist::Choice { .. });
    if r.scale && !numeric {
        return Err(src.error(&r.attribute, "scale needs numbers, not a choice"));
    }
    let unit_to_rad = match &r.unit {
        None => None,
        Some(u) => {
            if randomize::angle_components(kind, attribute).is_none() {
                return Err(src.error(u, format!("'{attribute}' of <{kind}> is not an angle in compiler units (MuJoCo reads it as written); drop the unit")));
            }
            if r.scale {
                return Err(src.error(u, "a scale has no unit"));
            }
            match u.as_ref().as_str() {
                "deg" => Some(std::f64::consts::PI / 180.0),
                "rad" => Some(1.0),
                _ => return Err(src.error(u, "unit must be \"deg\" or \"rad\"")),
            }
        }
    };
    if let Some(c) = &r.components {
        let n = match &dist {
            Dist::Uniform { lo, hi } | Dist::LogUniform { lo, hi } => lo.len().max(hi.len()),
            Dist::Normal {
                mean,
                std,
                min,
                max,
            } => mean.len().max(std.len()).max(min.len()).max(max.len()),
            Dist::Choice { .. } => {
                return Err(src.error(c, "components need numbers, not a choice"));
            }
        };
        if c.as_ref().is_empty() || (n > 1 && n != c.as_ref().len()) {
            return Err(src.error(
                c,
                "give one bound per component listed (or one bound for all)",
            ));
        }
    }
    Ok(Randomizer {
        kind: kind.to_string(),
        attribute: attribute.to_string(),
        name: r.name.as_ref().map(|n| n.as_ref().clone()),
        part: r.part.as_ref().map(|p| p.as_ref().clone()),
        dist,
        scale: r.scale,
        unit_to_rad,
        components: r.components.as_ref().map(|c| c.as_ref().clone()),
        shared: r.shared,
        location: src.location(r.kind.span()),
        index,
        file: matches!(attr_spec.kind, AttrKind::File),
    })
}

/// Whether XML 1.0 allows `c` in text (its `Char` production).
fn is_xml_char(c: char) -> bool {
    matches!(c, '\t' | '\n' | '\r' | '\u{20}'..='\u{D7FF}' | '\u{E000}'..='\u{FFFD}' | '\u{10000}'..)
}

/// Lists of bounds of one length (or a single value), each pair satisfying `ok`.
fn pairwise(a: &[f64], b: &[f64], ok: impl Fn(f64, f64) -> bool) -> bool {
    let n = a.len().max(b.len());
    (a.len() == n || a.len() == 1)
        && (b.len() == n || b.len() == 1)
        && (0..n).all(|i| ok(a[i.min(a.len() - 1)], b[i.min(b.len() - 1)]))
}

/// Pool model `m` of `group` prefixed for `slot`, with what each randomizer selects in it.
pub(crate) fn make_instance(
    scene: &Scene,
    group: &super::Group,
    slot: u32,
    m: usize,
) -> Result<Instance, Errors> {
    let prefix = group.prefix_pattern.replace("{i}", &slot.to_string());
    let model = XmlModel::with_prefix(group.pool[m].doc.clone(), &prefix, group.options.clone())?;
    let mut doc = model.into_document();
    // Brought to the template's compiler settings once, so merging a variant converts
    // nothing; randomized angles are then written in the template's units.
    let mut errors = Vec::new();
    if let Some(converted) = scene.template.prepared_part(&doc, &mut errors) {
        doc = converted;
    }
    if !errors.is_empty() {
        return Err(Errors(errors));
    }
    let root = root_body(&doc).expect("pool models have one root body");
    let root_name = doc.attr(root, "name").unwrap_or_default().to_string();
    let part: Arc<str> = Arc::from(group.name.as_str());
    let mut targets = Vec::new();
    for r in &scene.randomizers {
        if !r.applies_to_part(&group.name) {
            continue;
        }
        match r.select(&doc, doc.descendants(doc.root()), &prefix, &part) {
            Ok(t) if !t.is_empty() => targets.push((r.index, t)),
            Ok(_) => {}
            Err(e) => errors.extend(e.0),
        }
    }
    // Instances are merged into copies of the template without a name check: check once.
    errors.extend(scene.template.name_clashes(&[&doc]));
    if !errors.is_empty() {
        return Err(Errors(errors));
    }
    let fragments = scene.splice.as_ref().and_then(|t| {
        splice::Fragments::build(&doc, root, &targets, &scene.randomizers, &scene.template, t)
    });
    Ok(Instance {
        doc,
        prefix,
        root,
        root_name,
        targets,
        fragments,
    })
}
