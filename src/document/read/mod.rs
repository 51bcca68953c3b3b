//! Reading: the markup goes straight into the arena; `<include>` is expanded on the way.
//!
//! Two readers build the same document. [`Builder::parse_fast`] reads the markup that
//! well-formed MJCF uses (elements, attributes, comments, processing instructions,
//! character data without references) in one pass over the bytes, finding exactly what
//! quick-xml finds there. Anything else, and every error, sends the whole load through
//! [`Builder::parse`] on quick-xml's events, which handles all of XML and words the errors
//! with their positions. `tests` below and the document judge hold the two to the same
//! output; the fast one is what makes loading several times quicker.

mod bytes;
mod checks;
mod fast;
mod include;
mod lines;
mod tags;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

use crate::document::limits::{Limits, read_regular_file};
use crate::document::names::{Names, Sym};
use crate::document::tree::{Node, NodeData, Tree};
use crate::document::{Document, SourceFile, Span};
use crate::error::{Error, ErrorKind, Errors, Location};
use bytes::{is_blank, is_xml_space};
use checks::{expand_refs, first_forbidden_char, is_utf16, name_problem};
use lines::Lines;
use tags::{AttrSpan, scan_attrs};

pub(crate) use checks::clip;

/// `part` (a slice quick-xml borrowed from the source) as a slice of `src`, the same source
/// already checked to be UTF-8; `None` if it does not lie in `src` on character boundaries.
fn sub_str<'s>(src: &'s str, part: &[u8]) -> Option<&'s str> {
    let start = (part.as_ptr() as usize).checked_sub(src.as_ptr() as usize)?;
    let s = src.get(start..start.checked_add(part.len())?)?;
    std::ptr::eq(s.as_ptr(), part.as_ptr()).then_some(s)
}

/// The offset of `part` in `whole`, when it is a slice of it.
fn offset_in(whole: &[u8], part: &[u8]) -> Option<usize> {
    let start = (part.as_ptr() as usize).checked_sub(whole.as_ptr() as usize)?;
    (start + part.len() <= whole.len()).then_some(start)
}

struct Builder {
    doc: Document,
    files: Vec<SourceFile>,
    /// Canonical paths of the files being read, outermost first (for cycles).
    chain: Vec<PathBuf>,
    /// The same files as the user would name them.
    chain_display: Vec<PathBuf>,
    /// The main file's folder as the user named it: included files are shown under it.
    display_dir: PathBuf,
    /// The main file's absolute path until its canonical path is needed: that takes a
    /// system call per path component, and only `<include>` needs it.
    main_to_canonicalize: Option<PathBuf>,
    /// Character data gathered across text and entity events (reused buffer).
    pending_text: String,
    /// Attribute spans of the tag being read (reused buffer).
    attr_spans: Vec<AttrSpan>,
    /// For `parse_fast`: the open elements' name ranges in their source (reused buffer).
    open_names: Vec<(u32, u32)>,
    /// Canonical paths of every file read so far (MuJoCo includes a file at most once),
    /// hashed: thousands of sibling includes stay linear.
    seen_set: ahash::AHashSet<PathBuf>,
    limits: Limits,
    /// The depth of the element the file being read inserts its elements under (0 for the
    /// main file, whose root element is level 1).
    depth_base: u32,
    /// How many includes deep the file being read is (0: the main file).
    include_depth: u32,
}

pub(crate) fn read_file(path: &Path, limits: &Limits) -> Result<Document, Errors> {
    let bytes = read_regular_file(path, limits.max_file_size).map_err(|reason| {
        Error::bare(ErrorKind::Io {
            path: path.to_path_buf(),
            reason,
        })
    })?;
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let dir = abs.parent().unwrap_or(Path::new(""));
    let display_dir = path.parent().unwrap_or(Path::new(""));
    read_bytes(
        &bytes,
        Arc::from(path),
        dir,
        display_dir,
        Main::File { abs: abs.clone() },
        limits,
    )
}

