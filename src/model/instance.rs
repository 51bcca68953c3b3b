//! The model tier: one instance of a model in a scene, with its own name prefix and the
//! semantic lists robot-learning code asks for (robosuite's `MujocoModel` vocabulary).

use std::collections::BTreeMap;
use std::convert::Infallible;
use std::sync::OnceLock;

use crate::document::import::NodeMap;
use crate::document::names::{Sym, sym};
use crate::document::tree::Node;
use crate::document::vocab::Ns;
use crate::document::{Document, Section};
use crate::error::{Error, ErrorKind, Errors};
use crate::model::geometry;
use crate::model::merge::MergeReport;
use crate::model::sort::{SortKey, SortRules, geom_group, name_unnamed_geoms, sort_elements};

/// What a model in a scene offers: its names, its parts sorted by role, and where it sits.
/// Names returned by the list methods carry the model's prefix.
pub trait MujocoModel {
    /// The model's name.
    fn name(&self) -> &str;
    /// The prefix every name of this instance carries.
    fn naming_prefix(&self) -> &str;
    /// Whether `name` (of namespace `ns`) stays without prefix.
    fn exclude_from_prefixing(&self, ns: Ns, name: &str) -> bool {
        let _ = (ns, name);
        false
    }
    /// A raw name as it appears in this instance: prefixed unless excluded or empty.
    fn correct_naming(&self, name: &str) -> String {
        if name.is_empty() || self.exclude_from_prefixing(Ns::Body, name) {
            name.to_string()
        } else {
            format!("{}{name}", self.naming_prefix())
        }
    }
    /// [`MujocoModel::correct_naming`] of each name of a list.
    fn correct_naming_list(&self, names: &[&str]) -> Vec<String> {
        names.iter().map(|n| self.correct_naming(n)).collect()
    }
    /// [`MujocoModel::correct_naming`] of each value of a map.
    fn correct_naming_map(&self, names: &BTreeMap<String, String>) -> BTreeMap<String, String> {
        names
            .iter()
            .map(|(k, v)| (k.clone(), self.correct_naming(v)))
            .collect()
    }
    /// The one top-level body. One the model file leaves unnamed (robosuite's objects wrap
    /// their body in one) is named `root`, or the first of `root1`, `root2`... that no body
    /// of the model uses, before prefixing: so it can be looked up by name in a compiled
    /// model, and it is the name the same object has in a scene's variants. (robosuite's
    /// own `MujocoXMLModel.root_body` raises a `TypeError` there.)
    fn root_body(&self) -> &str;
    /// Every named body, the root first.
    fn bodies(&self) -> &[String];
    /// Every named joint (free joints included).
    fn joints(&self) -> &[String];
    /// Every named actuator.
    fn actuators(&self) -> &[String];
    /// Every named site of the kinematic tree.
    fn sites(&self) -> &[String];
    /// Every named sensor.
    fn sensors(&self) -> &[String];
    /// Collision geoms: group 0 (MuJoCo's default group).
    fn contact_geoms(&self) -> &[String];
    /// Visual geoms: group 1.
    fn visual_geoms(&self) -> &[String];
    /// Geoms that matter to a task, by role.
    fn important_geoms(&self) -> &BTreeMap<String, Vec<String>>;
    /// Sites that matter to a task, by role.
    fn important_sites(&self) -> &BTreeMap<String, String>;
    /// Sensors that matter to a task, by role.
    fn important_sensors(&self) -> &BTreeMap<String, String>;
    /// The root body's position in its parent.
    fn base_offset(&self) -> [f64; 3];
    /// From the root body's origin down to the model's lowest point, in the root's frame.
    fn bottom_offset(&self) -> [f64; 3];
    /// From the root body's origin up to the model's highest point, in the root's frame.
    fn top_offset(&self) -> [f64; 3];
    /// The largest horizontal distance of the model's geometry from the root's z axis.
    fn horizontal_radius(&self) -> f64;
}

