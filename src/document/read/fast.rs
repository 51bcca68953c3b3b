//! The fast reader: one pass over the bytes for the markup well-formed MJCF uses, building
//! the nodes quick-xml's events would build; anything else hands the load back.

use super::builder::Builder;
use super::bytes::{find_any, is_blank, is_xml_space};
use super::checks::first_forbidden_char;
use super::lines::LineCursor;
use super::tags::{StartTag, scan_start_tag};
use crate::document::Span;
use crate::document::tree::Node;

impl Builder {
    /// Reads one file like [`Builder::parse`] does, for the markup well-formed MJCF uses:
    /// elements, attributes without errors, character data without references, comments,
    /// processing instructions. It finds what quick-xml finds (tag ends outside quotes,
    /// comment and instruction ends, attribute rules) and builds the same nodes, without
    /// events in between. `None` as soon as anything else (a CDATA section, an entity, a
    /// mismatched end tag, any error) comes up: the caller starts the load over through
    /// [`Builder::parse`], which handles everything and words the errors.
    pub(super) fn parse_fast(
        &mut self,
        src: &str,
        file: u32,
        parent: Option<Node>,
    ) -> Option<usize> {
        let bytes = src.as_bytes();
        if first_forbidden_char(bytes).is_some() {
            return None; // `parse` reports it
        }
        if bytes.starts_with(b"\xEF\xBB\xBF") {
            return None; // a byte order mark: quick-xml skips it
        }
        // Lines are counted as the markup is read: each byte is looked at once.
        let mut at = LineCursor { line: 1, start: 0 };
        // As in `parse`, with each open element's name (for its end tag) alongside.
        let mut stack: Vec<Option<Node>> = Vec::with_capacity(32);
        let mut names = std::mem::take(&mut self.open_names);
        names.clear();
        let mut inserted = 0usize;
        let mut pos = 0;
        let done = loop {
            let lt = pos + find_any(&bytes[pos..], [b'<', b'&'])?;
            if bytes[lt] == b'&' {
                break None; // a reference: quick-xml's events
            }
            // Without references, character data is one run per gap between markup: kept
            // (where `parse` would keep it) unless it is only white space.
            if lt > pos {
                if let Some(Some(host)) = stack.last() {
                    let text = src.get(pos..lt)?;
                    if !is_blank(text) {
                        self.text(*host, text, false, at.span(file, pos));
                    }
                }
                at.pass(bytes, pos, lt);
            }
            match *bytes.get(lt + 1)? {
                b'!' => {
                    // Only comments. quick-xml ends one at the first `>` after `--` that is
                    // at least five bytes past the `!` (`<!---->` is the shortest).
                    if !bytes[lt + 1..].starts_with(b"!--") {
                        break None;
                    }
                    let mut gt = lt + 6;
                    loop {
                        gt += find_any(bytes.get(gt..)?, [b'>'])?;
                        if bytes[gt - 2..gt] == *b"--" {
                            break;
                        }
                        gt += 1;
                    }
                    at.pass(bytes, lt, gt);
                    pos = gt + 1;
                }
                b'?' => {
                    // Ends at the first `?>` after `<`; `<?>` is quick-xml's error.
                    let mut gt = lt + 2;
                    loop {
                        gt += find_any(&bytes[gt..], [b'>'])?;
                        if bytes[gt - 1] == b'?' {
                            break;
                        }
                        gt += 1;
                    }
                    if gt - (lt + 1) <= 1 {
                        break None;
                    }
                    at.pass(bytes, lt, gt);
                    pos = gt + 1;
                }
                b'/' => {
                    let gt = lt + 2 + find_any(&bytes[lt + 2..], [b'>', b'"', b'\''])?;
                    if bytes[gt] != b'>' {
                        break None; // quick-xml reads quotes in end tags
                    }
                    let end = &bytes[lt + 2..gt];
                    // quick-xml trims white space after the name (all of it stays if that is all).
                    let end = &end[..end
                        .iter()
                        .rposition(|&b| !is_xml_space(b))
                        .map_or(end.len(), |i| i + 1)];
                    let (start, len) = names.pop()?;
                    if end != &bytes[start as usize..(start + len) as usize] {
                        break None;
                    }
                    stack.pop();
                    if stack.is_empty() {
                        break Some(inserted);
                    }
                    at.pass(bytes, lt, gt);
                    pos = gt + 1;
                }
                _ => {
                    let span = at.span(file, lt);
                    let mut spans = std::mem::take(&mut self.attr_spans);
                    let max = self.limits.max_attributes as usize;
                    let tag = scan_start_tag(bytes, lt + 1, &mut spans, &mut at, max);
                    self.attr_spans = spans;
                    let StartTag {
                        gt,
                        content_end,
                        name_len,
                        is_empty,
                    } = tag?;
                    let content = src.get(lt + 1..content_end)?;
                    let depth = self.depth_base + stack.len() as u32 + u32::from(parent.is_none());
                    if depth > self.limits.max_depth {
                        break None;
                    }
                    let current = stack.last().copied();
                    let node = if stack.is_empty() {
                        match parent {
                            None => {
                                let n = self.commit_scanned(content, name_len, span, None)?;
                                if !matches!(self.doc.tag(n), "mujoco" | "robot") {
                                    break None;
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
                            Some(host) if &content[..name_len] == "include" => {
                                if Some(host) == parent {
                                    inserted += 1;
                                }
                                let node = self.commit_scanned(content, name_len, span, None)?;
                                if !matches!(
                                    self.expand_include(node, span, host, depth - 1, true),
                                    Ok(true)
                                ) {
                                    break None;
                                }
                                None
                            }
                            Some(host) => {
                                let n = self.commit_scanned(content, name_len, span, Some(host))?;
                                if Some(host) == parent {
                                    inserted += 1;
                                }
                                Some(n)
                            }
                        }
                    };
                    if !is_empty {
                        stack.push(node);
                        names.push(((lt + 1) as u32, name_len as u32));
                    } else if stack.is_empty() {
                        break Some(inserted);
                    }
                    pos = gt + 1;
                }
            }
        };
        self.open_names = names;
        done
    }

    /// [`Builder::commit_element`] with the spans [`scan_start_tag`] left in `attr_spans`.
    fn commit_scanned(
        &mut self,
        content: &str,
        name_len: usize,
        span: Span,
        host: Option<Node>,
    ) -> Option<Node> {
        let spans = std::mem::take(&mut self.attr_spans);
        let node = self.commit_element(content, name_len, &spans, span, host);
        self.attr_spans = spans;
        node
    }
}
