//! Editing the tree as ElementTree code does: elements moved to a position among a parent's
//! children, taken out, cleared, renamed, copied in from another document, or copied out
//! into a document of their own. An element's tail (the character data after it, see
//! [`text`](super::text)) goes where the element goes.
//!
//! Nodes are never freed: an element taken out stays in the arena, parentless, and can be
//! put back, so a handle to it never dangles.

use std::path::Path;
use std::sync::Arc;

use crate::document::import::{Import, NodeMap};
use crate::document::limits::Limits;
use crate::document::names::Names;
use crate::document::tree::{AttrRange, Node, NodeData, StrRef, Tree};
use crate::document::{Document, SourceFile, Span};
use crate::error::{Error, ErrorKind};

impl Document {
    /// A document holding one parentless element `tag` as its root: an element not in any
    /// model yet (ElementTree's `Element(tag)`), to fill and then copy into a model with
    /// [`Document::copy_element_from`]. Its positions name the file `<new>`.
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let mut body = Document::with_root("body");
    /// let root = body.root();
    /// body.set_attr(root, "name", "b");
    /// body.append_element(root, "geom", &[("size", "1")]);
    /// assert_eq!(body.to_xml_string(), r#"<body name="b"><geom size="1"/></body>"#);
    /// ```
    pub fn with_root(tag: &str) -> Document {
        let dir: Arc<Path> = Arc::from(Path::new("."));
        let files = Arc::new(vec![SourceFile {
            path: Arc::from(Path::new("<new>")),
            dir: dir.clone(),
            included_at: None,
        }]);
        let mut doc = Document::bare(files, dir, Limits::default(), 2);
        let tag = doc.intern(tag);
        doc.root = doc.new_element(tag, None);
        doc
    }

    /// A document with no element yet: its root is a placeholder for the caller to
    /// replace (as the reader does), its positions in `files`.
    pub(crate) fn bare(
        files: Arc<Vec<SourceFile>>,
        model_dir: Arc<Path>,
        limits: Limits,
        nodes: usize,
    ) -> Document {
        let mut tree = Tree::with_capacity(nodes + 1);
        let placeholder = tree.new_node(NodeData::Text {
            text: StrRef { start: 0, len: 0 },
            cdata: false,
        });
        Document {
            tree,
            root: placeholder,
            attrs: Vec::new(),
            strings: String::new(),
            spans: vec![Span::default()],
            files,
            names: Names::default(),
            model_dir,
            limits,
            warnings: Vec::new(),
        }
    }