/// How to make an [`XmlModel`].
#[derive(Clone, Debug)]
pub struct XmlModelOptions {
    /// The model's name; by default the `model` attribute, else the root body's name.
    pub name: Option<String>,
    /// Colour for collision geoms (group 0); their material is dropped. `None` leaves them.
    pub contact_geom_rgba: Option<[f64; 4]>,
    /// Give unnamed geoms of group 0 and 1 the names `g{n}_col` and `g{n}_vis`.
    pub name_unnamed_geoms: bool,
    /// Names that stay without prefix, in any namespace.
    pub exclude_from_prefixing: Vec<String>,
}

impl Default for XmlModelOptions {
    /// robosuite's choices: collision geoms drawn in its robot collision colour, unnamed
    /// geoms named.
    fn default() -> XmlModelOptions {
        XmlModelOptions {
            name: None,
            contact_geom_rgba: Some([0.0, 0.5, 0.0, 1.0]),
            name_unnamed_geoms: true,
            exclude_from_prefixing: Vec::new(),
        }
    }
}

/// Where a model sits, computed from its geometry or set by hand (see [`MujocoModel`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Offsets {
    /// The root body's position in its parent.
    pub base: [f64; 3],
    /// From the root body's origin down to the lowest point, in the root's frame.
    pub bottom: [f64; 3],
    /// From the root body's origin up to the highest point, in the root's frame.
    pub top: [f64; 3],
    /// The largest horizontal distance of the geometry from the root's z axis.
    pub horizontal_radius: f64,
}

/// One instance of an MJCF model (robosuite's `MujocoXMLModel`): the document with every
/// name prefixed `{idn}_`, and its parts sorted into the [`MujocoModel`] lists.
///
/// ```
/// use mjcf_forge::{Document, MujocoModel, XmlModel, XmlModelOptions};
/// let doc = Document::from_str(
///     r#"<mujoco model="cube"><worldbody><body name="cube" pos="0 0 0.5">
///          <freejoint name="free"/><geom type="box" size="0.1 0.1 0.1"/>
///          <geom type="box" size="0.1 0.1 0.1" group="1" contype="0" conaffinity="0"/>
///        </body></worldbody></mujoco>"#,
///     ".",
/// )?;
/// let cube = XmlModel::new(doc, 3)?;
/// assert_eq!(cube.naming_prefix(), "3_");
/// assert_eq!(cube.root_body(), "3_cube");
/// assert_eq!(cube.joints(), ["3_free"]);
/// assert_eq!(cube.contact_geoms(), ["3_g0_col"]);
/// assert_eq!(cube.visual_geoms(), ["3_g0_vis"]);
/// assert!((cube.bottom_offset()[2] + 0.1).abs() < 1e-12);
/// assert!((cube.horizontal_radius() - 0.02f64.sqrt()).abs() < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct XmlModel {
    doc: Document,
    name: String,
    prefix: String,
    exclude: Vec<String>,
    root_body: String,
    root: Node,
    /// The semantic lists, read off the document on first use (and again after a merge).
    lists: OnceLock<Lists>,
    important_geoms: BTreeMap<String, Vec<String>>,
    important_sites: BTreeMap<String, String>,
    important_sensors: BTreeMap<String, String>,
    /// Computed on first use (meshes are read from disk), unless set by hand.
    offsets: OnceLock<Result<Offsets, Error>>,
}

/// The semantic lists of a model (names with their prefix).
#[derive(Clone, Debug, Default)]
struct Lists {
    bodies: Vec<String>,
    joints: Vec<String>,
    actuators: Vec<String>,
    sites: Vec<String>,
    sensors: Vec<String>,
    contact_geoms: Vec<String>,
    visual_geoms: Vec<String>,
}

impl Lists {
    /// Reads the lists off a document whose top-level body is `root`: the element sort
    /// with MuJoCo's lists ([`SortRules::MUJOCO`]), `root` first among the bodies.
    fn of(doc: &Document, root: Node) -> Lists {
        let mut l = Lists::default();
        l.bodies
            .extend(doc.attr_sym(root, Syms::get().name).map(str::to_string));
        let Ok(sorted) = sort_elements(doc, SortRules::MUJOCO, |v| {
            Ok::<_, Infallible>(geom_group(v))
        });
        for s in sorted {
            let list = match s.key {
                SortKey::RootBody | SortKey::Bodies => &mut l.bodies,
                SortKey::Joints => &mut l.joints,
                SortKey::Actuators => &mut l.actuators,
                SortKey::Sites => &mut l.sites,
                SortKey::Sensors => &mut l.sensors,
                SortKey::ContactGeoms => &mut l.contact_geoms,
                SortKey::VisualGeoms => &mut l.visual_geoms,
            };
            for (node, name) in s.nodes.into_iter().zip(s.names) {
                if node != root {
                    list.extend(name);
                }
            }
        }
        l
    }
}

