//! A URDF `<robot>` written as the MJCF document MuJoCo's importer builds from it.
//!
//! The importer's rules, as MuJoCo 3.17.0 and 4.0.0 apply them (docs/urdf.md):
//! - compiler: angles in radians; `fusestatic` and `discardvisual` on unless the file's
//!   own `<mujoco><compiler>` says otherwise; that block's `<option>` and `<size>` kept;
//! - links become bodies in the order of [`Robot::order`]; a link called `world` is the
//!   world body; a joint's `<origin>` places its child body (`rpy` is MJCF's `XYZ` Euler
//!   sequence, written as such);
//! - `<inertial>`: its origin's `xyz`, its mass, and its six inertia numbers as
//!   `fullinertia` (whose principal axes the compiler takes), turned by the origin's `rpy`
//!   first; all six zero leave the inertia undefined and the `rpy` in force;
//! - geoms: each `<collision>`, and each `<visual>` when visuals are kept, in file order,
//!   links in file order; a collision geom takes the colour of the last visual of its link
//!   seen before it; names are kept when not taken yet, and a geom without one keeps the
//!   name of the previous geom of its link (so that it ends up unnamed);
//! - meshes are named after their file's stem; the same stem at another `scale` gets the
//!   stem with the count of its earlier scales appended;
//! - joints: revolute and continuous are hinges, prismatic slides, floating free,
//!   spherical balls, fixed nothing; `<limit>` gives the range (`limited="false"` when
//!   only one bound is given or they are reversed) and `effort` the actuator force range;
//!   `<dynamics>` damping and friction; `<mimic>` a joint equality.

use ahash::{AHashMap, AHashSet};

mod actuators;
mod joints;
mod visuals;

use super::packages::{Packages, Resolved};
use super::robot::Robot;
use super::{UrdfImporter, UrdfOptions};
use crate::document::Document;
use crate::document::tree::{Node, Tree};
use crate::error::{Error, ErrorKind, Errors, Warning};
use joints::JointKind;

/// How `<visual>` elements are read.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Visuals {
    /// Dropped (MuJoCo's default, `discardvisual`).
    Dropped,
    /// Made as MuJoCo makes them when the file's own compiler keeps them: the same name
    /// and mesh rules as the collision geoms, colours as `rgba`.
    AsMuJoCo,
    /// Kept by [`UrdfOptions::visuals`]: the collision geoms read exactly as when visuals
    /// are dropped; the visuals' meshes and names after them; URDF materials as MuJoCo
    /// materials.
    Kept,
}

/// The URDF document `raw` converted with `options`.
pub(crate) fn convert(raw: &Document, options: &UrdfOptions) -> Result<Document, Errors> {
    let mut errors = Vec::new();
    let robot = Robot::read(raw, &mut errors);
    let Some(robot) = robot else {
        return Err(Errors(errors));
    };
    let mut w = Writer::new(raw, options);
    w.write(&robot);
    if w.errors.is_empty() {
        w.doc.warnings = std::mem::take(&mut w.warnings);
        Ok(w.doc)
    } else {
        Err(Errors(w.errors))
    }
}

/// The importer's mesh names: a mesh is its file's stem; the same stem at another scale
/// gets the count of the stem's earlier scales appended; the same stem at the same scale
/// is the same asset.
#[derive(Default)]
struct MeshNames(AHashMap<String, Vec<[f64; 3]>>);

impl MeshNames {
    /// The asset name of `stem` at `scale`, and whether the asset is new.
    fn name(&mut self, stem: &str, scale: [f64; 3]) -> (String, bool) {
        let scales = self.0.entry(stem.to_string()).or_default();
        match scales.iter().position(|s| *s == scale) {
            Some(0) => (stem.to_string(), false),
            Some(i) => (format!("{stem}{i}"), false),
            None => {
                scales.push(scale);
                match scales.len() - 1 {
                    0 => (stem.to_string(), true),
                    i => (format!("{stem}{i}"), true),
                }
            }
        }
    }
}

