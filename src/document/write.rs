//! Writing: deterministic bytes, attribute values as read (escaped only where XML needs it).

use std::path::Path;

use crate::document::Document;
use crate::document::tree::{Node, NodeData, StrRef};
use crate::error::Error;
use crate::output::write_atomic;

/// The bytes an attribute value cannot hold as they are: markup, the quote, and white
/// space other than the space (parsers normalise raw white-space characters to spaces).
const ATTR_SPECIAL: [bool; 256] = special(b"&<>\"\n\r\t");
/// The bytes character data cannot hold as they are.
const TEXT_SPECIAL: [bool; 256] = special(b"&<>");

const fn special(bytes: &[u8]) -> [bool; 256] {
    let mut table = [false; 256];
    let mut i = 0;
    while i < bytes.len() {
        table[bytes[i] as usize] = true;
        i += 1;
    }
    table
}

const LO: u64 = 0x0101_0101_0101_0101;

/// Marks the bytes of `x` below `n` (`n` at most 128); no mark means there is none.
fn bytes_below(x: u64, n: u8) -> u64 {
    x.wrapping_sub(LO * u64::from(n)) & !x & (LO << 7)
}

/// Marks the bytes of `x` equal to `b`; no mark means there is none.
fn bytes_equal(x: u64, b: u8) -> u64 {
    bytes_below(x ^ (LO * u64::from(b)), 1)
}

/// Whether eight bytes hold one of [`ATTR_SPECIAL`]. `"` and `&` differ only in bit 2,
/// `<` and `>` only in bit 1, so two compares cover those four; `\t`, `\n`, `\r` are
/// below 14 (the other bytes below 14 are rare enough to only cost the slow path).
fn attr_word_is_special(w: u64) -> bool {
    (bytes_equal(w | (LO * 0x04), b'&') | bytes_equal(w | (LO * 0x02), b'>') | bytes_below(w, 14))
        != 0
}

fn text_word_is_special(w: u64) -> bool {
    (bytes_equal(w, b'&') | bytes_equal(w | (LO * 0x02), b'>')) != 0
}

/// Appends `value` escaped for a double-quoted attribute.
pub(crate) fn escape_attr(out: &mut String, value: &str) {
    if is_clean(value.as_bytes(), &ATTR_SPECIAL, attr_word_is_special) {
        out.push_str(value);
    } else {
        escape_with(out, value, &ATTR_SPECIAL);
    }
}

/// [`escape_attr`] for the value `r` of the string buffer `strings`. A value shorter than
/// a word (most are) is checked as one word read from the buffer, the bytes past its end
/// replaced by a harmless one.
fn escape_attr_in(out: &mut String, strings: &str, r: StrRef) {
    let (start, len) = (r.start as usize, r.len as usize);
    let value = &strings[start..start + len];
    let clean = match strings.as_bytes().get(start..start + 8) {
        Some(w) if len < 8 => {
            let w = u64::from_le_bytes(w.try_into().expect("8 bytes"));
            let keep = (1u64 << (8 * len)) - 1;
            !attr_word_is_special((w & keep) | ((LO * u64::from(b'a')) & !keep))
        }
        _ => is_clean(value.as_bytes(), &ATTR_SPECIAL, attr_word_is_special),
    };
    if clean {
        out.push_str(value);
    } else {
        escape_with(out, value, &ATTR_SPECIAL);
    }
}

fn escape_text(out: &mut String, text: &str) {
    if is_clean(text.as_bytes(), &TEXT_SPECIAL, text_word_is_special) {
        out.push_str(text);
    } else {
        escape_with(out, text, &TEXT_SPECIAL);
    }
}

/// Whether no byte of `bytes` needs escaping: eight bytes at a time (the last word may
/// overlap the one before), bytewise below eight bytes.
fn is_clean(bytes: &[u8], special: &[bool; 256], word_is_special: fn(u64) -> bool) -> bool {
    let word = |b: &[u8]| u64::from_le_bytes(b.try_into().expect("8 bytes"));
    if bytes.len() < 8 {
        return !bytes.iter().any(|&b| special[b as usize]);
    }
    let mut words = bytes.chunks_exact(8);
    if words.any(|w| word_is_special(word(w))) {
        return false;
    }
    words.remainder().is_empty() || !word_is_special(word(&bytes[bytes.len() - 8..]))
}

