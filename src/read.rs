//! Reading: quick-xml events go straight into the arena; `<include>` is expanded on the way.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

use crate::document::{Document, SourceFile, Span};
use crate::error::{Error, ErrorKind, Errors, Location};
use crate::names::Names;
use crate::tree::{Node, NodeData, Tree};

/// Line starts of a source text, to turn byte offsets into line:col.
struct Lines(Vec<usize>);

impl Lines {
    fn new(text: &[u8]) -> Lines {
        let mut starts = vec![0];
        starts.extend(text.iter().enumerate().filter(|(_, b)| **b == b'\n').map(|(i, _)| i + 1));
        Lines(starts)
    }

    fn line_col(&self, offset: usize) -> (u32, u32) {
        let line = self.0.partition_point(|&s| s <= offset);
        let col = offset - self.0[line - 1] + 1;
        (line as u32, col as u32)
    }
}

struct Builder {
    doc: Document,
    files: Vec<SourceFile>,
    /// Canonical paths of the files being read, outermost first (for cycles).
    chain: Vec<PathBuf>,
    /// The same files as the user would name them.
    chain_display: Vec<PathBuf>,
    /// Canonical paths of every file read so far (MuJoCo includes a file at most once).
    seen: Vec<PathBuf>,
    /// The main file's folder as the user named it: included files are shown under it.
    display_dir: PathBuf,
}

pub(crate) fn read_file(path: &Path) -> Result<Document, Errors> {
    let bytes = std::fs::read(path).map_err(|e| {
        Error::bare(ErrorKind::Io { path: path.to_path_buf(), reason: e.to_string() })
    })?;
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let dir = abs.parent().map(Path::to_path_buf).unwrap_or_default();
    let canonical = std::fs::canonicalize(path).unwrap_or(abs);
    let display_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    read_bytes(&bytes, Arc::from(path), &dir, &display_dir, Some(canonical))
}

pub(crate) fn read_str(xml: &str, base_dir: &Path) -> Result<Document, Errors> {
    let dir = std::path::absolute(base_dir).unwrap_or_else(|_| base_dir.to_path_buf());
    read_bytes(xml.as_bytes(), Arc::from(Path::new("<string>")), &dir, base_dir, None)
}

fn read_bytes(
    bytes: &[u8],
    name: Arc<Path>,
    dir: &Path,
    display_dir: &Path,
    canonical: Option<PathBuf>,
) -> Result<Document, Errors> {
    let mut tree = Tree::with_capacity(bytes.len() / 40 + 16);
    let placeholder = tree.new_node(NodeData::Text {
        text: crate::tree::StrRef { start: 0, len: 0 },
        cdata: false,
    });
    let mut b = Builder {
        doc: Document {
            tree,
            root: placeholder,
            attrs: Vec::with_capacity(bytes.len() / 20),
            strings: String::with_capacity(bytes.len() / 2),
            spans: Vec::with_capacity(bytes.len() / 40 + 16),
            files: Arc::new(Vec::new()),
            names: Names::default(),
            model_dir: Arc::from(dir),
        },
        files: vec![SourceFile { path: name.clone(), included_at: None }],
        chain: canonical.iter().cloned().collect(),
        chain_display: vec![name.to_path_buf()],
        seen: canonical.into_iter().collect(),
        display_dir: display_dir.to_path_buf(),
    };
    b.doc.spans.push(Span::default());
    b.parse(bytes, 0, None)?;
    let mut doc = b.doc;
    doc.files = Arc::new(b.files);
    if doc.root == placeholder {
        return Err(Error::at(
            Location::new(doc.files[0].path.clone(), 1, 1),
            ErrorKind::NotMjcf("no root element".into()),
        )
        .into());
    }
    Ok(doc)
}

