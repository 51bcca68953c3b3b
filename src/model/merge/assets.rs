//! Asset de-duplication: a part's asset the base already has (same tag, name and content) is
//! shared rather than copied; the same name with other content is an error naming both.

use ahash::AHashMap;

use super::syms;
use crate::document::names::Sym;
use crate::document::tree::Node;
use crate::document::{Document, Section};
use crate::error::{Error, ErrorKind};

impl Document {
    /// The name of an asset: its `name`, else the one MuJoCo derives from its file.
    fn asset_name(&self, n: Node) -> Option<&str> {
        let s = syms();
        // An empty name is no name: MuJoCo names such an asset after its file.
        self.attr_sym(n, s.name)
            .filter(|v| !v.is_empty())
            .or_else(|| {
                crate::document::prefix::named_after_file_tag(self.tag(n))?;
                self.attr_sym(n, s.file)
                    .and_then(crate::document::prefix::file_stem)
            })
    }

    /// For each asset of the part, in order: whether the base already has it (same tag,
    /// name and content); an asset with a base name but other content is an error naming both.
    pub(crate) fn asset_decisions(&self, part: &Document, errors: &mut Vec<Error>) -> Vec<bool> {
        self.asset_matches(part, errors)
            .iter()
            .map(Option::is_some)
            .collect()
    }

    /// [`Document::asset_decisions`], with this document's asset each shared one matches.
    pub(crate) fn asset_matches(
        &self,
        part: &Document,
        errors: &mut Vec<Error>,
    ) -> Vec<Option<Node>> {
        let Some(theirs) = part.find_section(Section::Asset) else {
            return Vec::new();
        };
        // Index the part's assets (usually a handful) and look each base asset up in that,
        // so a whole scene's assets are walked once per merge without building a map of them.
        let mine: Vec<Node> = part.elements(theirs).collect();
        let mut wanted: AHashMap<(Sym, &str), usize> = AHashMap::with_capacity(mine.len());
        for (i, &a) in mine.iter().enumerate() {
            if let (Some(tag), Some(name)) = (
                crate::document::names::known(part.tag(a)),
                part.asset_name(a),
            ) {
                wanted.entry((tag, name)).or_insert(i);
            }
        }
        let mut same: Vec<Option<Node>> = vec![None; mine.len()];
        if !wanted.is_empty()
            && let Some(assets) = self.find_section(Section::Asset)
        {
            for n in self.elements(assets) {
                if let (Some(tag), Some(name)) = (self.tag_sym(n), self.asset_name(n))
                    && let Some(&i) = wanted.get(&(tag, name))
                    && same[i].is_none()
                {
                    same[i] = Some(n);
                }
            }
        }
        mine.iter()
            .zip(same)
            .map(|(&a, found)| match found {
                None => None,
                Some(n) if self.same_subtree(n, part, a) => Some(n),
                Some(n) => {
                    let tag = part.tag(a);
                    let name = part.asset_name(a).unwrap_or_default();
                    errors.push(part.error_at(
                        a,
                        ErrorKind::Invalid(format!(
                            "asset <{tag}> '{name}' differs from the base's <{tag}> '{name}' at {}",
                            self.location(n)
                        )),
                    ));
                    None
                }
            })
            .collect()
    }
}