/// Copies `text` to `out` with the bytes marked in `special` escaped. They are all ASCII,
/// so the runs between them (usually the whole text) are copied whole, and cutting there
/// always lands on a character boundary.
fn escape_with(out: &mut String, text: &str, special: &[bool; 256]) {
    let mut done = 0;
    for (i, b) in text.bytes().enumerate() {
        if special[b as usize] {
            out.push_str(&text[done..i]);
            out.push_str(match b {
                b'&' => "&amp;",
                b'<' => "&lt;",
                b'>' => "&gt;",
                b'"' => "&quot;",
                b'\n' => "&#10;",
                b'\r' => "&#13;",
                _ => "&#9;",
            });
            done = i + 1;
        }
    }
    out.push_str(&text[done..]);
}

impl Document {
    /// The document as compact XML (no white space between elements).
    ///
    /// ```
    /// let doc = mjcf_forge::Document::from_str("<mujoco>\n  <worldbody/>\n</mujoco>", ".")?;
    /// assert_eq!(doc.to_xml_string(), "<mujoco><worldbody/></mujoco>");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn to_xml_string(&self) -> String {
        // Enough for every model of the wheel corpora (about three quarters used on average):
        // growing the buffer would copy it.
        let mut out = String::with_capacity(
            self.strings.len() + self.attrs.len() * 12 + self.tree.count() * 16,
        );
        self.write_node(&mut out, self.root, None);
        out
    }

    /// The document as indented XML (two spaces a level), ending in a newline.
    ///
    /// ```
    /// let doc = mjcf_forge::Document::from_str("<mujoco><worldbody/></mujoco>", ".")?;
    /// assert_eq!(doc.to_pretty_string(), "<mujoco>\n  <worldbody/>\n</mujoco>\n");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn to_pretty_string(&self) -> String {
        let mut out = String::with_capacity(
            self.strings.len() + self.attrs.len() * 12 + self.tree.count() * 48,
        );
        self.write_node(&mut out, self.root, Some(0));
        out.push('\n');
        out
    }

    /// Writes the pretty form to `path` as [`crate::write_atomic`] does: a regular file is
    /// replaced atomically, so a failure never leaves a partial or clobbered file.
    pub fn write_file(&self, path: impl AsRef<Path>) -> Result<(), Error> {
        write_atomic(path.as_ref(), self.to_pretty_string().as_bytes())
    }

    /// Writes `root` and everything below it. An explicit stack of steps, not recursion:
    /// documents nest as deep as [`crate::Limits::max_depth`] allows (and deeper once
    /// merged), and writing may run on a worker thread with a small stack.
    pub(crate) fn write_node(&self, out: &mut String, root: Node, indent: Option<usize>) {
        enum Step {
            /// Write a node at this indent; `newline` first when its siblings are indented.
            Enter {
                node: Node,
                indent: Option<usize>,
                newline: bool,
            },
            /// Close an element whose children are written; `lined`: they were indented.
            Leave {
                tag: crate::document::names::Sym,
                indent: Option<usize>,
                lined: bool,
            },
        }
        let mut stack = vec![Step::Enter {
            node: root,
            indent,
            newline: false,
        }];
        while let Some(step) = stack.pop() {
            let (node, indent) = match step {
                Step::Leave { tag, indent, lined } => {
                    if let (Some(i), true) = (indent, lined) {
                        out.push('\n');
                        push_indent(out, i);
                    }
                    match self.names.markup(tag) {
                        Some(m) => out.push_str(m.close),
                        None => {
                            out.push_str("</");
                            out.push_str(self.names.resolve(tag));
                            out.push('>');
                        }
                    }
                    continue;
                }
                Step::Enter {
                    node,
                    indent,
                    newline,
                } => {
                    if let (Some(i), true) = (indent, newline) {
                        out.push('\n');
                        push_indent(out, i);
                    }
                    (node, indent)
                }
            };
            match *self.tree.data(node) {
                NodeData::Text { text, cdata } => {
                    let text = self.str(text);
                    if cdata {
                        out.push_str("<![CDATA[");
                        out.push_str(&text.replace("]]>", "]]]]><![CDATA[>"));
                        out.push_str("]]>");
                    } else {
                        escape_text(out, text);
                    }
                }
                NodeData::Element { tag, .. } => {
                    // Vocabulary names come pre-rendered (` name="`, `<tag`, `</tag>`).
                    match self.names.markup(tag) {
                        Some(m) => out.push_str(m.open),
                        None => {
                            out.push('<');
                            out.push_str(self.names.resolve(tag));
                        }
                    }
                    for a in self.attr_slice(node) {
                        match self.names.markup(a.name) {
                            Some(m) => out.push_str(m.attr),
                            None => {
                                out.push(' ');
                                out.push_str(self.names.resolve(a.name));
                                out.push_str("=\"");
                            }
                        }
                        escape_attr_in(out, &self.strings, a.value);
                        out.push('"');
                    }
                    if self.tree.first_child(node).is_none() {
                        out.push_str("/>");
                        continue;
                    }
                    out.push('>');
                    // Mixed content (text inside) is written inline to keep the text exact.
                    let child_indent = indent
                        .filter(|_| self.tree.children(node).all(|k| self.is_element(k)))
                        .map(|i| i + 1);
                    stack.push(Step::Leave {
                        tag,
                        indent,
                        lined: child_indent.is_some(),
                    });
                    let at = stack.len();
                    stack.extend(self.tree.children(node).map(|kid| Step::Enter {
                        node: kid,
                        indent: child_indent,
                        newline: child_indent.is_some(),
                    }));
                    // Taken from the end: first child first.
                    stack[at..].reverse();
                }
            }
        }
    }
}

