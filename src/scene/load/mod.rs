//! From a scene description to a [`Scene`]: models loaded once, the template assembled,
//! every name, body, attribute and distribution checked, with the scene file's positions.
//! An object group is checked in `group.rs`, a randomizer in `randomizer.rs`; `open.rs`
//! holds [`Scene`]'s constructors (a file, TOML or JSON text, the demo).

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use toml::Spanned;

use crate::document::Document;
use crate::document::inertia::InertiaCompiler;
use crate::document::limits::Limits;
use crate::document::tree::{Node, Tree};
use crate::document::urdf::{UrdfActuators, UrdfOptions};
use crate::error::{Error, ErrorKind, Errors, Location, Warning};
use crate::model::geometry::{Angles, Pose};
use crate::model::merge::MergeOptions;
use crate::model::{XmlModel, XmlModelOptions};

use super::place::{self};
use super::randomize::{self};
use super::spec::{self, SceneSpec};
use super::{Group, Instance, Scene, splice};

mod group;
mod keys;
mod open;
mod randomizer;

/// The largest count a group, and all groups together, may ask for per variant (each slot
/// keeps its prefixed instances; placement compares every object with the ones before).
pub(super) const MAX_COUNT: u32 = 10_000;

/// Where model files come from: the disk, or the demo's built-in texts.
pub(crate) trait ModelSource: Sync {
    /// Loads `file` (as the scene names it) relative to `dir`; also returns its absolute
    /// path when it is a file on disk.
    fn load(&self, dir: &Path, file: &str) -> Result<(Document, Option<PathBuf>), Errors>;

    /// Loads `file` as [`ModelSource::load`] does, a URDF model with `options`; `None`
    /// when the model is not URDF.
    fn load_urdf(
        &self,
        _dir: &Path,
        _file: &str,
        _options: &UrdfOptions,
    ) -> Result<Option<(Document, Option<PathBuf>)>, Errors> {
        Ok(None)
    }
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

    fn load_urdf(
        &self,
        dir: &Path,
        file: &str,
        options: &UrdfOptions,
    ) -> Result<Option<(Document, Option<PathBuf>)>, Errors> {
        let path = dir.join(file);
        let Some(doc) = Document::load_urdf_only(&path, &Limits::default(), options)? else {
            return Ok(None);
        };
        let abs = std::path::absolute(&path).unwrap_or(path);
        Ok(Some((doc, Some(abs))))
    }
}

/// The options a scene's `urdf` table asks for (its package folders relative to `dir`).
pub(super) fn urdf_options(spec: &spec::UrdfSpec, dir: &Path) -> UrdfOptions {
    UrdfOptions {
        visuals: spec.visuals,
        fuse_static: spec.fuse_static,
        keep_links: spec.keep_links.clone(),
        packages: spec
            .packages
            .iter()
            .map(|(name, folder)| (name.clone(), dir.join(folder)))
            .collect(),
        actuators: spec.actuators.as_ref().map(|a| match *a {
            spec::ActuatorSpec::Position { kp, kv } => UrdfActuators::Position { kp, kv },
            spec::ActuatorSpec::Velocity { kv } => UrdfActuators::Velocity { kv },
            spec::ActuatorSpec::Motor => UrdfActuators::Motor,
        }),
        ..UrdfOptions::default()
    }
}

/// A model of the scene, read with its `urdf` table's options where it has one: an
/// error at that table when the model is not URDF (`what` names it).
pub(super) fn load_model(
    models: &dyn ModelSource,
    src: &Source<'_>,
    dir: &Path,
    file: &Spanned<String>,
    urdf: Option<&Spanned<spec::UrdfSpec>>,
) -> Result<(Document, Option<PathBuf>), Errors> {
    let Some(table) = urdf else {
        return models
            .load(dir, file.as_ref())
            .map_err(|e| src.model_errors(file, e));
    };
    let options = urdf_options(table.as_ref(), dir);
    match models.load_urdf(dir, file.as_ref(), &options) {
        Ok(Some(x)) => Ok(x),
        Ok(None) => Err(src
            .error(
                table,
                format!(
                    "urdf options are given for '{}', which is not a URDF file",
                    file.as_ref()
                ),
            )
            .into()),
        Err(e) => Err(src.model_errors(file, e)),
    }
}

/// The scene file's text, to turn byte spans into positions.
pub(super) struct Source<'a> {
    text: &'a str,
    file: Arc<Path>,
    /// For a description without text of its own (JSON, a Python `dict`): the key path of
    /// each span of the TOML text it was read as, which every location then names.
    keys: Option<keys::KeyPaths>,
}

impl Source<'_> {
    /// Where `span` is: its line and column, and its key path when the text is not the
    /// user's own. Every problem of a scene description is positioned here.
    pub(super) fn location(&self, span: std::ops::Range<usize>) -> Location {
        let upto = &self.text[..span.start.min(self.text.len())];
        let line = upto.matches('\n').count() as u32 + 1;
        let col = (upto.len() - upto.rfind('\n').map_or(0, |i| i + 1)) as u32 + 1;
        let mut at = Location::new(self.file.clone(), line, col);
        at.key = self.keys.as_ref().map(|k| k.at(span));
        at
    }

    /// The whole description (a problem the parser gives no span for).
    fn whole(&self) -> Location {
        let mut at = Location::new(self.file.clone(), 1, 1);
        at.key = self.keys.as_ref().map(|_| Arc::new(String::new()));
        at
    }

    pub(super) fn error<T>(&self, at: &Spanned<T>, msg: impl Into<String>) -> Error {
        Error::at(self.location(at.span()), ErrorKind::Invalid(msg.into()))
    }

    /// A model's own errors pass through (they point into the model); a model file that
    /// cannot be read at all is reported where the scene names it.
    pub(super) fn model_errors(&self, at: &Spanned<String>, errors: Errors) -> Errors {
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
    inertias: Option<&mut InertiaCompiler<'_>>,
) -> Result<Scene, Errors> {
    let dir = file.parent().unwrap_or(Path::new(".")).to_path_buf();
    from_text(text, file, dir, None, models, inertias)
}

