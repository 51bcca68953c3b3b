//! Writing: deterministic bytes, attribute values as read (escaped only where XML needs it).

use std::io::Write as _;
use std::path::Path;

use crate::document::Document;
use crate::error::{Error, ErrorKind};
use crate::tree::{Node, NodeData};

fn escape_attr(out: &mut String, value: &str) {
    for c in value.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            // Parsers normalise raw white-space characters in attributes to spaces.
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            '\t' => out.push_str("&#9;"),
            c => out.push(c),
        }
    }
}

fn escape_text(out: &mut String, text: &str) {
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            c => out.push(c),
        }
    }
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
        let mut out = String::with_capacity(self.strings.len() + self.attrs.len() * 8);
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
        let mut out = String::with_capacity(self.strings.len() * 2 + self.attrs.len() * 8);
        self.write_node(&mut out, self.root, Some(0));
        out.push('\n');
        out
    }

    /// Writes the pretty form to `path` atomically: a temporary file in the same folder,
    /// renamed over the target, so a failure never leaves a partial or clobbered file.
    pub fn write_file(&self, path: impl AsRef<Path>) -> Result<(), Error> {
        write_atomic(path.as_ref(), self.to_pretty_string().as_bytes())
    }

    fn write_node(&self, out: &mut String, node: Node, indent: Option<usize>) {
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
                let tag = self.names.resolve(tag);
                out.push('<');
                out.push_str(tag);
                for a in self.attr_slice(node) {
                    out.push(' ');
                    out.push_str(self.names.resolve(a.name));
                    out.push_str("=\"");
                    escape_attr(out, self.str(a.value));
                    out.push('"');
                }
                let mut kids = self.tree.children(node).peekable();
                if kids.peek().is_none() {
                    out.push_str("/>");
                    return;
                }
                out.push('>');
                // Mixed content (text inside) is written inline to keep the text exact.
                let has_text = self.tree.children(node).any(|k| !self.is_element(k));
                let child_indent = if has_text { None } else { indent.map(|i| i + 1) };
                for kid in kids {
                    if let Some(i) = child_indent {
                        out.push('\n');
                        push_indent(out, i);
                    }
                    self.write_node(out, kid, child_indent);
                }
                if let (Some(i), Some(_)) = (indent, child_indent) {
                    out.push('\n');
                    push_indent(out, i);
                }
                out.push_str("</");
                out.push_str(tag);
                out.push('>');
            }
        }
    }
}

fn push_indent(out: &mut String, level: usize) {
    for _ in 0..level {
        out.push_str("  ");
    }
}

/// Writes bytes to `path` through a temporary file in the same folder and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let fail = |e: std::io::Error| {
        Error::bare(ErrorKind::Write { path: path.to_path_buf(), reason: e.to_string() })
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(fail)?;
    tmp.write_all(bytes).map_err(fail)?;
    tmp.as_file().sync_all().map_err(fail)?;
    tmp.persist(path).map_err(|e| fail(e.error))?;
    Ok(())
}