/// Names this module looks up often, interned once.
struct Syms {
    name: Sym,
    rgba: Sym,
    material: Sym,
}

impl Syms {
    fn get() -> &'static Syms {
        static SYMS: OnceLock<Syms> = OnceLock::new();
        SYMS.get_or_init(|| Syms {
            name: sym("name"),
            rgba: sym("rgba"),
            material: sym("material"),
        })
    }
}

/// Names `root`, the top-level body of `doc`, when it has no name: `root`, or the first of
/// `root1`, `root2`... that no body under it uses (see [`MujocoModel::root_body`]). The one
/// rule for models and for the objects a scene places.
pub(crate) fn name_unnamed_root(doc: &mut Document, root: Node) {
    if doc.attr(root, "name").is_some() {
        return;
    }
    let taken: Vec<&str> = doc
        .descendants(root)
        .filter(|&n| doc.tag(n) == "body")
        .filter_map(|n| doc.attr(n, "name"))
        .collect();
    let name = (0..)
        .map(|k| match k {
            0 => "root".to_string(),
            k => format!("root{k}"),
        })
        .find(|n| !taken.contains(&n.as_str()))
        .expect("a free name exists");
    doc.set_attr(root, "name", &name);
}

impl XmlModel {
    /// An instance with robosuite's default options (see [`XmlModelOptions`]).
    pub fn new(doc: Document, idn: impl std::fmt::Display) -> Result<XmlModel, Errors> {
        XmlModel::with_options(doc, idn, XmlModelOptions::default())
    }

    /// An instance named with prefix `{idn}_`. Errors: not exactly one top-level body.
    pub fn with_options(
        doc: Document,
        idn: impl std::fmt::Display,
        options: XmlModelOptions,
    ) -> Result<XmlModel, Errors> {
        XmlModel::with_prefix(doc, &format!("{idn}_"), options)
    }

    /// An instance whose names all get exactly `prefix` (which may be empty).
    pub fn with_prefix(
        mut doc: Document,
        prefix: &str,
        options: XmlModelOptions,
    ) -> Result<XmlModel, Errors> {
        let prefix = prefix.to_string();
        let world = doc.section(Section::Worldbody);
        let roots = doc.top_level_bodies(world);
        if roots.len() != 1 {
            return Err(Error::at(
                doc.location(world),
                ErrorKind::Invalid(format!(
                    "expected exactly one top-level body in <worldbody>, found {}",
                    roots.len()
                )),
            )
            .into());
        }
        // The element sort (robosuite's, `sort.rs`) names the unnamed geoms and finds the
        // collision geoms to colour.
        let syms = Syms::get();
        let root = roots[0];
        name_unnamed_root(&mut doc, root);
        let Ok(mut sorted) = sort_elements(&doc, SortRules::MUJOCO, |v| {
            Ok::<_, Infallible>(geom_group(v))
        });
        if options.name_unnamed_geoms {
            name_unnamed_geoms(&mut doc, &mut sorted);
        }
        if let Some(rgba) = options.contact_geom_rgba {
            let value = doc.push_str(&rgba.map(|x| format!("{x}")).join(" "));
            let contact = sorted.iter().filter(|s| s.key == SortKey::ContactGeoms);
            for &g in contact.flat_map(|s| &s.nodes) {
                doc.set_attr_ref(g, syms.rgba, value);
                doc.remove_attr_sym(g, syms.material);
            }
        }
        let exclude = options.exclude_from_prefixing.clone();
        doc.apply_prefix_except(&prefix, |_, name| exclude.iter().any(|e| e == name))?;

        let root_body = doc.attr(root, "name").unwrap_or_default().to_string();
        let name = options
            .name
            .clone()
            .or_else(|| doc.model_name().map(str::to_string))
            .unwrap_or_else(|| root_body.clone());
        Ok(XmlModel {
            doc,
            name,
            prefix,
            exclude: options.exclude_from_prefixing,
            root_body,
            root,
            lists: OnceLock::new(),
            important_geoms: BTreeMap::new(),
            important_sites: BTreeMap::new(),
            important_sensors: BTreeMap::new(),
            offsets: OnceLock::new(),
        })
    }

