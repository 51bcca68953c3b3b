//! The document tier: one MJCF model held in an arena, read exactly as MuJoCo reads it.
//!
//! [`Document`] (this file) is the tier's type: the arena ([`tree`], the only file that
//! names indextree), interned names ([`names`]), flat side tables for source positions and
//! files. Around it, one file per operation on a single model:
//!
//! - reading: [`read`] (the markup into the arena, `<include>` expanded), [`load`] (read,
//!   then [`defaults`] inlined and [`paths`] made absolute), [`load_cache`] (loaded files
//!   served again while unchanged), [`skin`] (binary skin files);
//! - the MJCF vocabulary: [`vocab`] (generated from MuJoCo's schema) and its index
//!   [`schema`] (which attributes declare names and which refer to them);
//! - editing and checking: [`prefix`] (renaming every name and reference), [`validate`]
//!   (duplicate names, dangling references), [`relocate`](mod@relocate) (file references
//!   to content-named assets), [`inertia`] (which bodies take their inertia from geoms, and compiled inertias
//!   written back as `<inertial>`s);
//! - editing as ElementTree code does: [`edit`] (elements moved, taken out, cleared,
//!   copied between documents or into one of their own), [`text`] (text and tail),
//!   [`import`] (nodes copied between arenas, and the [`NodeMap`](import::NodeMap) of where
//!   they went);
//! - writing: [`write`](mod@write) (compact and pretty XML; files through `output`), and
//!   [`locate`] (MuJoCo's errors about what was written, back at the user's sources);
//! - [`limits`]: the input limits every reader honours.
//!
//! May use: `crate::error` and `crate::output` (atomic files). Knows nothing of models,
//! MuJoCo, scenes or the faces above.

pub(crate) mod defaults;
pub(crate) mod edit;
pub mod fuzzing;
pub(crate) mod import;
pub(crate) mod inertia;
mod kinematic;
pub(crate) mod limits;
pub(crate) mod load;
pub(crate) mod load_cache;
pub(crate) mod locate;
pub(crate) mod names;
pub(crate) mod paths;
pub(crate) mod prefix;
mod random_mjcf;
pub(crate) mod read;
mod relocate;
pub(crate) mod rotation;
pub(crate) mod schema;
pub(crate) mod skin;
pub(crate) mod text;
pub(crate) mod tree;
pub(crate) mod urdf;
pub(crate) mod validate;
pub mod vocab;
pub(crate) mod write;

use std::path::Path;
use std::sync::Arc;

use crate::document::limits::Limits;
use crate::document::names::{Names, Sym};
use crate::document::tree::{Attr, AttrRange, Node, NodeData, StrRef, Tree};
use crate::error::{Error, ErrorKind, Location};

/// Where a node came from: index into the document's file table, 1-based line and column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Span {
    pub(crate) file: u32,
    pub(crate) line: u32,
    pub(crate) col: u32,
}

/// A source file of a document and the `<include>` that brought it in.
#[derive(Clone, Debug)]
pub(crate) struct SourceFile {
    /// The file as the user would name it (shown in messages).
    pub(crate) path: Arc<Path>,
    /// The absolute folder of the path the file was read from (`..` resolved by name, as
    /// MuJoCo does): a nested include or an asset of an included file may be found here.
    pub(crate) dir: Arc<Path>,
    /// The include element's span in its own file, `None` for the main file.
    pub(crate) included_at: Option<Span>,
}

/// The sections of an MJCF model that hold lists of elements. [`Document::section`] creates
/// a missing one; repeated sections are merged into the first one at load.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Section {
    /// `<worldbody>`: the kinematic tree.
    Worldbody,
    /// `<asset>`: meshes, textures, materials, height fields, skins.
    Asset,
    /// `<actuator>`.
    Actuator,
    /// `<sensor>`.
    Sensor,
    /// `<tendon>`.
    Tendon,
    /// `<equality>`.
    Equality,
    /// `<contact>`: pairs and excludes.
    Contact,
    /// `<keyframe>`.
    Keyframe,
    /// `<custom>`: numeric, text and tuple data.
    Custom,
    /// `<deformable>`: flexes and skins.
    Deformable,
    /// `<extension>`: plugins.
    Extension,
}

impl Section {
    /// Every section, in the order MJCF files usually list them.
    pub const ALL: [Section; 11] = [
        Section::Extension,
        Section::Custom,
        Section::Asset,
        Section::Worldbody,
        Section::Deformable,
        Section::Contact,
        Section::Equality,
        Section::Tendon,
        Section::Actuator,
        Section::Sensor,
        Section::Keyframe,
    ];

