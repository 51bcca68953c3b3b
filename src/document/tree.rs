//! The arena: the only module that names `indextree`.
//!
//! A document is one `indextree::Arena` of small node payloads plus flat side tables
//! (attributes, string bytes, source spans) owned by [`crate::Document`]. Cloning a document
//! is therefore a handful of `Vec` copies, which is what makes template -> variant cheap.

use indextree::{Arena, NodeId};

use crate::document::names::Sym;

/// A range of bytes in the document's string buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct StrRef {
    pub(crate) start: u32,
    pub(crate) len: u32,
}

/// One attribute: an interned name and a value in the string buffer (12 bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Attr {
    pub(crate) name: Sym,
    pub(crate) value: StrRef,
}

/// A run of attributes in the document's flat attribute table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct AttrRange {
    pub(crate) start: u32,
    pub(crate) len: u32,
}

/// Node payload: kept tiny because it is multiplied by nodes and then by variants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum NodeData {
    Element {
        tag: Sym,
        attrs: AttrRange,
    },
    /// Character data that is not just white space; `cdata` keeps `<![CDATA[..]]>` form.
    Text {
        text: StrRef,
        cdata: bool,
    },
}

/// A handle to one node of a [`crate::Document`]. Cheap to copy; only meaningful for the
/// document it came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Node(pub(crate) NodeId);

/// The tree of a document.
#[derive(Clone, Debug)]
pub(crate) struct Tree {
    arena: Arena<NodeData>,
}

impl Tree {
    pub(crate) fn with_capacity(n: usize) -> Tree {
        Tree {
            arena: Arena::with_capacity(n),
        }
    }

    #[inline]
    /// Makes room for `n` more nodes.
    pub(crate) fn reserve(&mut self, n: usize) {
        self.arena.reserve(n);
    }

    pub(crate) fn new_node(&mut self, data: NodeData) -> Node {
        Node(self.arena.new_node(data))
    }

    /// Dense index of a node, for side tables (0-based). Nodes made later have larger
    /// indices, so an index range tells which merge brought a node in.
    #[inline]
    pub(crate) fn index(node: Node) -> usize {
        usize::from(node.0) - 1
    }

    #[inline]
    pub(crate) fn data(&self, node: Node) -> &NodeData {
        self.arena[node.0].get()
    }

    #[inline]
    pub(crate) fn data_mut(&mut self, node: Node) -> &mut NodeData {
        self.arena[node.0].get_mut()
    }

    pub(crate) fn append(&mut self, parent: Node, child: Node) {
        parent.0.append(child.0, &mut self.arena);
    }

    /// Creates a node as the last child of `parent`. Unlike [`Tree::append`] this skips
    /// the ancestor walk that guards against cycles: a new node cannot be an ancestor.
    #[inline]
    pub(crate) fn append_new(&mut self, parent: Node, data: NodeData) -> Node {
        Node(parent.0.append_value(data, &mut self.arena))
    }

    pub(crate) fn insert_before(&mut self, sibling: Node, new: Node) {
        sibling.0.insert_before(new.0, &mut self.arena);
    }

    pub(crate) fn insert_after(&mut self, sibling: Node, new: Node) {
        sibling.0.insert_after(new.0, &mut self.arena);
    }

    pub(crate) fn prepend(&mut self, parent: Node, child: Node) {
        parent.0.prepend(child.0, &mut self.arena);
    }

    pub(crate) fn detach(&mut self, node: Node) {
        node.0.detach(&mut self.arena);
    }

    #[inline]
    pub(crate) fn parent(&self, node: Node) -> Option<Node> {
        self.arena[node.0].parent().map(Node)
    }

    #[inline]
    pub(crate) fn first_child(&self, node: Node) -> Option<Node> {
        self.arena[node.0].first_child().map(Node)
    }

    #[inline]
    pub(crate) fn last_child(&self, node: Node) -> Option<Node> {
        self.arena[node.0].last_child().map(Node)
    }

    #[inline]
    pub(crate) fn next_sibling(&self, node: Node) -> Option<Node> {
        self.arena[node.0].next_sibling().map(Node)
    }

    #[inline]
    pub(crate) fn previous_sibling(&self, node: Node) -> Option<Node> {
        self.arena[node.0].previous_sibling().map(Node)
    }

    pub(crate) fn children(&self, node: Node) -> impl Iterator<Item = Node> + '_ {
        node.0.children(&self.arena).map(Node)
    }

    /// The node and all its descendants in document order.
    pub(crate) fn descendants(&self, node: Node) -> impl Iterator<Item = Node> + '_ {
        node.0.descendants(&self.arena).map(Node)
    }

    pub(crate) fn count(&self) -> usize {
        self.arena.len()
    }
}