    fn lists(&self) -> &Lists {
        self.lists.get_or_init(|| Lists::of(&self.doc, self.root))
    }

    /// The instance's document (names prefixed).
    pub fn document(&self) -> &Document {
        &self.doc
    }

    /// The instance's document, for changes.
    pub fn document_mut(&mut self) -> &mut Document {
        &mut self.doc
    }

    /// The instance's document, taken out.
    pub fn into_document(self) -> Document {
        self.doc
    }

    /// Sets the important geoms by role, with raw (unprefixed) names.
    pub fn set_important_geoms(&mut self, geoms: BTreeMap<String, Vec<String>>) {
        self.important_geoms = geoms
            .into_iter()
            .map(|(k, v)| (k, v.iter().map(|n| self.correct_naming(n)).collect()))
            .collect();
    }

    /// Sets the important sites by role, with raw (unprefixed) names.
    pub fn set_important_sites(&mut self, sites: BTreeMap<String, String>) {
        self.important_sites = self.correct_naming_map(&sites);
    }

    /// Sets the important sensors by role, with raw (unprefixed) names.
    pub fn set_important_sensors(&mut self, sensors: BTreeMap<String, String>) {
        self.important_sensors = self.correct_naming_map(&sensors);
    }

    /// The offsets from the model's geometry (computed once, on first use): the root body's
    /// position, and the bounds of every geom below it in the root's frame with the tree as
    /// written (primitives exactly, meshes from their vertices; planes and height fields
    /// left out). An unreadable mesh file is the error, an [`ErrorKind::Geometry`].
    ///
    /// ```
    /// use mjcf_forge::{Document, ErrorKind, XmlModel};
    /// let doc = Document::from_str(
    ///     "<mujoco><worldbody><body name='b'><geom type='box' size='1 x 1'/></body></worldbody></mujoco>", ".")?;
    /// let e = XmlModel::new(doc, 0)?.try_offsets().unwrap_err();
    /// assert!(matches!(e.kind, ErrorKind::Geometry(_)));
    /// assert!(e.to_string().contains("attribute 'size': 'x' is not a number at"), "{e}");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn try_offsets(&self) -> Result<Offsets, Error> {
        self.offsets.get_or_init(|| self.compute_offsets()).clone()
    }

    fn compute_offsets(&self) -> Result<Offsets, Error> {
        let doc = &self.doc;
        let missing = |what: &str| Error::bare(ErrorKind::Geometry(what.to_string()));
        let world = doc
            .find_section(Section::Worldbody)
            .ok_or_else(|| missing("no worldbody"))?;
        let root = *doc
            .top_level_bodies(world)
            .first()
            .ok_or_else(|| missing("no root body"))?;
        let angles = geometry::Angles::of(doc)?;
        let base = geometry::element_pose(doc, root, &angles)?.pos;
        let bounds = geometry::subtree_bounds(doc, root, |_, _| true)?;
        let finite = bounds.min.iter().chain(&bounds.max).all(|x| x.is_finite());
        Ok(Offsets {
            base,
            bottom: [0.0, 0.0, if finite { bounds.min[2] } else { 0.0 }],
            top: [0.0, 0.0, if finite { bounds.max[2] } else { 0.0 }],
            horizontal_radius: if finite {
                bounds.horizontal_radius
            } else {
                0.0
            },
        })
    }

    fn offsets_mut(&mut self) -> &mut Offsets {
        if self.offsets.get().is_none_or(|o| o.is_err()) {
            let computed = self.compute_offsets().unwrap_or_default();
            self.offsets = OnceLock::from(Ok(computed));
        }
        self.offsets
            .get_mut()
            .and_then(|o| o.as_mut().ok())
            .expect("offsets set above")
    }

    /// Overrides the computed bottom offset.
    pub fn set_bottom_offset(&mut self, offset: [f64; 3]) {
        self.offsets_mut().bottom = offset;
    }

    /// Overrides the computed top offset.
    pub fn set_top_offset(&mut self, offset: [f64; 3]) {
        self.offsets_mut().top = offset;
    }

    /// Overrides the computed horizontal radius.
    pub fn set_horizontal_radius(&mut self, radius: f64) {
        self.offsets_mut().horizontal_radius = radius;
    }

    /// Overrides the base offset.
    pub fn set_base_offset(&mut self, offset: [f64; 3]) {
        self.offsets_mut().base = offset;
    }

    /// Merges another instance into this one: into the world body, or into this model's
    /// body named `into` (a full, prefixed name). Lists grow by the other's.
    pub fn merge(
        &mut self,
        other: &XmlModel,
        into: Option<&str>,
        fuse_keys: bool,
    ) -> Result<MergeReport, Errors> {
        self.merge_all(&[(other, into)], fuse_keys)
    }

    /// Merges several instances in order (each into the world body or into a body of this
    /// model), checking every name once up front (see [`Document::merge_all`]).
    pub fn merge_all(
        &mut self,
        others: &[(&XmlModel, Option<&str>)],
        fuse_keys: bool,
    ) -> Result<MergeReport, Errors> {
        self.merge_with(others, fuse_keys, false)
            .map(|(report, _)| report)
    }

    /// [`XmlModel::merge_all`], also telling where each other model's nodes went (see
    /// [`Document::merge_all_mapped`]).
    pub fn merge_all_mapped(
        &mut self,
        others: &[(&XmlModel, Option<&str>)],
        fuse_keys: bool,
    ) -> Result<(MergeReport, Vec<NodeMap>), Errors> {
        self.merge_with(others, fuse_keys, true)
    }

    fn merge_with(
        &mut self,
        others: &[(&XmlModel, Option<&str>)],
        fuse_keys: bool,
        keep_maps: bool,
    ) -> Result<(MergeReport, Vec<NodeMap>), Errors> {
        let parts: Vec<crate::model::merge::MergePart<'_>> = others
            .iter()
            .map(|(m, into)| crate::model::merge::MergePart {
                doc: &m.doc,
                into: *into,
                prefix: &m.prefix,
            })
            .collect();
        let out = self.doc.merge_checked(&parts, fuse_keys, keep_maps, None)?;
        // The model's extent and lists changed with the merge.
        self.offsets = OnceLock::new();
        self.lists = OnceLock::new();
        Ok(out)
    }
}