    /// The XML tag of the section.
    pub fn tag(self) -> &'static str {
        match self {
            Section::Worldbody => "worldbody",
            Section::Asset => "asset",
            Section::Actuator => "actuator",
            Section::Sensor => "sensor",
            Section::Tendon => "tendon",
            Section::Equality => "equality",
            Section::Contact => "contact",
            Section::Keyframe => "keyframe",
            Section::Custom => "custom",
            Section::Deformable => "deformable",
            Section::Extension => "extension",
        }
    }

    /// The section written with `tag`, if it is one.
    pub fn from_tag(tag: &str) -> Option<Section> {
        Section::ALL.into_iter().find(|s| s.tag() == tag)
    }
}

/// An MJCF document: a tree of elements in an arena, names interned, every element keeping
/// its source position.
///
/// [`Document::load`] reads a file the way MuJoCo does: `<include>` expanded, default
/// classes resolved into explicit attributes, file references made absolute. What is left
/// compiles from anywhere to the same model as the file.
///
/// ```
/// use mjcf_forge::{Document, Section};
/// let mut doc = Document::from_str(
///     r#"<mujoco model="m"><default><geom rgba="1 0 0 1"/></default>
///        <worldbody><geom name="g" size="1"/></worldbody></mujoco>"#,
///     ".",
/// )?;
/// let world = doc.section(Section::Worldbody);
/// let geom = doc.elements(world).next().unwrap();
/// assert_eq!(doc.attr(geom, "rgba"), Some("1 0 0 1"));
/// assert_eq!(doc.model_name(), Some("m"));
/// assert!(!doc.to_xml_string().contains("default"));
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
#[derive(Clone, Debug)]
pub struct Document {
    pub(crate) tree: Tree,
    pub(crate) root: Node,
    pub(crate) attrs: Vec<Attr>,
    pub(crate) strings: String,
    pub(crate) spans: Vec<Span>,
    pub(crate) files: Arc<Vec<SourceFile>>,
    pub(crate) names: Names,
    /// The folder of the main file: MuJoCo looks for included and asset files here first.
    pub(crate) model_dir: Arc<Path>,
    /// The bounds it was loaded with; files read later (meshes, skins) keep to them too.
    pub(crate) limits: Limits,
    /// What its load warned about (a URDF's inputs that MuJoCo's importer warns about).
    pub(crate) warnings: Vec<crate::error::Warning>,
}

impl Document {
    /// What the load of this document warned about, in the order of the input: the
    /// inputs of a URDF file that MuJoCo's own importer warns about, with its messages
    /// (see [`crate::Warning`]). Empty for MJCF, and for a document built or edited in
    /// memory; the command line prints them, the Python package raises each as a
    /// `UserWarning`.
    pub fn warnings(&self) -> &[crate::error::Warning] {
        &self.warnings
    }

    /// The bounds this document was loaded with (files it reads later keep to them).
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The root `<mujoco>` element.
    pub fn root(&self) -> Node {
        self.root
    }

    /// The model's `name` (the `model` attribute of `<mujoco>`).
    pub fn model_name(&self) -> Option<&str> {
        self.attr(self.root, "model")
    }

    /// The folder of the main file.
    pub fn model_dir(&self) -> &Path {
        &self.model_dir
    }

    /// The section element with this tag, created (empty, at the end) when missing.
    pub fn section(&mut self, section: Section) -> Node {
        if let Some(n) = self.find_section(section) {
            return n;
        }
        let tag = self.names.intern(section.tag());
        let node = self.new_element(tag, None);
        self.tree.append(self.root, node);
        node
    }

    /// The section element with this tag, if the model has one.
    pub fn find_section(&self, section: Section) -> Option<Node> {
        self.elements(self.root)
            .find(|&n| self.tag(n) == section.tag())
    }

    /// Merges repeated container sections (`<asset>`, `<worldbody>`, ...) into the first one
    /// of each kind, keeping order: MuJoCo reads all of them in order, so this changes nothing.
    pub(crate) fn merge_repeated_sections(&mut self) {
        // One pass in document order: sections of different kinds do not interact, so this
        // is the same as merging each kind in turn.
        static TAGS: std::sync::OnceLock<[Sym; Section::ALL.len()]> = std::sync::OnceLock::new();
        let tags = TAGS.get_or_init(|| Section::ALL.map(|s| crate::document::names::sym(s.tag())));
        let mut first: [Option<Node>; Section::ALL.len()] = [None; Section::ALL.len()];
        let mut next = self.tree.first_child(self.root);
        while let Some(node) = next {
            next = self.tree.next_sibling(node);
            let Some(tag) = self.tag_sym(node) else {
                continue;
            };
            let Some(i) = tags.iter().position(|&t| t == tag) else {
                continue;
            };
            match first[i] {
                None => first[i] = Some(node),
                Some(first) => {
                    while let Some(k) = self.tree.first_child(node) {
                        self.tree.detach(k);
                        self.tree.append(first, k);
                    }
                    self.tree.detach(node);
                }
            }
        }
    }