struct Writer<'r> {
    raw: &'r Document,
    options: &'r UrdfOptions,
    doc: Document,
    errors: Vec<Error>,
    /// What MuJoCo's importer warns about, with its messages.
    warnings: Vec<Warning>,
    visuals: Visuals,
    strippath: bool,
    /// The file's own `<compiler meshdir assetdir>`: where MuJoCo looks for its meshes.
    meshdir: Option<String>,
    assetdir: Option<String>,
    /// URDF material name -> its colour text (the first definition with a colour).
    materials: AHashMap<&'r str, &'r str>,
    /// Mesh assets by file stem, as the importer keys them.
    meshes: MeshNames,
    /// Kept visuals' mesh assets: (file, scale text) -> name.
    visual_meshes: AHashMap<(String, String), String>,
    /// Every mesh asset name given so far.
    mesh_names: AHashSet<String>,
    /// Geom names given so far (the importer's set: the empty name counts once).
    geom_names: AHashSet<String>,
    /// Kept visuals: the names every collision geom ends up with, so that no visual
    /// takes one.
    collision_names: AHashSet<String>,
    /// Kept visuals: the names every collision mesh asset ends up with.
    collision_meshes: AHashSet<String>,
    /// Kept visuals: MuJoCo material names made so far.
    made_materials: AHashSet<String>,
    packages: Packages<'r>,
    asset_meshes: Vec<Node>,
    asset_visual: Vec<Node>,
    root: Node,
    worldbody: Node,
}

/// The text of an `f64` that reads back as it.
fn num(x: f64) -> String {
    let plain = format!("{x}");
    let exp = format!("{x:e}");
    if exp.len() < plain.len() { exp } else { plain }
}

/// MuJoCo's `mjuu_strippath`: the text after the last `/` or `\`.
fn strip_path(file: &str) -> &str {
    file.rsplit(['/', '\\']).next().unwrap_or(file)
}

/// MuJoCo's `mjuu_stripext`: the text before the last `.`.
fn strip_ext(file: &str) -> &str {
    file.rfind('.').map_or(file, |i| &file[..i])
}