impl MujocoModel for XmlModel {
    fn name(&self) -> &str {
        &self.name
    }
    fn naming_prefix(&self) -> &str {
        &self.prefix
    }
    fn exclude_from_prefixing(&self, _ns: Ns, name: &str) -> bool {
        self.exclude.iter().any(|e| e == name)
    }
    fn root_body(&self) -> &str {
        &self.root_body
    }
    fn bodies(&self) -> &[String] {
        &self.lists().bodies
    }
    fn joints(&self) -> &[String] {
        &self.lists().joints
    }
    fn actuators(&self) -> &[String] {
        &self.lists().actuators
    }
    fn sites(&self) -> &[String] {
        &self.lists().sites
    }
    fn sensors(&self) -> &[String] {
        &self.lists().sensors
    }
    fn contact_geoms(&self) -> &[String] {
        &self.lists().contact_geoms
    }
    fn visual_geoms(&self) -> &[String] {
        &self.lists().visual_geoms
    }
    fn important_geoms(&self) -> &BTreeMap<String, Vec<String>> {
        &self.important_geoms
    }
    fn important_sites(&self) -> &BTreeMap<String, String> {
        &self.important_sites
    }
    fn important_sensors(&self) -> &BTreeMap<String, String> {
        &self.important_sensors
    }
    /// NaN when the geometry cannot be read (see [`XmlModel::try_offsets`]).
    fn base_offset(&self) -> [f64; 3] {
        self.try_offsets().map(|o| o.base).unwrap_or([f64::NAN; 3])
    }
    /// NaN when the geometry cannot be read (see [`XmlModel::try_offsets`]).
    fn bottom_offset(&self) -> [f64; 3] {
        self.try_offsets()
            .map(|o| o.bottom)
            .unwrap_or([f64::NAN; 3])
    }
    /// NaN when the geometry cannot be read (see [`XmlModel::try_offsets`]).
    fn top_offset(&self) -> [f64; 3] {
        self.try_offsets().map(|o| o.top).unwrap_or([f64::NAN; 3])
    }
    /// NaN when the geometry cannot be read (see [`XmlModel::try_offsets`]).
    fn horizontal_radius(&self) -> f64 {
        self.try_offsets()
            .map(|o| o.horizontal_radius)
            .unwrap_or(f64::NAN)
    }
}