/// Builds a scene from a description without text of its own, read as the TOML text
/// `text` it serializes to: problems are told by the key path of the value (`objects[0].x`),
/// after the label `file`. Model paths are relative to `dir`.
pub(crate) fn from_serialized(
    text: &str,
    file: Arc<Path>,
    dir: PathBuf,
    models: &dyn ModelSource,
    inertias: Option<&mut InertiaCompiler<'_>>,
) -> Result<Scene, Errors> {
    from_text(text, file, dir, keys::KeyPaths::of(text), models, inertias)
}

/// Where a description (or a part of it) is by its key path, for problems found before it
/// is read as TOML.
pub(crate) fn key_location(file: Arc<Path>, key: &str) -> Location {
    let mut at = Location::new(file, 1, 1);
    at.key = Some(Arc::new(key.to_string()));
    at
}

pub(crate) use keys::join as join_key;

fn from_text(
    text: &str,
    file: Arc<Path>,
    dir: PathBuf,
    keys: Option<keys::KeyPaths>,
    models: &dyn ModelSource,
    inertias: Option<&mut InertiaCompiler<'_>>,
) -> Result<Scene, Errors> {
    let src = Source {
        text,
        file: file.clone(),
        keys,
    };
    // The caller's MuJoCo for the inertials a group writes out, else the build's own.
    let mut builtin = crate::model::merge::builtin_compiler();
    let inertias = match inertias {
        Some(c) => Some(c),
        None => builtin.as_mut().map(|f| f as &mut InertiaCompiler<'_>),
    };
    build(&src, dir, models, inertias).map_err(|mut e| {
        e.0.sort_by_key(|e| match &e.location {
            Some(l) if l.file == file => (0, l.line, l.col),
            _ => (1, 0, 0),
        });
        e
    })
}

/// Whether group `g`'s models get MuJoCo's own `<inertial>`s written out: as the group
/// says, else where they can be (`mujoco` at hand) when a body mass randomizer applies to
/// the group and none changes its geoms' densities or masses (an `<inertial>` would make
/// those do nothing). A written `<inertial>` makes a mass scale a patch of four numbers;
/// the geoms' densities need a body model compiled per variant (docs/compiled.md).
fn write_inertials(
    g: &spec::GroupSpec,
    randomizers: &[randomize::Randomizer],
    mujoco: bool,
) -> group::WriteInertials {
    let name = g.name.as_ref().as_str();
    let applies = |kind: &str, attrs: &[&str]| {
        randomizers.iter().any(|r| {
            r.kind == kind && attrs.contains(&r.attribute.as_str()) && r.applies_to_part(name)
        })
    };
    match g.write_inertials {
        Some(true) => group::WriteInertials::Yes,
        Some(false) => group::WriteInertials::No,
        None if mujoco && applies("body", &["mass"]) && !applies("geom", &["density", "mass"]) => {
            group::WriteInertials::Where
        }
        None => group::WriteInertials::No,
    }
}

fn build(
    src: &Source<'_>,
    dir: PathBuf,
    models: &dyn ModelSource,
    mut inertias: Option<&mut InertiaCompiler<'_>>,
) -> Result<Scene, Errors> {
    let file = src.file.clone();
    let spec: SceneSpec = toml::from_str(src.text).map_err(|e| {
        let location = e.span().map_or_else(|| src.whole(), |s| src.location(s));
        Error::at(location, ErrorKind::Invalid(e.message().trim().to_string()))
    })?;
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
    // What the models' loads warned about (a URDF's inputs MuJoCo's importer warns about).
    let mut warnings: Vec<Warning> = template.warnings().to_vec();
    for f in &spec.fixture {
        let (doc, path) = match load_model(models, src, &dir, &f.model, f.urdf.as_ref()) {
            Ok(x) => x,
            Err(e) => {
                errors.extend(e.0);
                continue;
            }
        };
        files.extend(path);
        warnings.extend_from_slice(doc.warnings());
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
        match randomizer::load(src, &dir, k, r, &prefixes, &group_names) {
            Ok(x) => randomizers.push(x),
            Err(e) => errors.push(e),
        }
    }

    // Groups.
    let angles = Angles::of(&template).map_err(|e| {
        Error::at(
            src.location(spec.base.span()),
            ErrorKind::Invalid(e.to_string()),
        )
    })?;
    let mut groups: Vec<Group> = Vec::new();
    for g in &spec.objects {
        let write = write_inertials(g, &randomizers, inertias.is_some());
        let compile = inertias.as_deref_mut();
        match group::load(
            src, &dir, g, &groups, &template, &angles, models, compile, write, &mut files,
        ) {
            Ok(x) => {
                for m in &x.pool {
                    warnings.extend_from_slice(m.doc.warnings());
                }
                groups.push(x)
            }
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
        written.set_discard_visual();
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
        warnings,
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

pub(super) fn model_options(
    collision_rgba: Option<[f64; 4]>,
    name_unnamed_geoms: bool,
) -> XmlModelOptions {
    XmlModelOptions {
        name: None,
        contact_geom_rgba: collision_rgba,
        name_unnamed_geoms,
        exclude_from_prefixing: Vec::new(),
    }
}

pub(super) fn root_body(doc: &Document) -> Option<Node> {
    let world = doc.worldbody()?;
    let roots = doc.top_level_bodies(world);
    (roots.len() == 1).then(|| roots[0])
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
