//! A part's residual default classes (the values `inline_defaults` keeps in classes because
//! MJCF has no attribute for them on the element itself): carried over, a class of the same
//! name having to mean the same in base and part.

use crate::document::Document;
use crate::document::import::Import;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind};

impl Document {
    /// Residual default classes of a part (see `defaults`): the same name must mean the same.
    pub(super) fn check_residual_defaults(&self, part: &Document, errors: &mut Vec<Error>) {
        let Some(ours) = self.elements(self.root).find(|&n| self.tag(n) == "default") else {
            return;
        };
        for section in part
            .elements(part.root)
            .filter(|&n| part.tag(n) == "default")
        {
            for class in part.elements(section) {
                let name = part.attr(class, "class").unwrap_or_default();
                if let Some(c) = self
                    .elements(ours)
                    .find(|&c| self.attr(c, "class") == Some(name))
                    && !self.same_subtree(c, part, class)
                {
                    errors.push(part.error_at(
                        class,
                        ErrorKind::Invalid(format!(
                            "default class '{name}' differs from the base's at {}",
                            self.location(c)
                        )),
                    ));
                }
            }
        }
    }

    /// Adds the part's residual classes the base does not have (checked beforehand).
    pub(super) fn merge_residual_defaults(
        &mut self,
        part: &Document,
        section: Node,
        file_offset: u32,
    ) {
        let existing = self.elements(self.root).find(|&n| self.tag(n) == "default");
        let dest = match existing {
            Some(d) => d,
            None => {
                let sym = self.intern("default");
                let d = self.new_element(sym, None);
                match self.tree.first_child(self.root) {
                    Some(f) => self.tree.insert_before(f, d),
                    None => self.tree.append(self.root, d),
                }
                d
            }
        };
        let mut imp = Import::new(file_offset, false);
        for class in part.elements(section).collect::<Vec<_>>() {
            let name = part.attr(class, "class").unwrap_or_default();
            if self
                .elements(dest)
                .any(|c| self.attr(c, "class") == Some(name))
            {
                continue;
            }
            self.import(part, class, Some(dest), &mut imp);
        }
    }
}