    /// A new document whose root is a copy of `node` and everything below it (a detached
    /// copy, as ElementTree's `deepcopy` of an element), with the map from this document's
    /// nodes to the copies. Positions still name the files the nodes were read from.
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let doc = Document::from_str(r#"<mujoco><worldbody><body name="b"><geom size="1"/></body></worldbody></mujoco>"#, ".")?;
    /// let body = doc.find_body("b").unwrap();
    /// let (copy, map) = doc.element_document(body);
    /// assert_eq!(copy.to_xml_string(), r#"<body name="b"><geom size="1"/></body>"#);
    /// assert_eq!(map.get(body), Some(copy.root()));
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn element_document(&self, node: Node) -> (Document, NodeMap) {
        let nodes = self.tree.descendants(node).count();
        let mut doc = Document::bare(
            self.files.clone(),
            self.model_dir.clone(),
            self.limits,
            nodes,
        );
        let mut imp = Import::subtree(&mut doc, self);
        doc.root = doc.import(self, node, None, &mut imp);
        (doc, imp.map.unwrap_or_default())
    }

    /// Whether `ancestor` is `node` itself or one of its ancestors.
    pub fn contains_node(&self, ancestor: Node, node: Node) -> bool {
        std::iter::successors(Some(node), |&n| self.parent(n)).any(|n| n == ancestor)
    }

    /// The child element of `parent` at `index`, counting elements only.
    pub fn element_at(&self, parent: Node, index: usize) -> Option<Node> {
        self.elements(parent).nth(index)
    }

    /// Moves the element `node` (from wherever it is in this document, or from nowhere if
    /// it was taken out) to be child element number `index` of `parent`, with its tail.
    /// `index` counts child elements once `node` is out of its old place; past the end,
    /// the element goes last. An element cannot go into itself or below itself, and the
    /// root stays where it is.
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let mut doc = Document::from_str(r#"<mujoco><worldbody><body name="a"/><body name="b"><geom size="1"/></body></worldbody></mujoco>"#, ".")?;
    /// let (a, b) = (doc.find_body("a").unwrap(), doc.find_body("b").unwrap());
    /// doc.insert_element(a, 0, b)?;
    /// assert_eq!(doc.to_xml_string(), r#"<mujoco><worldbody><body name="a"><body name="b"><geom size="1"/></body></body></worldbody></mujoco>"#);
    /// assert!(doc.insert_element(b, 0, a).is_err());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn insert_element(&mut self, parent: Node, index: usize, node: Node) -> Result<(), Error> {
        let refuse = |doc: &Document, why: &str| {
            Err(doc.error_at(
                node,
                ErrorKind::Invalid(format!(
                    "cannot move <{}> into <{}>: {why}",
                    doc.tag(node),
                    doc.tag(parent)
                )),
            ))
        };
        if !self.is_element(node) || !self.is_element(parent) {
            return refuse(self, "only elements hold and move as elements");
        }
        if node == self.root {
            return refuse(self, "it is the document's root");
        }
        if self.contains_node(node, parent) {
            return refuse(self, "an element cannot go into itself or below itself");
        }
        let tail = self.tail_nodes(node);
        self.tree.detach(node);
        for &t in &tail {
            self.tree.detach(t);
        }
        match self.element_at(parent, index) {
            Some(next) => self.tree.insert_before(next, node),
            None => self.tree.append(parent, node),
        }
        let mut last = node;
        for t in tail {
            self.tree.insert_after(last, t);
            last = t;
        }
        Ok(())
    }

    /// Takes an element (and its tail) out of its parent, as ElementTree's `remove`. It
    /// stays in the arena without a parent: [`Document::insert_element`] can put it back.
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let mut doc = Document::from_str(r#"<mujoco><worldbody><body name="a"/></worldbody></mujoco>"#, ".")?;
    /// let a = doc.find_body("a").unwrap();
    /// doc.remove_element(a);
    /// assert_eq!(doc.to_xml_string(), "<mujoco><worldbody/></mujoco>");
    /// assert_eq!(doc.parent(a), None);
    /// assert_eq!(doc.attr(a, "name"), Some("a"));
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn remove_element(&mut self, node: Node) {
        for t in self.tail_nodes(node) {
            self.tree.detach(t);
        }
        self.tree.detach(node);
    }

    /// Removes every attribute, child, the text and the tail of an element, as
    /// ElementTree's `clear`; the children taken out stay in the arena, parentless.
    pub fn clear_element(&mut self, node: Node) {
        if let NodeData::Element { attrs, .. } = self.tree.data_mut(node) {
            *attrs = AttrRange::default();
        }
        while let Some(k) = self.tree.first_child(node) {
            self.tree.detach(k);
        }
        for t in self.tail_nodes(node) {
            self.tree.detach(t);
        }
    }

    /// Changes the tag of an element.
    pub fn rename(&mut self, node: Node, tag: &str) {
        let tag = self.intern(tag);
        self.set_tag(node, tag);
    }

    /// Copies `node` of `other` and everything below it, with its tail, into this document
    /// as child element number `index` of `parent` (past the end: last); returns where
    /// each copied node of `other` went (the copy of `node` is `map.get(node)`).
    pub fn copy_element_from(
        &mut self,
        other: &Document,
        node: Node,
        parent: Node,
        index: usize,
    ) -> NodeMap {
        let next = self.element_at(parent, index);
        let mut imp = Import::subtree(self, other);
        let top = self.import(other, node, Some(parent), &mut imp);
        let mut tail = Vec::new();
        for t in other.tail_nodes(node) {
            tail.push(self.import(other, t, Some(parent), &mut imp));
        }
        if let Some(next) = next {
            for &n in std::iter::once(&top).chain(&tail) {
                self.tree.detach(n);
                self.tree.insert_before(next, n);
            }
        }
        imp.map.unwrap_or_default()
    }
}

impl Document {
    /// Sets `discardvisual="true"` on the document's last `<compiler>` (the one whose setting
    /// MuJoCo keeps), adding one when it has none.
    pub(crate) fn set_discard_visual(&mut self) {
        let root = self.root();
        let last = self
            .elements(root)
            .filter(|&n| self.tag(n) == "compiler")
            .last();
        match last {
            Some(c) => self.set_attr(c, "discardvisual", "true"),
            None => {
                self.append_element(root, "compiler", &[("discardvisual", "true")]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{Document, Section};

    fn doc(xml: &str) -> Document {
        Document::from_str(xml, ".").unwrap()
    }

    #[test]
    fn moving_within_a_parent_counts_positions_without_the_element() {
        let mut d = doc(
            r#"<mujoco><worldbody><site name="a"/><site name="b"/><site name="c"/></worldbody></mujoco>"#,
        );
        let world = d.section(Section::Worldbody);
        let a = d.element_at(world, 0).unwrap();
        d.insert_element(world, 2, a).unwrap();
        assert_eq!(
            d.to_xml_string(),
            r#"<mujoco><worldbody><site name="b"/><site name="c"/><site name="a"/></worldbody></mujoco>"#
        );
        let a = d.element_at(world, 2).unwrap();
        d.insert_element(world, 0, a).unwrap();
        assert!(
            d.to_xml_string()
                .contains(r#"<worldbody><site name="a"/><site name="b"/>"#)
        );
        assert!(d.insert_element(world, 0, d.root()).is_err());
    }

    #[test]
    fn a_tail_moves_and_is_removed_with_its_element() {
        let mut d = doc("<mujoco><custom>t<numeric name=\"n\"/>tail</custom><size/></mujoco>");
        let custom = d.element_at(d.root(), 0).unwrap();
        let numeric = d.element_at(custom, 0).unwrap();
        let root = d.root();
        d.insert_element(root, 5, numeric).unwrap();
        assert_eq!(
            d.to_xml_string(),
            r#"<mujoco><custom>t</custom><size/><numeric name="n"/>tail</mujoco>"#
        );
        d.remove_element(numeric);
        assert_eq!(
            d.to_xml_string(),
            "<mujoco><custom>t</custom><size/></mujoco>"
        );
        d.clear_element(custom);
        assert_eq!(d.to_xml_string(), "<mujoco><custom/><size/></mujoco>");
    }

    #[test]
    fn copies_between_documents_keep_names_values_and_positions() {
        let part = Document::from_str(
            "<mujoco>\n<worldbody><body name=\"p\" user=\"1 2\"><geom size=\"1\"/></body></worldbody></mujoco>",
            "/tmp",
        )
        .unwrap();
        let body = part.find_body("p").unwrap();
        let mut scene = doc(r#"<mujoco><worldbody><site name="s"/></worldbody></mujoco>"#);
        let world = scene.section(Section::Worldbody);
        let files = scene.files.len();
        for _ in 0..3 {
            let map = scene.copy_element_from(&part, body, world, 0);
            let copy = map.get(body).unwrap();
            assert_eq!(scene.element_at(world, 0), Some(copy));
            assert_eq!(scene.location(copy).line, 2);
        }
        // The part's file is added once, not again for every copy.
        assert_eq!(scene.files.len(), files + 1);
        assert_eq!(scene.elements(world).count(), 4);
        let (alone, map) = scene.element_document(world);
        assert_eq!(map.len(), 1 + 1 + 3 * 2); // worldbody, site, three bodies with a geom each
        assert!(
            alone
                .to_xml_string()
                .starts_with(r#"<worldbody><body name="p" user="1 2">"#)
        );
        let mut new = Document::with_root("site");
        let root = new.root();
        new.rename(root, "camera");
        assert_eq!(new.to_xml_string(), "<camera/>");
    }
}
