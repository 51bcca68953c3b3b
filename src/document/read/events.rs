//! The full reader: quick-xml's events into the arena. It reads all of XML and words every
//! error with its position; the fast reader hands it whatever it does not read itself.

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

use super::builder::Builder;
use super::bytes::{is_blank, is_xml_space};
use super::checks::{clip, expand_refs, first_forbidden_char, is_utf16};
use super::lines::Lines;
use super::tags::scan_attrs;
use crate::document::Span;
use crate::document::tree::{Node, NodeData};
use crate::error::{Error, ErrorKind, Errors, Location};

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

impl Builder {
    /// Parses one file. `parent` is `None` for the main file (its root element becomes the
    /// document root) and the include's parent for an included file (whose own root element
    /// is dropped, its children inserted in the include's place). Returns how many elements
    /// were inserted under `parent`.
    pub(super) fn parse(
        &mut self,
        bytes: &[u8],
        file: u32,
        parent: Option<Node>,
    ) -> Result<usize, Errors> {
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
                                if !matches!(self.doc.tag(n), "mujoco" | "robot") {
                                    return Err(Error::at(
                                        self.loc(file, line, col),
                                        ErrorKind::NotMjcf(format!(
                                            "root element is <{}>, not <mujoco> (MJCF) or <robot> (URDF)",
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
}
