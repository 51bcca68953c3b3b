//! The builder both readers write through: the document's tables filled in place, names
//! checked when first met, character data joined into one node per run.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::Main;
use super::checks::{expand_refs, name_problem};
use super::tags::AttrSpan;
use crate::document::limits::Limits;
use crate::document::names::{Names, Sym};
use crate::document::tree::{Node, NodeData, Tree};
use crate::document::{Document, SourceFile, Span};
use crate::error::{Error, ErrorKind, Errors, Location};

pub(super) struct Builder {
    pub(super) doc: Document,
    pub(super) files: Vec<SourceFile>,
    /// Canonical paths of the files being read, outermost first (for cycles).
    pub(super) chain: Vec<PathBuf>,
    /// The same files as the user would name them.
    pub(super) chain_display: Vec<PathBuf>,
    /// The main file's folder as the user named it: included files are shown under it.
    pub(super) display_dir: PathBuf,
    /// The main file's absolute path until its canonical path is needed: that takes a
    /// system call per path component, and only `<include>` needs it.
    pub(super) main_to_canonicalize: Option<PathBuf>,
    /// Character data gathered across text and entity events (reused buffer).
    pub(super) pending_text: String,
    /// Attribute spans of the tag being read (reused buffer).
    pub(super) attr_spans: Vec<AttrSpan>,
    /// For `parse_fast`: the open elements' name ranges in their source (reused buffer).
    pub(super) open_names: Vec<(u32, u32)>,
    /// Canonical paths of every file read so far (MuJoCo includes a file at most once),
    /// hashed: thousands of sibling includes stay linear.
    pub(super) seen_set: ahash::AHashSet<PathBuf>,
    pub(super) limits: Limits,
    /// Whether the root is URDF's `<robot>` (whose names may hold a `:`).
    pub(super) urdf: bool,
    /// The depth of the element the file being read inserts its elements under (0 for the
    /// main file, whose root element is level 1).
    pub(super) depth_base: u32,
    /// How many includes deep the file being read is (0: the main file).
    pub(super) include_depth: u32,
}

impl Builder {
    pub(super) fn new(
        size: usize,
        name: &Arc<Path>,
        model_dir: &Arc<Path>,
        display_dir: &Path,
        main: &Main,
        limits: &Limits,
    ) -> Builder {
        // Sized from the robosuite and dm_control models (about 100 bytes of XML per node,
        // 15 per attribute once defaults are inlined, 0.55 bytes of values per byte), so
        // that loading seldom grows a table.
        let mut tree = Tree::with_capacity(size / 80 + 16);
        let placeholder = tree.new_node(NodeData::Text {
            text: crate::document::tree::StrRef { start: 0, len: 0 },
            cdata: false,
        });
        let mut spans = Vec::with_capacity(size / 80 + 16);
        spans.push(Span::default());
        Builder {
            doc: Document {
                tree,
                root: placeholder,
                attrs: Vec::with_capacity(size / 12 + 16),
                strings: String::with_capacity(size / 2 + size / 8),
                spans,
                files: Arc::new(Vec::new()),
                names: Names::default(),
                model_dir: model_dir.clone(),
                limits: *limits,
                warnings: Vec::new(),
            },
            files: vec![SourceFile {
                path: name.clone(),
                dir: model_dir.clone(),
                included_at: None,
            }],
            chain: Vec::new(),
            // The main file joins both chains when the first include is met; a text has
            // no file to be part of a cycle.
            chain_display: match main {
                Main::File { .. } => vec![name.to_path_buf()],
                Main::Text => Vec::new(),
            },
            display_dir: display_dir.to_path_buf(),
            main_to_canonicalize: match main {
                Main::File { abs } => Some(abs.clone()),
                Main::Text => None,
            },
            pending_text: String::new(),
            attr_spans: Vec::new(),
            open_names: Vec::new(),
            seen_set: ahash::AHashSet::new(),
            limits: *limits,
            urdf: false,
            depth_base: 0,
            include_depth: 0,
        }
    }

    pub(super) fn finish(self) -> Result<Document, Errors> {
        let mut doc = self.doc;
        doc.files = Arc::new(self.files);
        // The placeholder (node 0) stays the root when the text had no root element.
        if Tree::index(doc.root) == 0 {
            return Err(Error::at(
                Location::new(doc.files[0].path.clone(), 1, 1),
                ErrorKind::NotMjcf("no root element".into()),
            )
            .into());
        }
        Ok(doc)
    }

