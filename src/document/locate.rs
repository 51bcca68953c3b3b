//! From MuJoCo's error about XML we wrote back to the user's sources: MuJoCo names the
//! offending element by its line in the XML it was given; that XML is this document as
//! its writers render it, so the line maps to the element, and the element to its place
//! in the files it was read from (`robot.xml:12:7: Error: mesh 'nope' not found in geom
//! 0`, then the include chain, as for load errors). The command line's `compile` and
//! `--validate`, the MuJoCo FFI's `compile_document` and the Python model caches (which
//! compile with the user's own `mujoco`) all go through [`Document::mujoco_error`].

use crate::document::Document;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind, Location};

impl Document {
    /// MuJoCo's `message` about `xml` (this document as [`Document::to_pretty_string`] or
    /// [`Document::to_xml_string`] wrote it) as an error at the element it names, in the
    /// user's sources: `file:line:col: message`. When the message names no line, or the
    /// line no element, the error names the main file alone (`file: message`).
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let doc = Document::from_str("<mujoco>\n<worldbody>\n\n<geom name='g' size='x'/>\n</worldbody>\n</mujoco>", ".")?;
    /// let xml = doc.to_pretty_string(); // the geom is on line 3 here, line 4 in the source
    /// let err = doc.mujoco_error(&xml, "XML Error: bad format\nElement 'geom', line 3");
    /// assert!(err.to_string().starts_with("<string>:4:1: XML Error: bad format"), "{err}");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn mujoco_error(&self, xml: &str, message: &str) -> Error {
        let message = message.trim_end();
        let located = error_line(message)
            .and_then(|line| element_at_line(self, xml, line, message))
            .and_then(|node| source_location(self, node));
        match located {
            Some(location) => Error {
                location: Some(location),
                kind: ErrorKind::Invalid(message.to_string()),
            },
            None => Error {
                location: None,
                kind: ErrorKind::Invalid(format!(
                    "{}: {message}",
                    self.location(self.root()).file.display()
                )),
            },
        }
    }
}

/// The line number in a MuJoCo error message: MuJoCo's `", line N"` (it ends the
/// `Element ...` line of its messages), else tinyxml2's `"Line number=N"`.
pub(crate) fn error_line(message: &str) -> Option<u32> {
    let element_line = message
        .lines()
        .rev()
        .filter(|line| line.trim_start().starts_with("Element"))
        .find_map(|line| number_after(line, ", line "));
    element_line
        .or_else(|| number_after(message, ", line "))
        .or_else(|| number_after(message, "Line number="))
}

/// The decimal number right after the last `marker` in `text` that has one.
fn number_after(text: &str, marker: &str) -> Option<u32> {
    text.rmatch_indices(marker).find_map(|(at, _)| {
        let rest = &text[at + marker.len()..];
        let end = rest
            .find(|c: char| !c.is_ascii_digit())
            .unwrap_or(rest.len());
        rest[..end].parse().ok()
    })
}

/// Where each element's start tag begins in `xml` as written by [`Document`]'s writers:
/// `(1-based line, byte offset of its '<')`, in document order, i.e. the order of
/// `doc.descendants(doc.root())`.
///
/// Exact for our writers' output, mixed content included (where several elements share a
/// line), because the writers escape `<` in attribute values and text; the only other
/// markup they emit is closing tags and CDATA sections, which are skipped whole. (Counting
/// lines that start with `<` would miscount inside mixed content and CDATA.)
fn element_starts(xml: &str) -> Vec<(u32, usize)> {
    let bytes = xml.as_bytes();
    let mut starts = Vec::new();
    let mut line = 1u32;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'\n' => line += 1,
            b'<' => {
                let rest = &xml[i..];
                let skip_to = |end: &str| rest.find(end).map_or(rest.len(), |at| at + end.len());
                let skipped = if rest.starts_with("<![CDATA[") {
                    skip_to("]]>")
                } else if rest.starts_with("<!--") {
                    skip_to("-->")
                } else if rest.starts_with("<?") {
                    skip_to("?>")
                } else if rest.starts_with("</") || rest.starts_with("<!") {
                    1
                } else {
                    starts.push((line, i));
                    1
                };
                line += rest[..skipped].bytes().filter(|&b| b == b'\n').count() as u32;
                i += skipped;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    starts
}

/// The element that MuJoCo's message points at: one whose start tag is on `line` of `xml`
/// (the document's own rendering). When several share the line (mixed content), the one
/// whose tag or name matches MuJoCo's `Element 'geom'` / `Element name 'g'` wins, else
/// the first; when none starts there, the last one that starts before it.
fn element_at_line(doc: &Document, xml: &str, line: u32, message: &str) -> Option<Node> {
    let starts = element_starts(xml);
    let elements: Vec<Node> = doc.descendants(doc.root()).collect();
    if starts.len() != elements.len() {
        // Not this document's rendering: better no position than a wrong one.
        return None;
    }
    let on_line: Vec<Node> = starts
        .iter()
        .zip(&elements)
        .filter(|((l, _), _)| *l == line)
        .map(|(_, &node)| node)
        .collect();
    let tag = quoted_after(message, "Element '");
    let name = quoted_after(message, "Element name '");
    let matching = on_line.iter().copied().find(|&node| {
        tag.is_some_and(|t| doc.tag(node) == t)
            || name.is_some_and(|n| doc.attr(node, "name") == Some(n))
    });
    matching.or_else(|| on_line.first().copied()).or_else(|| {
        starts
            .iter()
            .zip(&elements)
            .take_while(|((l, _), _)| *l < line)
            .last()
            .map(|(_, &node)| node)
    })
}

/// The text between `marker` and the next `'`.
fn quoted_after<'a>(text: &'a str, marker: &str) -> Option<&'a str> {
    let rest = &text[text.find(marker)? + marker.len()..];
    rest.find('\'').map(|end| &rest[..end])
}

