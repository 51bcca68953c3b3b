//! Character data as ElementTree sees it: an element's *text* is the character data before
//! its first child element, its *tail* the character data after it, up to its next sibling
//! element.
//!
//! MJCF carries almost none: the reader keeps character data that is not white space only,
//! so a model read from a file has `None` for nearly every text and tail. Both can be set,
//! and are written out as given. A tail lives in the element's parent, so an element
//! without a parent has none.

use std::borrow::Cow;

use crate::document::Document;
use crate::document::tree::{Node, NodeData};
use crate::error::{Error, ErrorKind};

impl Document {
    /// The character data of `node` before its first child element (`None` when there is
    /// none), as ElementTree's `text`.
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let doc = Document::from_str("<mujoco>a<![CDATA[b]]><option/>c</mujoco>", ".")?;
    /// let option = doc.elements(doc.root()).next().unwrap();
    /// assert_eq!(doc.element_text(doc.root()).as_deref(), Some("ab"));
    /// assert_eq!(doc.element_tail(option).as_deref(), Some("c"));
    /// assert_eq!(doc.element_text(option), None);
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn element_text(&self, node: Node) -> Option<Cow<'_, str>> {
        self.join_text(self.tree.first_child(node))
    }

    /// The character data right after `node`, up to its next sibling element (`None` when
    /// there is none), as ElementTree's `tail`.
    pub fn element_tail(&self, node: Node) -> Option<Cow<'_, str>> {
        self.join_text(self.tree.next_sibling(node))
    }

    /// The run of text nodes starting at `first`, joined.
    fn join_text(&self, first: Option<Node>) -> Option<Cow<'_, str>> {
        let mut run = std::iter::successors(first, |&n| self.tree.next_sibling(n))
            .map_while(|n| self.text(n));
        let head = run.next()?;
        match run.next() {
            None => Some(Cow::Borrowed(head)),
            Some(second) => {
                let mut joined = String::from(head);
                joined.push_str(second);
                run.for_each(|t| joined.push_str(t));
                Some(Cow::Owned(joined))
            }
        }
    }

    /// The text nodes right after `node` (its tail), in order.
    pub(crate) fn tail_nodes(&self, node: Node) -> Vec<Node> {
        std::iter::successors(self.tree.next_sibling(node), |&n| self.tree.next_sibling(n))
            .take_while(|&n| !self.is_element(n))
            .collect()
    }

    /// Sets the text of `node` (see [`Document::element_text`]); `None` or `""` removes it.
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let mut doc = Document::from_str("<mujoco><option/></mujoco>", ".")?;
    /// let root = doc.root();
    /// doc.set_element_text(root, Some("x < y"));
    /// assert_eq!(doc.to_xml_string(), "<mujoco>x &lt; y<option/></mujoco>");
    /// doc.set_element_text(root, None);
    /// assert_eq!(doc.to_xml_string(), "<mujoco><option/></mujoco>");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn set_element_text(&mut self, node: Node, text: Option<&str>) {
        while let Some(first) = self.tree.first_child(node) {
            if self.is_element(first) {
                break;
            }
            self.tree.detach(first);
        }
        if let Some(text) = text.filter(|t| !t.is_empty()) {
            let new = self.new_text(text, node);
            self.tree.prepend(node, new);
        }
    }

    /// Sets the tail of `node` (see [`Document::element_tail`]); `None` or `""` removes it.
    /// An element without a parent cannot carry one: setting a non-empty tail on it is an
    /// error.
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let mut doc = Document::from_str("<mujoco><option/></mujoco>", ".")?;
    /// let option = doc.elements(doc.root()).next().unwrap();
    /// doc.set_element_tail(option, Some("after"))?;
    /// assert_eq!(doc.to_xml_string(), "<mujoco><option/>after</mujoco>");
    /// assert!(doc.set_element_tail(doc.root(), Some("x")).is_err());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn set_element_tail(&mut self, node: Node, tail: Option<&str>) -> Result<(), Error> {
        for t in self.tail_nodes(node) {
            self.tree.detach(t);
        }
        let Some(tail) = tail.filter(|t| !t.is_empty()) else {
            return Ok(());
        };
        if self.parent(node).is_none() {
            return Err(self.error_at(
                node,
                ErrorKind::Invalid(format!(
                    "<{}> has no parent to hold a tail (the text after an element lives in its parent)",
                    self.tag(node)
                )),
            ));
        }
        let new = self.new_text(tail, node);
        self.tree.insert_after(node, new);
        Ok(())
    }

    /// A parentless text node, with the position of `origin`.
    fn new_text(&mut self, text: &str, origin: Node) -> Node {
        let text = self.push_str(text);
        let node = self.tree.new_node(NodeData::Text { text, cdata: false });
        let span = self.spans[crate::document::tree::Tree::index(origin)];
        self.set_span(node, span);
        node
    }

    /// Every piece of character data inside `node`, in document order, as ElementTree's
    /// `itertext`: its text, then each child's pieces and tail (not its own tail).
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let doc = Document::from_str("<mujoco>a<custom>b</custom>c<size/>d</mujoco>", ".")?;
    /// assert_eq!(doc.text_pieces(doc.root()).concat(), "abcd");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn text_pieces(&self, node: Node) -> Vec<Cow<'_, str>> {
        let mut pieces: Vec<Cow<'_, str>> = Vec::new();
        for n in self.tree.descendants(node).skip(1) {
            let Some(text) = self.text(n) else { continue };
            // A text node right after another one continues its piece (a text node has
            // no children, so that one was the node just visited).
            let continues = self
                .tree
                .previous_sibling(n)
                .is_some_and(|p| !self.is_element(p));
            match pieces.last_mut() {
                Some(last) if continues => last.to_mut().push_str(text),
                _ => pieces.push(Cow::Borrowed(text)),
            }
        }
        pieces
    }
}

#[cfg(test)]
mod tests {
    use crate::Document;

    #[test]
    fn text_and_tail_are_replaced_not_added_to() {
        let mut doc =
            Document::from_str("<mujoco>a<option/>b<![CDATA[c]]><size/></mujoco>", ".").unwrap();
        let root = doc.root();
        let option = doc.elements(root).next().unwrap();
        assert_eq!(doc.element_tail(option).as_deref(), Some("bc"));
        doc.set_element_tail(option, Some("t")).unwrap();
        doc.set_element_text(root, Some("x"));
        doc.set_element_text(option, Some("inside"));
        assert_eq!(
            doc.to_xml_string(),
            "<mujoco>x<option>inside</option>t<size/></mujoco>"
        );
        assert_eq!(doc.text_pieces(root), ["x", "inside", "t"]);
        doc.set_element_tail(option, Some("")).unwrap();
        doc.set_element_text(option, None);
        assert_eq!(doc.to_xml_string(), "<mujoco>x<option/><size/></mujoco>");
        assert_eq!(doc.element_tail(option), None);
    }
}