    pub(super) fn loc(&self, file: u32, line: u32, col: u32) -> Location {
        let mut loc = Location::new(self.files[file as usize].path.clone(), line, col);
        let mut at = self.files[file as usize].included_at;
        while let Some(s) = at {
            let f = &self.files[s.file as usize];
            loc.included_from.push((f.path.clone(), s.line, s.col));
            at = f.included_at;
        }
        loc.included_from.reverse();
        loc
    }

    pub(super) fn text(&mut self, host: Node, text: &str, cdata: bool, span: Span) {
        // Adjacent runs (text split by entity references) are joined into one node.
        if !cdata
            && let Some(last) = self.doc.tree.last_child(host)
            && let NodeData::Text {
                text: r,
                cdata: false,
            } = *self.doc.tree.data(last)
            && (r.start + r.len) as usize == self.doc.strings.len()
        {
            self.doc.strings.push_str(text);
            if let NodeData::Text { text: r, .. } = self.doc.tree.data_mut(last) {
                r.len += text.len() as u32;
            }
            return;
        }
        let r = self.doc.push_str(text);
        let n = self
            .doc
            .tree
            .append_new(host, NodeData::Text { text: r, cdata });
        self.doc.set_span(n, span);
    }

    pub(super) fn commit_element(
        &mut self,
        content: &str,
        name_len: usize,
        spans: &[AttrSpan],
        span: Span,
        host: Option<Node>,
    ) -> Option<Node> {
        if spans.len() > self.limits.max_attributes as usize {
            return None;
        }
        let tag = self.name_sym(content.get(..name_len)?).ok()?;
        let (attrs_at, strings_at) = (self.doc.attrs.len(), self.doc.strings.len());
        // Few attributes are compared pairwise as they come; many are sorted once below, so
        // that a tag with thousands stays linear-logarithmic.
        let few = spans.len() <= 16;
        let undo = |doc: &mut Document| {
            doc.attrs.truncate(attrs_at);
            doc.strings.truncate(strings_at);
            None
        };
        for a in spans {
            let (Some(key), Some(raw)) = (
                content.get(a.key.0 as usize..a.key.1 as usize),
                content.get(a.value.0 as usize..a.value.1 as usize),
            ) else {
                return undo(&mut self.doc);
            };
            let Ok(name) = self.name_sym(key) else {
                return undo(&mut self.doc);
            };
            let doc = &mut self.doc;
            if few && doc.attrs[attrs_at..].iter().any(|a| a.name == name) {
                return undo(doc);
            }
            let value = if a.has_ref {
                match expand_refs(raw) {
                    Ok(v) => doc.push_str(&v),
                    Err(_) => return undo(doc),
                }
            } else {
                doc.push_str(raw)
            };
            doc.attrs.push(crate::document::tree::Attr { name, value });
        }
        if !few {
            let mut names: Vec<Sym> = self.doc.attrs[attrs_at..].iter().map(|a| a.name).collect();
            names.sort_unstable();
            if names.windows(2).any(|w| w[0] == w[1]) {
                return undo(&mut self.doc);
            }
        }
        let doc = &mut self.doc;
        let attrs = crate::document::tree::AttrRange {
            start: attrs_at as u32,
            len: (doc.attrs.len() - attrs_at) as u32,
        };
        let data = NodeData::Element { tag, attrs };
        let node = match host {
            Some(host) => doc.tree.append_new(host, data),
            None => doc.tree.new_node(data),
        };
        doc.set_span(node, span);
        Some(node)
    }

    /// The symbol of an element or attribute name read from the source; a name met for the
    /// first time must be one we can write back (see [`name_problem`]).
    #[inline]
    pub(super) fn name_sym(&mut self, name: &str) -> Result<Sym, String> {
        match self.doc.names.get(name) {
            Some(sym) => Ok(sym),
            None => self.new_name_sym(name),
        }
    }

    /// [`Builder::name_sym`] for a name not seen before (rare: most are vocabulary).
    #[cold]
    fn new_name_sym(&mut self, name: &str) -> Result<Sym, String> {
        // The first name read is the root's: a `<robot>` root makes the file URDF.
        if self.doc.tree.count() <= 1 && self.depth_base == 0 && name == "robot" {
            self.urdf = true;
        }
        match name_problem(name, &self.limits, self.urdf) {
            Some(why) => Err(why),
            None => Ok(self.doc.names.intern(name)),
        }
    }
}