/// The source position of `node`, or of its nearest ancestor that has one (elements made
/// while loading, such as a section created on demand, have none: line 0).
fn source_location(doc: &Document, node: Node) -> Option<Location> {
    std::iter::successors(Some(node), |&n| doc.parent(n))
        .map(|n| doc.location(n))
        .find(|location| location.line > 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn doc(xml: &str) -> Document {
        Document::from_str(xml, ".").unwrap()
    }

    #[test]
    fn element_starts_follow_document_order_through_mixed_content_and_cdata() {
        let d = doc("<mujoco><custom><text name='t' data='a&lt;b'/></custom>\
             <worldbody><body><geom size='1'/></body></worldbody></mujoco>");
        let xml = d.to_pretty_string();
        let lines: Vec<u32> = element_starts(&xml).iter().map(|s| s.0).collect();
        assert_eq!(lines, [1, 2, 3, 5, 6, 7], "{xml}");

        // Several elements on one line, and markup-like text inside CDATA.
        let mixed = "<a>x<b/>y<c/><![CDATA[\n<d>\n]]>\n<e/></a>";
        let starts = element_starts(mixed);
        let lines: Vec<u32> = starts.iter().map(|s| s.0).collect();
        assert_eq!(lines, [1, 1, 1, 4]);
        assert!(mixed[starts[3].1..].starts_with("<e/>"));
    }

    #[test]
    fn mujoco_line_maps_to_the_named_element() {
        let src = "<mujoco>\n<worldbody>\n\n\n<body name='b'>\n<geom name='g' size='1'/>\n</body>\n</worldbody>\n</mujoco>";
        let d = doc(src);
        let xml = d.to_pretty_string();
        // Pretty XML: mujoco 1, worldbody 2, body 3, geom 4.
        let geom =
            element_at_line(&d, &xml, 4, "Error: x\nElement name 'g', id 0, line 4").unwrap();
        assert_eq!(d.tag(geom), "geom");
        let loc = source_location(&d, geom).unwrap();
        assert_eq!((loc.line, loc.col), (6, 1));
        // A line past every start falls back to the last element before it.
        let last = element_at_line(&d, &xml, 99, "").unwrap();
        assert_eq!(d.tag(last), "geom");
    }

    #[test]
    fn quoted_names_in_mujoco_messages() {
        let m = "Error: bad\nElement name 'arm', id 3, line 9";
        assert_eq!(quoted_after(m, "Element name '"), Some("arm"));
        assert_eq!(quoted_after(m, "Element '"), None);
        assert_eq!(
            quoted_after("Element 'geom', line 2", "Element '"),
            Some("geom")
        );
    }

    /// The start-tag scan agrees with `descendants` on every wheel model: same count, and
    /// each start tag is that element's tag.
    #[test]
    fn element_starts_match_descendants_on_the_corpus() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let list = std::fs::read_to_string(root.join(".cache/corpus/models.txt"))
            .expect(".cache/corpus/models.txt: run scripts/setup.sh first");
        let mut checked = 0;
        for path in list.lines().filter(|l| !l.trim().is_empty()) {
            let d = Document::load(root.join(path)).unwrap_or_else(|e| panic!("{path}: {e}"));
            for xml in [d.to_pretty_string(), d.to_xml_string()] {
                let starts = element_starts(&xml);
                let elements: Vec<_> = d.descendants(d.root()).collect();
                assert_eq!(starts.len(), elements.len(), "{path}");
                for ((_, at), node) in starts.iter().zip(elements) {
                    let tag = d.tag(node);
                    let after = xml.as_bytes().get(at + 1 + tag.len()).copied();
                    assert!(
                        xml[at + 1..].starts_with(tag) && matches!(after, Some(b' ' | b'/' | b'>')),
                        "{path}: element <{tag}> is not at byte {at}"
                    );
                }
            }
            checked += 1;
        }
        assert!(checked >= 100, "only {checked} corpus models");
    }
}