pub(crate) fn read_str(xml: &str, base_dir: &Path, limits: &Limits) -> Result<Document, Errors> {
    let name: Arc<Path> = Arc::from(Path::new("<string>"));
    if xml.len() as u64 > limits.max_file_size {
        return Err(Error::at(
            Location::new(name, 1, 1),
            ErrorKind::Invalid(format!(
                "text of {} bytes, more than the limit of {} (Limits::max_file_size)",
                xml.len(),
                limits.max_file_size
            )),
        )
        .into());
    }
    let dir = std::path::absolute(base_dir).unwrap_or_else(|_| base_dir.to_path_buf());
    read_bytes(xml.as_bytes(), name, &dir, base_dir, Main::Text, limits)
}

/// Reads `bytes` as the text `<string>` found in `dir`, through the fast reader first (as
/// every load does) with `fast`, through quick-xml's path alone without: the two must give
/// the same document or the same errors (the tests and the `readers` fuzz target).
pub(crate) fn read_bytes_as_text(
    bytes: &[u8],
    dir: &Path,
    limits: &Limits,
    fast: bool,
) -> Result<Document, Errors> {
    let name = Arc::from(Path::new("<string>"));
    read_bytes_with(bytes, name, dir, dir, Main::Text, limits, fast)
}

/// Where the main text came from: a file (which takes part in include cycles) or a string.
enum Main {
    File { abs: PathBuf },
    Text,
}

fn read_bytes(
    bytes: &[u8],
    name: Arc<Path>,
    dir: &Path,
    display_dir: &Path,
    main: Main,
    limits: &Limits,
) -> Result<Document, Errors> {
    read_bytes_with(bytes, name, dir, display_dir, main, limits, true)
}

fn read_bytes_with(
    bytes: &[u8],
    name: Arc<Path>,
    dir: &Path,
    display_dir: &Path,
    main: Main,
    limits: &Limits,
    try_fast: bool,
) -> Result<Document, Errors> {
    let model_dir: Arc<Path> = Arc::from(dir);
    // Models are read by `Builder::parse_fast` when it can; anything outside what it handles
    // (and every error) sends the whole load, includes and all, through quick-xml.
    if let Some(src) = std::str::from_utf8(bytes).ok().filter(|_| try_fast) {
        let mut b = Builder::new(bytes.len(), &name, &model_dir, display_dir, &main, limits);
        if b.parse_fast(src, 0, None).is_some() {
            return b.finish();
        }
    }
    let mut b = Builder::new(bytes.len(), &name, &model_dir, display_dir, &main, limits);
    b.parse(bytes, 0, None)?;
    b.finish()
}