    // ---------------------------------------------------------------- reading nodes

    /// The tag of an element (`""` for a text node).
    pub fn tag(&self, node: Node) -> &str {
        match self.tree.data(node) {
            NodeData::Element { tag, .. } => self.names.resolve(*tag),
            NodeData::Text { .. } => "",
        }
    }

    #[inline]
    pub(crate) fn tag_sym(&self, node: Node) -> Option<Sym> {
        match self.tree.data(node) {
            NodeData::Element { tag, .. } => Some(*tag),
            NodeData::Text { .. } => None,
        }
    }

    /// Whether the node is an element (not character data).
    #[inline]
    pub fn is_element(&self, node: Node) -> bool {
        matches!(self.tree.data(node), NodeData::Element { .. })
    }

    /// The text of a character-data node.
    pub fn text(&self, node: Node) -> Option<&str> {
        match self.tree.data(node) {
            NodeData::Text { text, .. } => Some(self.str(*text)),
            NodeData::Element { .. } => None,
        }
    }

    #[inline]
    pub(crate) fn str(&self, r: StrRef) -> &str {
        &self.strings[r.start as usize..(r.start + r.len) as usize]
    }

    #[inline]
    pub(crate) fn push_str(&mut self, s: &str) -> StrRef {
        let start = self.strings.len() as u32;
        self.strings.push_str(s);
        StrRef {
            start,
            len: s.len() as u32,
        }
    }

    #[inline]
    pub(crate) fn attr_range(&self, node: Node) -> AttrRange {
        match self.tree.data(node) {
            NodeData::Element { attrs, .. } => *attrs,
            NodeData::Text { .. } => AttrRange::default(),
        }
    }

    #[inline]
    pub(crate) fn attr_slice(&self, node: Node) -> &[Attr] {
        let r = self.attr_range(node);
        &self.attrs[r.start as usize..(r.start + r.len) as usize]
    }

