//! An element written as `xml.etree.ElementTree.tostring(element, encoding="unicode")`
//! writes it, for `mjcf_forge.etree.tostring` (robosuite writes every task's XML that way
//! at each hard reset, through `edit_model_xml`).
//!
//! The same text as xml.etree's serializer walking the element: `<tag`, each attribute as
//! ` name="value"` in order, then ` />` for an element with neither text nor children, or
//! `>`, the text, the children, `</tag>`; the element's own tail after it. Character data
//! escapes `&`, `<` and `>`; attribute values also `"`, CR, LF and tab (as
//! `&#13;`, `&#10;`, `&#09;`). `mjcf_forge.etree` checks these rules against the running
//! Python's own serializer once and uses it instead where they differ.

use mjcf_forge::{Document, Node};

/// `node` and its subtree as xml.etree writes them, or `None` where xml.etree would
/// treat a name as namespaced (`{uri}local`), which this writer does not do.
pub(crate) fn etree_xml(d: &Document, node: Node) -> Option<String> {
    let mut out = String::new();
    // Explicit stack (documents can nest thousands deep): an element to open, or one
    // to close (its end tag, then its tail).
    enum Step {
        Open(Node),
        Close(Node),
    }
    let mut stack = vec![Step::Open(node)];
    while let Some(step) = stack.pop() {
        match step {
            Step::Open(n) => {
                let tag = d.tag(n);
                if tag.contains('{') {
                    return None;
                }
                out.push('<');
                out.push_str(tag);
                for (k, v) in d.attrs(n) {
                    if k.contains('{') {
                        return None;
                    }
                    out.push(' ');
                    out.push_str(k);
                    out.push_str("=\"");
                    escape(&mut out, v, true);
                    out.push('"');
                }
                let text = d.element_text(n).filter(|t| !t.is_empty());
                let mut children = d.elements(n).peekable();
                if text.is_none() && children.peek().is_none() {
                    out.push_str(" />");
                    push_tail(d, n, &mut out);
                    continue;
                }
                out.push('>');
                if let Some(t) = text {
                    escape(&mut out, &t, false);
                }
                stack.push(Step::Close(n));
                let kids: Vec<Node> = children.collect();
                stack.extend(kids.into_iter().rev().map(Step::Open));
            }
            Step::Close(n) => {
                out.push_str("</");
                out.push_str(d.tag(n));
                out.push('>');
                push_tail(d, n, &mut out);
            }
        }
    }
    Some(out)
}

/// The tail of `n`: every element's, the written element's own included (xml.etree
/// writes it).
fn push_tail(d: &Document, n: Node, out: &mut String) {
    if let Some(tail) = d.element_tail(n).filter(|t| !t.is_empty()) {
        escape(out, &tail, false);
    }
}

fn escape(out: &mut String, s: &str, attribute: bool) {
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' if attribute => out.push_str("&quot;"),
            '\r' if attribute => out.push_str("&#13;"),
            '\n' if attribute => out.push_str("&#10;"),
            '\t' if attribute => out.push_str("&#09;"),
            c => out.push(c),
        }
    }
}