fn push_indent(out: &mut String, level: usize) {
    for _ in 0..level {
        out.push_str("  ");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_like_a_byte_loop() {
        let naive = |s: &str, attr: bool| {
            let mut out = String::new();
            for c in s.chars() {
                match c {
                    '&' => out.push_str("&amp;"),
                    '<' => out.push_str("&lt;"),
                    '>' => out.push_str("&gt;"),
                    '"' if attr => out.push_str("&quot;"),
                    '\n' if attr => out.push_str("&#10;"),
                    '\r' if attr => out.push_str("&#13;"),
                    '\t' if attr => out.push_str("&#9;"),
                    c => out.push(c),
                }
            }
            out
        };
        let mut samples: Vec<String> = [
            "",
            "a",
            "0 0 1",
            "1234567",
            "12345678",
            "123456789",
            "\u{e9}t\u{e9}",
            "\u{1F600}x",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        for special in ["&", "<", ">", "\"", "\n", "\r", "\t", "\u{b}", "\u{0}", "'"] {
            for len in 0..20 {
                for at in 0..=len {
                    let mut s: String = "0123456789abcdefghij"[..len].to_string();
                    s.insert_str(at, special);
                    samples.push(s);
                }
            }
        }
        for s in &samples {
            let (mut a, mut t) = (String::new(), String::new());
            escape_attr(&mut a, s);
            escape_text(&mut t, s);
            assert_eq!(a, naive(s, true), "{s:?}");
            assert_eq!(t, naive(s, false), "{s:?}");
            // In a buffer, with bytes after it that must not count.
            for tail in ["", "x", "&&&&&&&&", "\"\n<>", "01234567"] {
                let buf = format!("ab{s}{tail}");
                let mut b = String::new();
                escape_attr_in(
                    &mut b,
                    &buf,
                    StrRef {
                        start: 2,
                        len: s.len() as u32,
                    },
                );
                assert_eq!(b, naive(s, true), "{s:?} then {tail:?}");
            }
        }
    }
}
