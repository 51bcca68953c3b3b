//! Copying nodes of one document into another's arena: names interned again here, strings
//! copied (a merge copies the other's whole buffer once; a single subtree copies its own
//! values), and source positions kept, pointing into the other's files.
//!
//! [`NodeMap`] records where each copied node went, so that callers holding handles to the
//! other document's nodes (the Python proxies, keyframe remapping) can follow them.

use std::sync::Arc;

use crate::document::names::Sym;
use crate::document::tree::{Attr, AttrRange, Node, NodeData, StrRef, Tree};
use crate::document::{Document, SourceFile};

/// Where each node of one document went when it was copied into another (by a merge,
/// [`Document::copy_element_from`] or [`Document::element_document`]).
///
/// Only copied nodes are in the map: a part's `<compiler>` or keyframes, which a merge
/// folds into the base rather than copies, are not; a part's asset that the base already
/// had maps to the base's asset.
///
/// ```
/// use mjcf_forge::{Document, Section};
/// let part = Document::from_str(r#"<mujoco><worldbody><body name="b"><geom size="1"/></body></worldbody></mujoco>"#, ".")?;
/// let body = part.descendants(part.root()).find(|&n| part.tag(n) == "body").unwrap();
/// let mut scene = Document::from_str("<mujoco/>", ".")?;
/// let world = scene.section(Section::Worldbody);
/// let map = scene.copy_element_from(&part, body, world, 0);
/// let copy = map.get(body).unwrap();
/// assert_eq!(scene.attr(copy, "name"), Some("b"));
/// assert_eq!(map.len(), 2); // the body and its geom
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
#[derive(Clone, Debug, Default)]
pub struct NodeMap {
    /// Indexed by the other document's dense node index: copies are made in bulk, and a
    /// vector is cheaper to fill and to read than a hash map.
    to: Vec<Option<Node>>,
    len: usize,
}

impl NodeMap {
    /// The node `from` (of the document copied from) became, if it was copied.
    pub fn get(&self, from: Node) -> Option<Node> {
        self.to.get(Tree::index(from)).copied().flatten()
    }

    /// How many nodes the map holds.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no node was copied.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub(crate) fn insert(&mut self, from: Node, to: Node) {
        let i = Tree::index(from);
        if i >= self.to.len() {
            self.to.resize(i + 1, None);
        }
        if self.to[i].replace(to).is_none() {
            self.len += 1;
        }
    }
}

/// How the other document's source files are found in ours.
enum Files {
    /// Its table was appended to ours at this offset (or is ours: offset 0).
    Offset(u32),
    /// Each of its files' index in our table.
    Map(Vec<u32>),
}

/// State for copying nodes of one document into another.
pub(crate) struct Import {
    files: Files,
    /// Where the other document's string buffer starts in ours, once copied whole; `None`
    /// with `whole_strings` false: values are copied one by one.
    strings_at: Option<u32>,
    whole_strings: bool,
    /// The other document's name ids mapped to ours (the vocabulary's are the same);
    /// `u32::MAX` where not looked up yet.
    syms: Vec<u32>,
    /// Old node to new node, when the caller needs it.
    pub(crate) map: Option<NodeMap>,
}

impl Import {
    /// For a merge: the other's file table appended at `file_offset` (see
    /// [`Document::adopt_files`]), its string buffer copied whole on first use.
    pub(crate) fn new(file_offset: u32, keep_map: bool) -> Import {
        Import {
            files: Files::Offset(file_offset),
            strings_at: None,
            whole_strings: true,
            syms: Vec::new(),
            map: keep_map.then(NodeMap::default),
        }
    }

    /// For one subtree of `other`: values copied one by one (the rest of its buffer is not
    /// ours to carry), its files found in our table or added to it, the map kept.
    pub(crate) fn subtree(doc: &mut Document, other: &Document) -> Import {
        Import {
            files: doc.share_files(other),
            strings_at: None,
            whole_strings: false,
            syms: Vec::new(),
            map: Some(NodeMap::default()),
        }
    }

    fn sym(&mut self, doc: &mut Document, other: &Document, sym: Sym) -> Sym {
        let i = sym.0 as usize;
        if i >= self.syms.len() {
            self.syms.resize(i + 1, u32::MAX);
        }
        if self.syms[i] == u32::MAX {
            self.syms[i] = doc.intern(other.sym_name(sym)).0;
        }
        Sym(self.syms[i])
    }