impl<'r> Writer<'r> {
    fn new(raw: &'r Document, options: &'r UrdfOptions) -> Writer<'r> {
        let mut doc = Document::bare(
            raw.files.clone(),
            raw.model_dir.clone(),
            raw.limits,
            raw.node_count(),
        );
        let tag = doc.intern("mujoco");
        doc.root = doc.new_element(tag, None);
        let root = doc.root;
        doc.set_span(root, raw.spans[Tree::index(raw.root())]);
        let wb = doc.intern("worldbody");
        let worldbody = doc.new_element(wb, None);
        Writer {
            raw,
            options,
            doc,
            errors: Vec::new(),
            warnings: Vec::new(),
            visuals: Visuals::Dropped,
            strippath: false,
            meshdir: None,
            assetdir: None,
            materials: AHashMap::new(),
            meshes: MeshNames::default(),
            visual_meshes: AHashMap::new(),
            mesh_names: AHashSet::new(),
            geom_names: AHashSet::new(),
            collision_names: AHashSet::new(),
            collision_meshes: AHashSet::new(),
            made_materials: AHashSet::new(),
            packages: Packages {
                map: &options.packages,
                start: &raw.model_dir,
            },
            asset_meshes: Vec::new(),
            asset_visual: Vec::new(),
            root,
            worldbody,
        }
    }

    fn error(&mut self, at: Node, msg: String) {
        self.errors
            .push(self.raw.error_at(at, ErrorKind::Invalid(msg)));
    }

    /// A warning MuJoCo's importer gives, with its message, at `at`.
    fn warn(&mut self, at: Node, message: String) {
        let location = self.raw.location(at);
        self.warnings.push(Warning { location, message });
    }

    /// A new element `tag` of the output, placed at `from`'s source position.
    fn element(&mut self, tag: &str, from: Node) -> Node {
        let sym = self.doc.intern(tag);
        let n = self.doc.new_element(sym, None);
        self.doc.set_span(n, self.raw.spans[Tree::index(from)]);
        n
    }

    fn child(&mut self, parent: Node, tag: &str, from: Node) -> Node {
        let n = self.element(tag, from);
        self.doc.tree.append(parent, n);
        n
    }

    fn set(&mut self, node: Node, name: &str, value: &str) {
        self.doc.set_attr(node, name, value);
    }

    /// The first child element of `node` called `tag`, as the importer finds it.
    fn sub(&self, node: Node, tag: &str) -> Option<Node> {
        self.raw.elements(node).find(|&n| self.raw.tag(n) == tag)
    }

    /// A required attribute, or an error naming it.
    fn required(&mut self, node: Node, attr: &str) -> Option<&'r str> {
        let v = self.raw.attr(node, attr);
        if v.is_none() {
            let tag = self.raw.tag(node).to_string();
            self.error(node, format!("<{tag}> without '{attr}'"));
        }
        v
    }

    /// `count` numbers of an attribute, or an error.
    fn numbers(&mut self, node: Node, attr: &str, text: &str, count: usize) -> Option<Vec<f64>> {
        let v: Result<Vec<f64>, _> = text.split_ascii_whitespace().map(str::parse).collect();
        match v {
            Ok(v) if v.len() == count => Some(v),
            _ => {
                self.error(
                    node,
                    format!("'{attr}' must be {count} number(s), not '{text}'"),
                );
                None
            }
        }
    }

    /// A copy of the `<mujoco>` block's element `src` (attributes and child elements).
    fn copy_tree(&mut self, parent: Node, src: Node, skip: &[&str]) -> Node {
        let tag = self.raw.tag(src).to_string();
        let n = self.child(parent, &tag, src);
        for (k, v) in self.raw.attrs(src) {
            if !skip.contains(&k) {
                self.doc.set_attr(n, k, v);
            }
        }
        for c in self.raw.elements(src).collect::<Vec<_>>() {
            self.copy_tree(n, c, &[]);
        }
        n
    }

    fn write(&mut self, robot: &Robot<'r>) {
        let raw = self.raw;
        let root = raw.root();
        if let Some(name) = raw.attr(root, "name") {
            self.set(self.root, "model", name);
        }
        self.compiler(root);
        self.register_materials(root);
        let asset = self.element("asset", root);
        self.doc.tree.append(self.root, asset);
        self.doc.tree.append(self.root, self.worldbody);

        // Bodies, in the importer's tree order.
        let mut bodies = vec![self.worldbody; robot.links.len()];
        for &i in &robot.order {
            let link = &robot.links[i];
            if link.name == "world" {
                continue;
            }
            let parent = link.parent.map_or(self.worldbody, |p| bodies[p]);
            let body = self.child(parent, "body", link.node);
            self.set(body, "name", link.name);
            if self.options.keep_links.iter().any(|k| k == link.name) {
                self.set(body, "fuse", "false");
            }
            bodies[i] = body;
        }
        for k in &self.options.keep_links {
            if !robot.links.iter().any(|l| l.name == k) {
                self.error(
                    root,
                    format!("keep_links names '{k}', which no <link> defines"),
                );
            }
        }
        // Kept visuals: the collision geoms' names as they are when visuals are dropped.
        if self.visuals == Visuals::Kept {
            self.collision_names = self.names_without_visuals(robot);
            self.collision_meshes = self.collision_mesh_names(robot);
            self.geom_names.clear();
        }
        // Inertials and geoms, links in file order.
        let mut by_node: AHashMap<Node, usize> = AHashMap::new();
        for (i, l) in robot.links.iter().enumerate() {
            by_node.insert(l.node, i);
        }
        for (i, link) in robot.links.iter().enumerate() {
            self.link(link.node, link.name, bodies[i]);
        }
        // Joints, in file order.
        let mut equalities = Vec::new();
        let mut actuated = Vec::new();
        // The importer warns about the <mimic>s it ignores after reading every joint.
        let mut ignored = Vec::new();
        for &j in &robot.joints {
            let Some(child) = self
                .sub(j, "child")
                .and_then(|c| raw.attr(c, "link"))
                .and_then(|name| robot.links.iter().position(|l| l.name == name))
            else {
                continue;
            };
            if let Some(kind) = self.joint(j, bodies[child]) {
                let mimic = self.sub(j, "mimic").filter(|_| kind != JointKind::Fixed);
                let read = match mimic {
                    Some(m) if kind.mimics() && self.leader_moves(m, robot) => {
                        equalities.push((j, m));
                        true
                    }
                    Some(m) => {
                        let name = raw.attr(j, "name").unwrap_or_default();
                        ignored.push((
                            m,
                            format!(
                                "<mimic> on joint '{name}' ignored; mimic requires revolute, \
                                 continuous, or prismatic joints"
                            ),
                        ));
                        false
                    }
                    None => false,
                };
                // A joint its <mimic> drives gets no actuator of its own.
                if kind.mimics() && !read {
                    actuated.push(j);
                }
            }
        }
        for (m, message) in ignored {
            self.warn(m, message);
        }
        if !equalities.is_empty() {
            let eq = self.child(self.root, "equality", root);
            for (j, m) in equalities {
                self.mimic(eq, j, m);
            }
        }
        if let Some(kind) = self.options.actuators.clone() {
            self.actuators(&kind, &actuated);
        }
        for n in std::mem::take(&mut self.asset_meshes)
            .into_iter()
            .chain(std::mem::take(&mut self.asset_visual))
        {
            self.doc.tree.append(asset, n);
        }
        if self.doc.elements(asset).next().is_none() {
            self.doc.tree.detach(asset);
        }
        self.bodies_last();
    }

    /// Each body's elements in the order MJCF is usually written: `<inertial>`, joints,
    /// geoms, then child bodies (the compiled model is the same; what reads elements in
    /// order, such as robosuite's naming and joint lists, sees a link's own first).
    fn bodies_last(&mut self) {
        let body = self.doc.intern("body");
        let rank = |doc: &Document, n: Node| match doc.tag(n) {
            "inertial" => 0,
            "joint" => 1,
            "body" => 3,
            _ => 2,
        };
        let parents: Vec<Node> = std::iter::once(self.worldbody)
            .chain(
                self.doc
                    .descendants(self.worldbody)
                    .filter(|&n| self.doc.tag_sym(n) == Some(body)),
            )
            .collect();
        for p in parents {
            let mut kids: Vec<Node> = self.doc.elements(p).collect();
            kids.sort_by_key(|&k| rank(&self.doc, k));
            for k in kids {
                self.doc.tree.detach(k);
                self.doc.tree.append(p, k);
            }
        }
    }

    /// `<compiler>`, `<option>` and `<size>`: the file's `<mujoco>` block over the
    /// importer's defaults.
    fn compiler(&mut self, root: Node) {
        let raw = self.raw;
        let block = self.sub(root, "mujoco");
        let given = block.and_then(|b| self.sub(b, "compiler"));
        let setting = |attr: &str| given.and_then(|c| raw.attr(c, attr)).map(str::trim);
        self.visuals = if setting("discardvisual") == Some("false") {
            Visuals::AsMuJoCo
        } else if self.options.visuals {
            Visuals::Kept
        } else {
            Visuals::Dropped
        };
        self.strippath = setting("strippath") == Some("true");
        self.meshdir = setting("meshdir").map(str::to_string);
        self.assetdir = setting("assetdir").map(str::to_string);
        let fuse = if self.options.fuse_static {
            setting("fusestatic").unwrap_or("true")
        } else {
            "false"
        };
        let handled = [
            "angle",
            "eulerseq",
            "discardvisual",
            "strippath",
            "fusestatic",
        ];
        let c = match given {
            Some(g) => self.copy_tree(self.root, g, &handled),
            None => self.child(self.root, "compiler", root),
        };
        self.set(c, "angle", "radian");
        self.set(c, "eulerseq", "XYZ");
        self.set(c, "fusestatic", fuse);
        for tag in ["option", "size"] {
            if let Some(e) = block.and_then(|b| self.sub(b, tag)) {
                self.copy_tree(self.root, e, &[]);
            }
        }
    }

    /// A link's `<inertial>` and geoms, into `body`.
    fn link(&mut self, link: Node, name: &str, body: Node) {
        let raw = self.raw;
        if let Some(inertial) = self.sub(link, "inertial") {
            if body == self.worldbody {
                self.error(
                    inertial,
                    format!("the link '{name}' is the world body, which has no <inertial>"),
                );
            } else {
                self.inertial(inertial, body);
            }
        }
        let mut rgba: Option<&'r str> = None;
        let mut geom_name: &'r str = "";
        for e in raw.elements(link).collect::<Vec<_>>() {
            match raw.tag(e) {
                "visual" => {
                    if let Some(c) = self.visual_rgba(e) {
                        rgba = Some(c);
                    }
                    match self.visuals {
                        Visuals::Dropped => {}
                        Visuals::AsMuJoCo => {
                            if let Some(g) = self.geom(e, body, false) {
                                if let Some(c) = rgba {
                                    self.set(g, "rgba", c);
                                }
                                if let Some(n) = raw.attr(e, "name") {
                                    geom_name = n;
                                }
                                self.name_geom(g, geom_name, e);
                            }
                        }
                        Visuals::Kept => self.kept_visual(e, body),
                    }
                }
                "collision" => {
                    if let Some(g) = self.geom(e, body, true) {
                        if let Some(c) = rgba {
                            self.set(g, "rgba", c);
                        }
                        if let Some(n) = raw.attr(e, "name") {
                            geom_name = n;
                        }
                        self.name_geom(g, geom_name, e);
                    }
                }
                _ => {}
            }
        }
    }

    /// The importer's naming: a name not given yet is kept, any other left off, with the
    /// importer's warning (`at`: the URDF element). 3.17.0 warns about a name the element
    /// keeps from the one before it too, 4.0.0 only about the element's own.
    fn name_geom(&mut self, geom: Node, name: &str, at: Node) {
        let own = self.raw.attr(at, "name").is_some();
        if self.geom_names.insert(name.to_string()) {
            if !name.is_empty() {
                self.set(geom, "name", name);
            }
        } else if !name.is_empty() && (own || self.options.importer == UrdfImporter::MuJoCo3) {
            self.warn(
                at,
                format!(
                    "Geom with duplicate name '{name}' encountered in URDF, creating an \
                     unnamed geom."
                ),
            );
        }
    }

    /// `<inertial>`: position, mass, and the full inertia (or, all six numbers zero, an
    /// undefined inertia in the origin's orientation).
    fn inertial(&mut self, inertial: Node, body: Node) {
        let out = self.child(body, "inertial", inertial);
        let origin = self.sub(inertial, "origin");
        let xyz = origin.and_then(|o| self.raw.attr(o, "xyz"));
        self.set(out, "pos", xyz.unwrap_or("0 0 0"));
        if let Some(mass) = self.sub(inertial, "mass") {
            if let Some(v) = self.required(mass, "value") {
                self.set(out, "mass", v);
            }
        } else {
            self.error(inertial, "<inertial> without <mass>".into());
        }
        let Some(inertia) = self.sub(inertial, "inertia") else {
            self.error(inertial, "<inertial> without <inertia>".into());
            return;
        };
        let mut texts = Vec::with_capacity(6);
        let mut defined = false;
        for attr in ["ixx", "iyy", "izz", "ixy", "ixz", "iyz"] {
            let Some(t) = self.required(inertia, attr) else {
                return;
            };
            let Some(v) = self.numbers(inertia, attr, t, 1) else {
                return;
            };
            defined |= v[0] != 0.0;
            texts.push(t.trim());
        }
        let rpy = origin.and_then(|o| self.raw.attr(o, "rpy"));
        let turned = match rpy {
            Some(t) => {
                let Some(v) = self.numbers(origin.unwrap_or(inertial), "rpy", t, 3) else {
                    return;
                };
                v.iter().any(|&a| a != 0.0).then(|| [v[0], v[1], v[2]])
            }
            None => None,
        };
        if defined && turned.is_none() {
            // The compiler takes the principal axes itself: the same computation.
            self.set(out, "fullinertia", &texts.join(" "));
        } else if let (true, Some(rpy)) = (defined, turned) {
            // The importer turns the inertia matrix by the origin's rpy (R I R'), whose
            // principal axes the compiler then takes: the same matrix, written out.
            use crate::document::rotation::{euler_xyz, quat_to_mat, rotate_matrix};
            let v: Vec<f64> = texts.iter().map(|t| t.parse().unwrap_or(0.0)).collect();
            let full = [v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2]];
            let f = rotate_matrix(&quat_to_mat(&euler_xyz(rpy)), &full);
            let six = [f[0], f[4], f[8], f[1], f[2], f[5]].map(num);
            self.set(out, "fullinertia", &six.join(" "));
        } else {
            self.set(out, "diaginertia", "0 0 0");
            if let Some(rpy) = rpy {
                self.set(out, "euler", rpy);
            }
        }
    }

    /// The `<origin>` of `of` as `pos` and `euler` on `out`.
    fn origin(&mut self, of: Node, out: Node) {
        if let Some(o) = self.sub(of, "origin") {
            if let Some(xyz) = self.raw.attr(o, "xyz") {
                self.set(out, "pos", xyz);
            }
            if let Some(rpy) = self.raw.attr(o, "rpy") {
                self.set(out, "euler", rpy);
            }
        }
    }

    /// A geom for a `<visual>` or `<collision>`, appended to `body`.
    fn geom(&mut self, e: Node, body: Node, collision: bool) -> Option<Node> {
        let raw = self.raw;
        let Some(geometry) = self.sub(e, "geometry") else {
            let tag = raw.tag(e).to_string();
            self.error(e, format!("<{tag}> without <geometry>"));
            return None;
        };
        let g = self.element("geom", e);
        let shape = ["box", "cylinder", "sphere", "capsule", "mesh"]
            .into_iter()
            .find_map(|t| self.sub(geometry, t).map(|n| (t, n)));
        let Some((shape, s)) = shape else {
            self.error(
                geometry,
                "visual geometry specification not found: <geometry> holds none of box, cylinder, sphere, capsule, mesh"
                    .into(),
            );
            return None;
        };
        match shape {
            "box" => {
                let size = self.required(s, "size")?;
                let v = self.numbers(s, "size", size, 3)?;
                let half: Vec<String> = v.iter().map(|x| num(x / 2.0)).collect();
                self.set(g, "size", &half.join(" "));
                self.set(g, "type", "box");
            }
            "cylinder" | "capsule" => {
                let r = self.required(s, "radius")?;
                let l = self.required(s, "length")?;
                let r = self.numbers(s, "radius", r, 1)?;
                let l = self.numbers(s, "length", l, 1)?;
                self.set(g, "size", &format!("{} {}", num(r[0]), num(l[0] / 2.0)));
                self.set(g, "type", shape);
            }
            "sphere" => {
                let r = self.required(s, "radius")?;
                let r = self.numbers(s, "radius", r, 1)?;
                self.set(g, "size", &num(r[0]));
                self.set(g, "type", "sphere");
            }
            _ => {
                let mesh = self.mesh(s, collision)?;
                self.set(g, "type", "mesh");
                self.set(g, "mesh", &mesh);
            }
        }
        // A kept visual of no extent (a placeholder box of size 0) has no MuJoCo geom:
        // MuJoCo refuses a size of 0.
        if self.visuals == Visuals::Kept && !collision && shape != "mesh" {
            let flat = self.doc.attr(g, "size").is_some_and(|t| {
                t.split_ascii_whitespace()
                    .any(|x| x.parse::<f64>().is_ok_and(|v| v <= 0.0))
            });
            if flat {
                return None;
            }
        }
        self.origin(e, g);
        if !collision {
            self.set(g, "contype", "0");
            self.set(g, "conaffinity", "0");
            self.set(g, "group", "1");
            self.set(g, "density", "0");
        }
        self.doc.tree.append(body, g);
        Some(g)
    }

    /// The file a URDF reference names, as MJCF will name it. MuJoCo's own rule first: the
    /// name its compiler opens (the file's `strippath` applied, to any path or URI), in the
    /// file's mesh folder (`meshdir`, else `assetdir`, from the URDF's folder) unless
    /// absolute. Only where that finds no file are `package://` and `file://` resolved, so
    /// resolution never changes a model MuJoCo builds. COLLADA and missing files refused,
    /// a missing one with every place looked in.
    fn file_reference(&mut self, at: Node, file: &'r str) -> Option<String> {
        let own = if self.strippath {
            strip_path(file)
        } else {
            file
        };
        let uri = file.starts_with("package://") || file.starts_with("file://");
        if uri && !self.options.resolve_packages {
            // Left as MuJoCo's importer sees it.
            return Some(own.to_string());
        }
        if file.to_ascii_lowercase().ends_with(".dae") {
            let name = strip_path(file);
            self.error(
                at,
                format!(
                    "'{file}' is a COLLADA mesh, which MuJoCo cannot read (it reads STL, OBJ \
                     and MSH): convert it, for example with `assimp export {name} {stem}.obj`, \
                     and point the URDF at the converted file",
                    stem = strip_ext(name),
                ),
            );
            return None;
        }
        let own_full = {
            let p = std::path::Path::new(own);
            let dir = match self.meshdir.as_deref().or(self.assetdir.as_deref()) {
                Some(m) => self.raw.model_dir.join(m),
                None => self.raw.model_dir.to_path_buf(),
            };
            dir.join(p)
        };
        if own_full.is_file() {
            return Some(own.to_string());
        }
        let looked = own_full.display();
        let message = match (uri, self.packages.resolve(file)) {
            (true, Resolved::File(p)) if p.is_file() => {
                return Some(p.to_string_lossy().into_owned());
            }
            (true, Resolved::File(p)) => {
                format!(
                    "'{file}': no such file (not {looked}, where MuJoCo looks, nor {})",
                    p.display()
                )
            }
            (true, Resolved::Unfound(pkg)) => format!(
                "'{file}': no such file where MuJoCo looks ({looked}), and package '{pkg}' is \
                 found nowhere: give its folder (the `packages` option; --urdf-package \
                 {pkg}=DIR on the command line), or list it on ROS_PACKAGE_PATH"
            ),
            _ => format!("'{file}': no such file ({looked})"),
        };
        self.error(at, message);
        None
    }

    /// The mesh asset for a `<mesh>` geometry, made when new; its name.
    fn mesh(&mut self, m: Node, collision: bool) -> Option<String> {
        let raw = self.raw;
        let file = self.required(m, "filename")?;
        let scale_text = raw.attr(m, "scale");
        let scale = match scale_text {
            Some(t) => {
                let v = self.numbers(m, "scale", t, 3)?;
                [v[0], v[1], v[2]]
            }
            None => [1.0; 3],
        };
        let path = self.file_reference(m, file)?;
        let stem_of = |f: &str| strip_ext(strip_path(f)).to_string();
        let stem = stem_of(if self.strippath {
            strip_path(file)
        } else {
            file
        });
        if self.visuals == Visuals::Kept && !collision {
            let key = (path.clone(), scale_text.unwrap_or("1 1 1").to_string());
            if let Some(name) = self.visual_meshes.get(&key) {
                return Some(name.clone());
            }
            let mut name = stem.clone();
            let mut i = 0;
            while self.mesh_names.contains(&name) || self.collision_meshes.contains(&name) {
                name = format!(
                    "{stem}_visual{}",
                    if i == 0 { String::new() } else { i.to_string() }
                );
                i += 1;
            }
            let n = self.mesh_element(m, &name, &path, scale_text);
            // Only massless geoms use it: its inertia is never used, and a flat mesh (a
            // floor, a cloth) has the area a shell needs where it has no volume.
            self.set(n, "inertia", "shell");
            self.asset_visual.push(n);
            self.visual_meshes.insert(key, name.clone());
            return Some(name);
        }
        let (name, new) = self.meshes.name(&stem, scale);
        if !new {
            return Some(name);
        }
        let n = self.mesh_element(m, &name, &path, scale_text);
        self.asset_meshes.push(n);
        Some(name)
    }

    fn mesh_element(&mut self, m: Node, name: &str, path: &str, scale: Option<&str>) -> Node {
        let n = self.element("mesh", m);
        self.set(n, "name", name);
        self.set(n, "file", path);
        if let Some(s) = scale {
            self.set(n, "scale", s);
        }
        self.mesh_names.insert(name.to_string());
        n
    }
}