/// [`XmlModel::info_json`]'s object, its keys in this order.
#[derive(serde::Serialize)]
struct Info<'a> {
    name: &'a str,
    naming_prefix: &'a str,
    root_body: &'a str,
    bodies: &'a [String],
    joints: &'a [String],
    actuators: &'a [String],
    sites: &'a [String],
    sensors: &'a [String],
    contact_geoms: &'a [String],
    visual_geoms: &'a [String],
    important_geoms: &'a BTreeMap<String, Vec<String>>,
    important_sites: &'a BTreeMap<String, String>,
    important_sensors: &'a BTreeMap<String, String>,
    base_offset: [f64; 3],
    bottom_offset: [f64; 3],
    top_offset: [f64; 3],
    horizontal_radius: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    geometry_error: Option<String>,
}

/// JSON on one line with Python's `json.dumps` separators (`", "`, `": "`), and numbers
/// as Rust prints them (`0`, `0.1`; a number that is not finite is `null`).
struct OneLine;

impl serde_json::ser::Formatter for OneLine {
    fn begin_array_value<W: ?Sized + std::io::Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        if first {
            Ok(())
        } else {
            writer.write_all(b", ")
        }
    }

    fn begin_object_key<W: ?Sized + std::io::Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        if first {
            Ok(())
        } else {
            writer.write_all(b", ")
        }
    }

    fn begin_object_value<W: ?Sized + std::io::Write>(
        &mut self,
        writer: &mut W,
    ) -> std::io::Result<()> {
        writer.write_all(b": ")
    }

    fn write_f64<W: ?Sized + std::io::Write>(
        &mut self,
        writer: &mut W,
        value: f64,
    ) -> std::io::Result<()> {
        write!(writer, "{value}")
    }
}

impl XmlModel {
    /// Everything [`MujocoModel`] tells, as one JSON object (keys in a fixed order).
    ///
    /// ```
    /// use mjcf_forge::{Document, XmlModel};
    /// let doc = Document::from_str(r#"<mujoco><worldbody><body name="b"><geom size="1"/></body></worldbody></mujoco>"#, ".")?;
    /// let json = XmlModel::new(doc, 0)?.info_json();
    /// assert!(json.starts_with(r#"{"name": "0_b", "naming_prefix": "0_", "root_body": "0_b""#));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn info_json(&self) -> String {
        let offsets = self.try_offsets();
        let info = Info {
            name: &self.name,
            naming_prefix: &self.prefix,
            root_body: &self.root_body,
            bodies: self.bodies(),
            joints: self.joints(),
            actuators: self.actuators(),
            sites: self.sites(),
            sensors: self.sensors(),
            contact_geoms: self.contact_geoms(),
            visual_geoms: self.visual_geoms(),
            important_geoms: &self.important_geoms,
            important_sites: &self.important_sites,
            important_sensors: &self.important_sensors,
            base_offset: self.base_offset(),
            bottom_offset: self.bottom_offset(),
            top_offset: self.top_offset(),
            horizontal_radius: self.horizontal_radius(),
            geometry_error: offsets.as_ref().err().map(ToString::to_string),
        };
        let mut out = Vec::new();
        let mut writer = serde_json::Serializer::with_formatter(&mut out, OneLine);
        serde::Serialize::serialize(&info, &mut writer).expect("writing to memory cannot fail");
        String::from_utf8(out).expect("serde_json writes UTF-8")
    }
}