impl Builder {
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
        let lines = Lines::new(bytes);
        let mut reader = Reader::from_reader(bytes);
        reader.config_mut().check_end_names = true;
        // Open elements; `None` marks the dropped root of an included file, or an include.
        let mut stack: Vec<Option<Node>> = Vec::new();
        let mut inserted = 0usize;
        let mut seen_root = false;
        // Character data is gathered across text and entity events, then kept only if it
        // is more than white space.
        let mut pending: Option<(Node, String, Span)> = None;
        loop {
            let offset = reader.buffer_position() as usize;
            let event = reader.read_event().map_err(|e| {
                let (line, col) = lines.line_col(reader.error_position() as usize);
                Error::at(self.loc(file, line, col), ErrorKind::Syntax(e.to_string()))
            })?;
            let (line, col) = lines.line_col(offset);
            let span = Span { file, line, col };
            if !matches!(event, Event::Text(_) | Event::GeneralRef(_)) {
                if let Some((host, text, at)) = pending.take() {
                    if !text.trim().is_empty() {
                        self.text(host, &text, false, at);
                    }
                }
            }
            let is_empty = matches!(event, Event::Empty(_));
            match event {
                Event::Start(e) | Event::Empty(e) => {
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
                                let n = self.element(&e, span, &reader, &lines, offset)?;
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
                                self.include(&e, span, host, &reader, &lines, offset)?;
                                None
                            }
                            Some(host) => {
                                let n = self.element(&e, span, &reader, &lines, offset)?;
                                self.doc.tree.append(host, n);
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
                        let raw = t.decode().map_err(|e| {
                            Error::at(self.loc(file, line, col), ErrorKind::Syntax(e.to_string()))
                        })?;
                        let text = quick_xml::escape::unescape(&raw).map_err(|e| {
                            Error::at(self.loc(file, line, col), ErrorKind::Syntax(e.to_string()))
                        })?;
                        pending.get_or_insert_with(|| (*host, String::new(), span)).1.push_str(&text);
                    }
                }
                Event::GeneralRef(r) => {
                    if let Some(Some(host)) = stack.last() {
                        let name = r.decode().unwrap_or_default();
                        let entity = format!("&{name};");
                        let text = quick_xml::escape::unescape(&entity).map_err(|e| {
                            Error::at(self.loc(file, line, col), ErrorKind::Syntax(e.to_string()))
                        })?;
                        pending.get_or_insert_with(|| (*host, String::new(), span)).1.push_str(&text);
                    }
                }
                Event::CData(t) => {
                    if let Some(Some(host)) = stack.last() {
                        let text = String::from_utf8_lossy(&t).into_owned();
                        self.text(*host, &text, true, span);
                    }
                }
                Event::Eof => {
                    if !stack.is_empty() {
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
        Ok(inserted)
    }

    fn text(&mut self, host: Node, text: &str, cdata: bool, span: Span) {
        // Adjacent runs (text split by entity references) are joined into one node.
        if !cdata {
            let last = self.doc.tree.children(host).last();
            if let Some(last) = last {
                if let NodeData::Text { text: r, cdata: false } = *self.doc.tree.data(last) {
                    if (r.start + r.len) as usize == self.doc.strings.len() {
                        self.doc.strings.push_str(text);
                        if let NodeData::Text { text: r, .. } = self.doc.tree.data_mut(last) {
                            r.len += text.len() as u32;
                        }
                        return;
                    }
                }
            }
        }
        let r = self.doc.push_str(text);
        let n = self.doc.tree.new_node(NodeData::Text { text: r, cdata });
        self.doc.set_span(n, span);
        self.doc.tree.append(host, n);
    }

    fn element(
        &mut self,
        e: &BytesStart<'_>,
        span: Span,
        reader: &Reader<&[u8]>,
        lines: &Lines,
        offset: usize,
    ) -> Result<Node, Errors> {
        let tag_bytes = e.name();
        let tag = std::str::from_utf8(tag_bytes.as_ref()).map_err(|err| {
            Error::at(self.loc(span.file, span.line, span.col), ErrorKind::Syntax(err.to_string()))
        })?;
        let tag = self.doc.names.intern(tag);
        let node = self.doc.tree.new_node(NodeData::Element {
            tag,
            attrs: crate::tree::AttrRange::default(),
        });
        self.doc.set_span(node, span);
        let start = self.doc.attrs.len() as u32;
        for attr in e.attributes() {
            let attr = attr.map_err(|err| {
                use quick_xml::events::attributes::AttrError;
                // quick-xml counts attribute offsets from the byte after '<'.
                let (at, msg) = match err {
                    AttrError::Duplicated(at, _) => (at, "attribute is already defined".to_string()),
                    AttrError::ExpectedEq(at) => (at, "expected '=' after attribute name".to_string()),
                    AttrError::ExpectedValue(at) => (at, "expected attribute value".to_string()),
                    AttrError::UnquotedValue(at) => (at, "attribute value must be quoted".to_string()),
                    AttrError::ExpectedQuote(at, _) => (at, "unterminated attribute value".to_string()),
                };
                let (line, col) = lines.line_col(offset + 1 + at);
                Error::at(self.loc(span.file, line, col), ErrorKind::Syntax(msg))
            })?;
            let key = std::str::from_utf8(attr.key.as_ref()).map_err(|err| {
                Error::at(self.loc(span.file, span.line, span.col), ErrorKind::Syntax(err.to_string()))
            })?;
            let value = attr.decode_and_unescape_value(reader.decoder()).map_err(|err| {
                Error::at(self.loc(span.file, span.line, span.col), ErrorKind::Syntax(err.to_string()))
            })?;
            let name = self.doc.names.intern(key);
            let value = self.doc.push_str(&value);
            self.doc.attrs.push(crate::tree::Attr { name, value });
        }
        let len = self.doc.attrs.len() as u32 - start;
        if let NodeData::Element { attrs, .. } = self.doc.tree.data_mut(node) {
            *attrs = crate::tree::AttrRange { start, len };
        }
        Ok(node)
    }

    fn include(
        &mut self,
        e: &BytesStart<'_>,
        span: Span,
        host: Node,
        reader: &Reader<&[u8]>,
        lines: &Lines,
        offset: usize,
    ) -> Result<(), Errors> {
        let here = self.loc(span.file, span.line, span.col);
        // Read the include's attributes through the common path, then drop the element.
        let node = self.element(e, span, reader, lines, offset)?;
        let Some(file) = self.doc.attr(node, "file").map(str::to_owned) else {
            return Err(Error::at(here, ErrorKind::IncludeWithoutFile).into());
        };
        // MuJoCo resolves every include against the main file's folder, not the including one.
        let full = self.doc.model_dir.join(&file);
        let path = self.display_dir.join(&file);
        let canonical = std::fs::canonicalize(&full).map_err(|err| {
            Error::at(here.clone(), ErrorKind::Io { path: path.clone(), reason: err.to_string() })
        })?;
        if let Some(i) = self.chain.iter().position(|p| *p == canonical) {
            let mut chain = self.chain_display[i..].to_vec();
            chain.push(path);
            return Err(Error::at(here, ErrorKind::IncludeCycle { chain }).into());
        }
        if self.seen.contains(&canonical) {
            return Err(Error::at(here, ErrorKind::IncludedTwice(path)).into());
        }
        let bytes = std::fs::read(&full).map_err(|err| {
            Error::at(here.clone(), ErrorKind::Io { path: path.clone(), reason: err.to_string() })
        })?;
        let index = self.files.len() as u32;
        self.files.push(SourceFile { path: Arc::from(path.as_path()), included_at: Some(span) });
        self.chain.push(canonical.clone());
        self.chain_display.push(path.clone());
        self.seen.push(canonical);
        let inserted = self.parse(&bytes, index, Some(host))?;
        self.chain.pop();
        self.chain_display.pop();
        if inserted == 0 {
            return Err(Error::at(here, ErrorKind::EmptyInclude(path)).into());
        }
        Ok(())
    }
}