impl Builder {
    fn new(
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
            depth_base: 0,
            include_depth: 0,
        }
    }

    fn finish(self) -> Result<Document, Errors> {
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

    fn loc(&self, file: u32, line: u32, col: u32) -> Location {
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

    /// Parses one file. `parent` is `None` for the main file (its root element becomes the
    /// document root) and the include's parent for an included file (whose own root element
    /// is dropped, its children inserted in the include's place). Returns how many elements
    /// were inserted under `parent`.
    fn parse(&mut self, bytes: &[u8], file: u32, parent: Option<Node>) -> Result<usize, Errors> {
        if is_utf16(bytes) {
            return Err(Error::at(
                self.loc(file, 1, 1),
                ErrorKind::Syntax(
                    "the file is UTF-16; MJCF is read as UTF-8 (convert it, e.g. with iconv)"
                        .into(),
                ),
            )
            .into());
        }
        if let Some((at, what)) = first_forbidden_char(bytes) {
            let (line, col) = Lines::new(bytes).line_col(at);
            return Err(Error::at(self.loc(file, line, col), ErrorKind::Syntax(what)).into());
        }
        let mut lines = Lines::new(bytes);
        // Checked once here, the text lets tags, attribute values and character data be
        // taken as slices below without checking each piece again; text that is not UTF-8
        // takes quick-xml's decoding path, which reports where.
        let src = std::str::from_utf8(bytes).ok();
        let mut reader = Reader::from_reader(bytes);
        reader.config_mut().check_end_names = true;
        // Open elements; `None` marks the dropped root of an included file, or an include.
        let mut stack: Vec<Option<Node>> = Vec::new();
        let mut inserted = 0usize;
        let mut seen_root = false;
        // Character data is gathered across text and entity events (in `pending_text`),
        // then kept only if it is more than white space.
        let mut pending: Option<(Node, Span)> = None;
        self.pending_text.clear();
        loop {
            let offset = reader.buffer_position() as usize;
            let event = reader.read_event().map_err(|e| {
                let (line, col) = lines.line_col(reader.error_position() as usize);
                Error::at(self.loc(file, line, col), ErrorKind::Syntax(e.to_string()))
            })?;
            if !matches!(event, Event::Text(_) | Event::GeneralRef(_))
                && let Some((host, at)) = pending.take()
            {
                let text = std::mem::take(&mut self.pending_text);
                if !is_blank(&text) {
                    self.text(host, &text, false, at);
                }
                self.pending_text = text;
                self.pending_text.clear();
            }
            let is_empty = matches!(event, Event::Empty(_));
            match event {
                Event::Start(e) | Event::Empty(e) => {
                    let (line, col) = lines.advance(offset);
                    let span = Span { file, line, col };
                    let depth = self.depth_base + stack.len() as u32 + u32::from(parent.is_none());
                    if depth > self.limits.max_depth {
                        return Err(Error::at(
                            self.loc(file, line, col),
                            ErrorKind::Invalid(format!(
                                "element nesting deeper than {} levels (Limits::max_depth)",
                                self.limits.max_depth
                            )),
                        )
                        .into());
                    }
                    let current = stack.last().copied();
                    let node = if stack.is_empty() {
                        if seen_root {
                            return Err(Error::at(
                                self.loc(file, line, col),
                                ErrorKind::Syntax("more than one root element".into()),
                            )
                            .into());
                        }
                        seen_root = true;
                        match parent {
                            None => {
                                let n = match src.and_then(|src| sub_str(src, &e)) {
                                    Some(content) => self.element_fast(content, span, None),
                                    None => None,
                                };
                                let n = match n {
                                    Some(n) => n,
                                    None => self.element(&e, span, &reader, &lines, offset)?,
                                };
                                if self.doc.tag(n) != "mujoco" {
                                    return Err(Error::at(
                                        self.loc(file, line, col),
                                        ErrorKind::NotMjcf(format!(
                                            "root element is <{}>, not <mujoco>",
                                            self.doc.tag(n)
                                        )),
                                    )
                                    .into());
                                }
                                self.doc.root = n;
                                Some(n)
                            }
                            Some(_) => None,
                        }
                    } else {
                        let host = match current {
                            Some(Some(n)) => Some(n),
                            Some(None) if stack.len() == 1 => parent,
                            _ => None,
                        };
                        match host {
                            None => None, // inside an <include>: ignored, as MuJoCo does
                            Some(host) if e.name().as_ref() == b"include" => {
                                if Some(host) == parent {
                                    inserted += 1;
                                }
                                // The include's attributes are read as any element's; the
                                // element itself is dropped.
                                let node = self.element(&e, span, &reader, &lines, offset)?;
                                self.expand_include(node, span, host, depth - 1, false)?;
                                None
                            }
                            Some(host) => {
                                let fast = match src.and_then(|src| sub_str(src, &e)) {
                                    Some(content) => self.element_fast(content, span, Some(host)),
                                    None => None,
                                };
                                let n = match fast {
                                    Some(n) => n,
                                    None => {
                                        let n = self.element(&e, span, &reader, &lines, offset)?;
                                        self.doc.tree.append(host, n);
                                        n
                                    }
                                };
                                if Some(host) == parent {
                                    inserted += 1;
                                }
                                Some(n)
                            }
                        }
                    };
                    if !is_empty {
                        stack.push(node);
                    } else if stack.is_empty() {
                        break;
                    }
                }
                Event::End(_) => {
                    stack.pop();
                    if stack.is_empty() {
                        break;
                    }
                }
                Event::Text(t) => {
                    if let Some(Some(host)) = stack.last() {
                        if pending.is_none() {
                            let (line, col) = lines.advance(offset);
                            pending = Some((*host, Span { file, line, col }));
                        }
                        match src.and_then(|src| sub_str(src, &t)) {
                            Some(raw) if !raw.contains('&') => self.pending_text.push_str(raw),
                            _ => {
                                let (line, col) = lines.line_col(offset);
                                let raw = t.decode().map_err(|e| {
                                    Error::at(
                                        self.loc(file, line, col),
                                        ErrorKind::Syntax(e.to_string()),
                                    )
                                })?;
                                let text = expand_refs(&raw).map_err(|(_, why)| {
                                    Error::at(self.loc(file, line, col), ErrorKind::Syntax(why))
                                })?;
                                self.pending_text.push_str(&text);
                            }
                        }
                    }
                }
                Event::GeneralRef(r) => {
                    if let Some(Some(host)) = stack.last() {
                        let (line, col) = lines.advance(offset);
                        let name = r.decode().unwrap_or_default();
                        let entity = format!("&{name};");
                        let text = expand_refs(&entity).map_err(|(_, why)| {
                            Error::at(self.loc(file, line, col), ErrorKind::Syntax(why))
                        })?;
                        pending.get_or_insert((*host, Span { file, line, col }));
                        self.pending_text.push_str(&text);
                    }
                }
                Event::CData(t) => {
                    if let Some(Some(host)) = stack.last() {
                        let (line, col) = lines.advance(offset);
                        let text = String::from_utf8_lossy(&t).into_owned();
                        self.text(*host, &text, true, Span { file, line, col });
                    }
                }
                Event::Eof => {
                    if !stack.is_empty() {
                        let (line, col) = lines.advance(offset);
                        return Err(Error::at(
                            self.loc(file, line, col),
                            ErrorKind::Syntax("unexpected end of file: unclosed element".into()),
                        )
                        .into());
                    }
                    break;
                }
                _ => {}
            }
        }
        if !seen_root {
            let (line, col) = lines.line_col(0);
            return Err(Error::at(
                self.loc(file, line, col),
                ErrorKind::Syntax("no root element".into()),
            )
            .into());
        }
        // What follows the root element is not read: MuJoCo (tinyxml2's root element) ignores
        // it as well.
        Ok(inserted)
    }

    fn text(&mut self, host: Node, text: &str, cdata: bool, span: Span) {
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

    /// Reads a start tag from the source text: the same element [`Builder::element`] makes,
    /// without quick-xml's per-attribute decoding and copying. `None` (with nothing added
    /// but interned names) where quick-xml would see an error, so that path words it.
    fn element_fast(&mut self, content: &str, span: Span, host: Option<Node>) -> Option<Node> {
        let bytes = content.as_bytes();
        let name_len = bytes
            .iter()
            .position(|&b| is_xml_space(b))
            .unwrap_or(bytes.len());
        let mut spans = std::mem::take(&mut self.attr_spans);
        let ok = scan_attrs(bytes, name_len, &mut spans);
        let node = if ok {
            self.commit_element(content, name_len, &spans, span, host)
        } else {
            None
        };
        self.attr_spans = spans;
        node
    }

    fn commit_element(
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

    fn element(
        &mut self,
        e: &BytesStart<'_>,
        span: Span,
        reader: &Reader<&[u8]>,
        lines: &Lines,
        offset: usize,
    ) -> Result<Node, Errors> {
        let syntax =
            |loc: Location, msg: String| Errors::from(Error::at(loc, ErrorKind::Syntax(msg)));
        let tag_bytes = e.name();
        let tag = std::str::from_utf8(tag_bytes.as_ref()).map_err(|err| {
            syntax(
                self.loc_in(span, lines, tag_bytes.as_ref(), 0),
                err.to_string(),
            )
        })?;
        let tag = self
            .name_sym(tag)
            .map_err(|why| syntax(self.loc_in(span, lines, tag_bytes.as_ref(), 0), why))?;
        let node = self.doc.tree.new_node(NodeData::Element {
            tag,
            attrs: crate::document::tree::AttrRange::default(),
        });
        self.doc.set_span(node, span);
        let start = self.doc.attrs.len() as u32;
        // quick-xml's own duplicate check compares each attribute with all before it; ours
        // below is a hash set (and words the error at the repeated attribute).
        let mut keys = ahash::AHashSet::new();
        let mut attributes = e.attributes();
        attributes.with_checks(false);
        for (count, attr) in attributes.enumerate() {
            let attr = attr.map_err(|err| {
                use quick_xml::events::attributes::AttrError;
                // quick-xml counts attribute offsets from the byte after '<'.
                let (at, msg) = match err {
                    AttrError::Duplicated(at, _) => {
                        (at, "attribute is already defined".to_string())
                    }
                    AttrError::ExpectedEq(at) => {
                        (at, "expected '=' after attribute name".to_string())
                    }
                    AttrError::ExpectedValue(at) => (at, "expected attribute value".to_string()),
                    AttrError::UnquotedValue(at) => {
                        (at, "attribute value must be quoted".to_string())
                    }
                    AttrError::ExpectedQuote(at, _) => {
                        (at, "unterminated attribute value".to_string())
                    }
                };
                let (line, col) = lines.line_col(offset + 1 + at);
                syntax(self.loc(span.file, line, col), msg)
            })?;
            let key_bytes = attr.key.as_ref();
            if count >= self.limits.max_attributes as usize {
                let msg = format!(
                    "more than {} attributes on one element (Limits::max_attributes)",
                    self.limits.max_attributes
                );
                return Err(Error::at(
                    self.loc_in(span, lines, key_bytes, 0),
                    ErrorKind::Invalid(msg),
                )
                .into());
            }
            let key = std::str::from_utf8(key_bytes)
                .map_err(|err| syntax(self.loc_in(span, lines, key_bytes, 0), err.to_string()))?;
            let name = self.name_sym(key).map_err(|why| {
                syntax(
                    self.loc_in(span, lines, key_bytes, 0),
                    format!("attribute name: {why}"),
                )
            })?;
            if !keys.insert(name) {
                return Err(syntax(
                    self.loc_in(span, lines, key_bytes, 0),
                    format!("attribute '{}' is already defined", clip(key, 40)),
                ));
            }
            let raw = &attr.value;
            let text = reader
                .decoder()
                .decode(raw)
                .map_err(|err| syntax(self.loc_in(span, lines, raw, 0), err.to_string()))?;
            let value = expand_refs(&text)
                .map_err(|(at, why)| syntax(self.loc_in(span, lines, raw, at), why))?;
            let value = self.doc.push_str(&value);
            self.doc
                .attrs
                .push(crate::document::tree::Attr { name, value });
        }
        let len = self.doc.attrs.len() as u32 - start;
        if let NodeData::Element { attrs, .. } = self.doc.tree.data_mut(node) {
            *attrs = crate::document::tree::AttrRange { start, len };
        }
        Ok(node)
    }

    /// Where `part` (plus `extra` bytes) is in the file, when it is a slice of the source;
    /// else the position of the tag it belongs to, `span`.
    fn loc_in(&self, span: Span, lines: &Lines, part: &[u8], extra: usize) -> Location {
        match offset_in(lines.text, part) {
            Some(at) => {
                let (line, col) = lines.line_col(at + extra);
                self.loc(span.file, line, col)
            }
            None => self.loc(span.file, span.line, span.col),
        }
    }

    /// The symbol of an element or attribute name read from the source; a name met for the
    /// first time must be one we can write back (see [`name_problem`]).
    #[inline]
    fn name_sym(&mut self, name: &str) -> Result<Sym, String> {
        match self.doc.names.get(name) {
            Some(sym) => Ok(sym),
            None => self.new_name_sym(name),
        }
    }

    /// [`Builder::name_sym`] for a name not seen before (rare: most are vocabulary).
    #[cold]
    fn new_name_sym(&mut self, name: &str) -> Result<Sym, String> {
        match name_problem(name, &self.limits) {
            Some(why) => Err(why),
            None => Ok(self.doc.names.intern(name)),
        }
    }
}
