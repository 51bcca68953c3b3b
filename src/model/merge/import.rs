//! Copying a part's nodes into the base's arena: its names interned again here, its string
//! buffer copied once, and its source positions kept, pointing into its own files.

use ahash::AHashMap;

use crate::document::names::Sym;
use crate::document::tree::{Attr, Node, NodeData, StrRef, Tree};
use crate::document::{Document, SourceFile};

/// State for copying nodes of one document into another.
pub(super) struct Import {
    file_offset: u32,
    /// Where the other document's string buffer starts in ours, once copied.
    strings_at: Option<u32>,
    /// The other document's name ids mapped to ours (the vocabulary's are the same);
    /// `u32::MAX` where not looked up yet.
    syms: Vec<u32>,
    /// Old node to new node, when the caller needs it (keyframe remapping).
    pub(super) map: Option<AHashMap<Node, Node>>,
}

impl Import {
    pub(super) fn new(file_offset: u32, keep_map: bool) -> Import {
        Import {
            file_offset,
            strings_at: None,
            syms: Vec::new(),
            map: keep_map.then(AHashMap::new),
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

    /// The other document's string, as a range of ours: the whole buffer is copied once.
    fn string(&mut self, doc: &mut Document, other: &Document, r: StrRef) -> StrRef {
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
}

impl Document {
    /// Appends the part's file table to ours; returns the offset of its first file.
    pub(super) fn adopt_files(&mut self, part: &Document) -> u32 {
        let offset = self.files.len() as u32;
        let files = std::sync::Arc::make_mut(&mut self.files);
        for f in part.files.iter() {
            let mut f: SourceFile = f.clone();
            if let Some(s) = &mut f.included_at {
                s.file += offset;
            }
            files.push(f);
        }
        offset
    }

    /// Copies one node of `other` (without its children) under `parent` here.
    fn import_one(&mut self, other: &Document, node: Node, parent: Node, imp: &mut Import) -> Node {
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
                    attrs: crate::document::tree::AttrRange {
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
        let new = self.tree.append_new(parent, data);
        let mut span = other.spans[Tree::index(node)];
        span.file += imp.file_offset;
        self.set_span(new, span);
        if let Some(map) = imp.map.as_mut() {
            map.insert(node, new);
        }
        new
    }

    /// Copies `node` of `other` and everything below it into this arena as the last child of
    /// `parent`, through `imp` (in document order, from a stack: parts nest without bound);
    /// returns the copy of `node`. Nodes are created in place (no detached copy to re-link).
    pub(super) fn import(
        &mut self,
        other: &Document,
        node: Node,
        parent: Node,
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
            let copy = self.import_one(other, node, parent, imp);
            push_kids(&mut stack, node, copy);
        }
        top
    }
}