    /// The attributes of an element as (name, value) pairs, in order.
    pub fn attrs(&self, node: Node) -> impl Iterator<Item = (&str, &str)> + '_ {
        self.attr_slice(node)
            .iter()
            .map(|a| (self.names.resolve(a.name), self.str(a.value)))
    }

    /// The value of an attribute.
    pub fn attr(&self, node: Node, name: &str) -> Option<&str> {
        let sym = self.names.get(name)?;
        self.attr_sym(node, sym)
    }

    #[inline]
    pub(crate) fn attr_sym(&self, node: Node, sym: Sym) -> Option<&str> {
        self.attr_slice(node)
            .iter()
            .find(|a| a.name == sym)
            .map(|a| self.str(a.value))
    }

    /// The child elements of a node, in order (character data skipped).
    pub fn elements(&self, node: Node) -> impl Iterator<Item = Node> + '_ {
        self.tree.children(node).filter(|&c| self.is_element(c))
    }

    /// All child nodes, character data included.
    pub fn children(&self, node: Node) -> impl Iterator<Item = Node> + '_ {
        self.tree.children(node)
    }

    /// The node and every element below it, in document order.
    pub fn descendants(&self, node: Node) -> impl Iterator<Item = Node> + '_ {
        self.tree.descendants(node).filter(|&c| self.is_element(c))
    }

    /// The parent of a node (`None` for the root).
    pub fn parent(&self, node: Node) -> Option<Node> {
        self.tree.parent(node)
    }

    /// The number of nodes in the document.
    pub fn node_count(&self) -> usize {
        self.tree.count()
    }

    /// The source position of a node, with its include chain.
    pub fn location(&self, node: Node) -> Location {
        self.span_location(self.spans[Tree::index(node)])
    }

    pub(crate) fn span_location(&self, span: Span) -> Location {
        let file = &self.files[span.file as usize];
        let mut included_from = Vec::new();
        let mut at = file.included_at;
        while let Some(s) = at {
            let f = &self.files[s.file as usize];
            included_from.push((f.path.clone(), s.line, s.col));
            at = f.included_at;
        }
        included_from.reverse();
        Location {
            file: file.path.clone(),
            line: span.line,
            col: span.col,
            included_from,
            key: None,
        }
    }

    pub(crate) fn error_at(&self, node: Node, kind: ErrorKind) -> Error {
        Error::at(self.location(node), kind)
    }

    // ---------------------------------------------------------------- changing nodes

    /// Creates a detached element; `origin` gives its source position (else the root's).
    pub(crate) fn new_element(&mut self, tag: Sym, origin: Option<Node>) -> Node {
        let span = origin
            .map(|o| self.spans[Tree::index(o)])
            .unwrap_or_default();
        let node = self.tree.new_node(NodeData::Element {
            tag,
            attrs: AttrRange::default(),
        });
        self.set_span(node, span);
        node
    }

    #[inline]
    pub(crate) fn set_span(&mut self, node: Node, span: Span) {
        let i = Tree::index(node);
        if self.spans.len() <= i {
            self.spans.resize(i + 1, Span::default());
        }
        self.spans[i] = span;
    }

    /// Appends a new child element with the given tag and attributes; returns it.
    ///
    /// ```
    /// use mjcf_forge::{Document, Section};
    /// let mut doc = Document::from_str("<mujoco/>", ".")?;
    /// let world = doc.section(Section::Worldbody);
    /// doc.append_element(world, "geom", &[("size", "0.1")]);
    /// assert_eq!(doc.to_xml_string(), r#"<mujoco><worldbody><geom size="0.1"/></worldbody></mujoco>"#);
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn append_element(&mut self, parent: Node, tag: &str, attrs: &[(&str, &str)]) -> Node {
        let tag = self.names.intern(tag);
        let node = self.new_element(tag, Some(parent));
        for (k, v) in attrs {
            self.set_attr(node, k, v);
        }
        self.tree.append(parent, node);
        node
    }

    /// Sets an attribute (replacing its value, or appending it).
    pub fn set_attr(&mut self, node: Node, name: &str, value: &str) {
        let sym = self.names.intern(name);
        let value = self.push_str(value);
        self.set_attr_ref(node, sym, value);
    }

    pub(crate) fn set_attr_ref(&mut self, node: Node, name: Sym, value: StrRef) {
        let range = self.attr_range(node);
        let slice = &mut self.attrs[range.start as usize..(range.start + range.len) as usize];
        if let Some(a) = slice.iter_mut().find(|a| a.name == name) {
            a.value = value;
            return;
        }
        let end = (range.start + range.len) as usize;
        let new_range = if end == self.attrs.len() {
            // The element's run is last in the table: grow it in place.
            AttrRange {
                start: range.start,
                len: range.len + 1,
            }
        } else {
            // Copy the run to the end; the old run becomes garbage until the next compaction.
            let start = self.attrs.len() as u32;
            self.attrs.extend_from_within(range.start as usize..end);
            AttrRange {
                start,
                len: range.len + 1,
            }
        };
        self.attrs.push(Attr { name, value });
        if let NodeData::Element { attrs, .. } = self.tree.data_mut(node) {
            *attrs = new_range;
        }
    }

    /// Changes the tag of an element.
    pub(crate) fn set_tag(&mut self, node: Node, new: Sym) {
        if let NodeData::Element { tag, .. } = self.tree.data_mut(node) {
            *tag = new;
        }
    }

    /// Replaces all attributes of an element.
    pub(crate) fn replace_attrs(&mut self, node: Node, new: &[Attr]) {
        let start = self.attrs.len() as u32;
        self.attrs.extend_from_slice(new);
        if let NodeData::Element { attrs, .. } = self.tree.data_mut(node) {
            *attrs = AttrRange {
                start,
                len: new.len() as u32,
            };
        }
    }

    /// Removes an attribute; returns whether it was there.
    pub fn remove_attr(&mut self, node: Node, name: &str) -> bool {
        let Some(sym) = self.names.get(name) else {
            return false;
        };
        self.remove_attr_sym(node, sym)
    }

    pub(crate) fn remove_attr_sym(&mut self, node: Node, sym: Sym) -> bool {
        let range = self.attr_range(node);
        let (s, e) = (range.start as usize, (range.start + range.len) as usize);
        let Some(pos) = self.attrs[s..e].iter().position(|a| a.name == sym) else {
            return false;
        };
        // Removing keeps the run contiguous: shift the tail of the run left by one.
        self.attrs[s + pos..e].rotate_left(1);
        if let NodeData::Element { attrs, .. } = self.tree.data_mut(node) {
            attrs.len -= 1;
        }
        true
    }

    /// Detaches a node (and its subtree) from the document.
    pub fn remove(&mut self, node: Node) {
        self.tree.detach(node);
    }

    /// Moves `node` to the end of `parent`'s children.
    pub fn append_node(&mut self, parent: Node, node: Node) {
        self.tree.detach(node);
        self.tree.append(parent, node);
    }

    pub(crate) fn intern(&mut self, name: &str) -> Sym {
        self.names.intern(name)
    }

    pub(crate) fn sym_name(&self, sym: Sym) -> &str {
        self.names.resolve(sym)
    }
}