    /// The other document's string, as a range of ours.
    fn string(&mut self, doc: &mut Document, other: &Document, r: StrRef) -> StrRef {
        if !self.whole_strings {
            return doc.push_str(other.str(r));
        }
        let at = *self.strings_at.get_or_insert_with(|| {
            let at = doc.strings.len() as u32;
            doc.strings.push_str(&other.strings);
            at
        });
        StrRef {
            start: r.start + at,
            len: r.len,
        }
    }

    fn file(&self, file: u32) -> u32 {
        match &self.files {
            Files::Offset(o) => file + o,
            Files::Map(m) => m[file as usize],
        }
    }
}

impl Document {
    /// Appends the part's file table to ours; returns the offset of its first file.
    pub(crate) fn adopt_files(&mut self, part: &Document) -> u32 {
        let offset = self.files.len() as u32;
        let files = Arc::make_mut(&mut self.files);
        for f in part.files.iter() {
            let mut f: SourceFile = f.clone();
            if let Some(s) = &mut f.included_at {
                s.file += offset;
            }
            files.push(f);
        }
        offset
    }

    /// The other's files in our table, each found there (same path, folder and include
    /// site) or added: copying element after element from one document must not grow the
    /// table by the other's whole table each time.
    fn share_files(&mut self, other: &Document) -> Files {
        if Arc::ptr_eq(&self.files, &other.files) {
            return Files::Offset(0);
        }
        let mut map: Vec<u32> = Vec::with_capacity(other.files.len());
        for f in other.files.iter() {
            // Files come before the files they include, so the include site is mapped.
            let included_at = f.included_at.map(|mut s| {
                s.file = map[s.file as usize];
                s
            });
            let found = self
                .files
                .iter()
                .position(|g| g.path == f.path && g.dir == f.dir && g.included_at == included_at);
            let index = match found {
                Some(i) => i as u32,
                None => {
                    let files = Arc::make_mut(&mut self.files);
                    files.push(SourceFile {
                        path: f.path.clone(),
                        dir: f.dir.clone(),
                        included_at,
                    });
                    (files.len() - 1) as u32
                }
            };
            map.push(index);
        }
        Files::Map(map)
    }

    /// Copies one node of `other` (without its children): the last child of `parent`, or
    /// parentless.
    fn import_one(
        &mut self,
        other: &Document,
        node: Node,
        parent: Option<Node>,
        imp: &mut Import,
    ) -> Node {
        let data = match *other.tree.data(node) {
            NodeData::Element { tag, attrs } => {
                let tag = imp.sym(self, other, tag);
                let start = self.attrs.len() as u32;
                for i in attrs.start..attrs.start + attrs.len {
                    let a = other.attrs[i as usize];
                    let name = imp.sym(self, other, a.name);
                    let value = imp.string(self, other, a.value);
                    self.attrs.push(Attr { name, value });
                }
                NodeData::Element {
                    tag,
                    attrs: AttrRange {
                        start,
                        len: attrs.len,
                    },
                }
            }
            NodeData::Text { text, cdata } => NodeData::Text {
                text: imp.string(self, other, text),
                cdata,
            },
        };
        let new = match parent {
            Some(parent) => self.tree.append_new(parent, data),
            None => self.tree.new_node(data),
        };
        let mut span = other.spans[Tree::index(node)];
        span.file = imp.file(span.file);
        self.set_span(new, span);
        if let Some(map) = imp.map.as_mut() {
            map.insert(node, new);
        }
        new
    }

    /// Copies `node` of `other` and everything below it into this arena as the last child of
    /// `parent` (parentless with `None`), through `imp` (in document order, from a stack:
    /// parts nest without bound); returns the copy of `node`. Nodes are created in place
    /// (no detached copy to re-link).
    pub(crate) fn import(
        &mut self,
        other: &Document,
        node: Node,
        parent: Option<Node>,
        imp: &mut Import,
    ) -> Node {
        let top = self.import_one(other, node, parent, imp);
        let mut stack: Vec<(Node, Node)> = Vec::new();
        let push_kids = |stack: &mut Vec<(Node, Node)>, node: Node, copy: Node| {
            let at = stack.len();
            stack.extend(other.children(node).map(|k| (k, copy)));
            stack[at..].reverse();
        };
        push_kids(&mut stack, node, top);
        while let Some((node, parent)) = stack.pop() {
            let copy = self.import_one(other, node, Some(parent), imp);
            push_kids(&mut stack, node, copy);
        }
        top
    }
}
