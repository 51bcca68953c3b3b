//! Writing a variant without building its document: the template is written once as
//! text with holes (the attributes randomizers set) and insertion points (the end of each
//! section), every object instance once as text per section with holes (its pose and
//! randomized attributes); a variant is those texts copied in order with its values.
//!
//! The text is exactly what merging the variant's objects into a copy of the template and
//! writing it gives (`tests/scene_batch.rs` compares both on every test variant): the
//! holes are found by writing the same documents with marker values, and merging a part
//! into the world copies its elements to the end of the template's sections in order,
//! which is what the insertion points reproduce. Where a merge does more than that (keys
//! to remap, a section the template does not have, settings, residual classes, an asset
//! the template shares), [`Template::write`] says no and the document path is taken.

use crate::document::tree::Node;
use crate::document::{Document, Section};

use super::randomize::{AttrTarget, Overlay, Randomizer};
use super::{Drawn, Target};

/// Marks a hole in written text: `HOLE_OPEN id HOLE_CLOSE` (private-use characters, which
/// the writer copies as they are and MJCF never needs).
const HOLE_OPEN: char = '\u{E000}';
const HOLE_CLOSE: char = '\u{E001}';
/// Tag of the element that marks an insertion point (written `<TAG-i/>`).
const INSERT_TAG: &str = "mjcf-forge-splice";

/// Text with holes, each the value of one attribute of one element.
#[derive(Debug)]
pub(crate) struct Pieces {
    text: String,
    /// (offset in `text`, what is there), in order of offset.
    cuts: Vec<(usize, Cut)>,
}

#[derive(Debug, Clone)]
enum Cut {
    /// The value of `attr` of `node`.
    Hole(Node, String),
    /// Insertion point `i` (template only).
    Insert(usize),
}

/// The template as text with holes and insertion points.
#[derive(Debug)]
pub(crate) struct Template {
    pieces: Pieces,
    /// Per insertion point, its section's tag.
    sections: Vec<String>,
}

/// An object instance as text per insertion point of the template.
#[derive(Debug)]
pub(crate) struct Fragments {
    parts: Vec<(usize, Pieces)>,
}

/// Sets a marker value for every attribute the variant sets; returns the holes in order.
fn mark(
    doc: &mut Document,
    holes: &mut Vec<(Node, String)>,
    targets: &[(usize, &[Target])],
    randomizers: &[Randomizer],
) {
    for (k, ts) in targets {
        for t in *ts {
            let attrs: Vec<String> = randomizers[*k]
                .attributes_set(doc, t.node)
                .into_iter()
                .map(str::to_string)
                .collect();
            for attr in attrs {
                hole(doc, holes, t.node, &attr);
            }
        }
    }
}

fn hole(doc: &mut Document, holes: &mut Vec<(Node, String)>, node: Node, attr: &str) {
    if holes.iter().any(|(n, a)| *n == node && a == attr) {
        return;
    }
    let marker = format!("{HOLE_OPEN}{}{HOLE_CLOSE}", holes.len());
    doc.set_attr(node, attr, &marker);
    holes.push((node, attr.to_string()));
}

/// Whether a document's own text has what this module uses as markers (then its variants
/// take the document path rather than risk reading the document's text as a marker).
fn has_markers(doc: &Document) -> bool {
    let text = doc.to_xml_string();
    text.contains(HOLE_OPEN) || text.contains(HOLE_CLOSE) || text.contains(INSERT_TAG)
}

/// Cuts markers out of written text.
fn cut(text: &str, holes: &[(Node, String)]) -> Option<Pieces> {
    let mut out = String::with_capacity(text.len());
    let mut cuts = Vec::new();
    let mut rest = text;
    let insert_open = format!("<{INSERT_TAG}-");
    loop {
        let hole_at = rest.find(HOLE_OPEN);
        let insert_at = rest.find(insert_open.as_str());
        let (at, is_hole) = match (hole_at, insert_at) {
            (None, None) => break,
            (Some(h), Some(i)) if i < h => (i, false),
            (Some(h), _) => (h, true),
            (None, Some(i)) => (i, false),
        };
        out.push_str(&rest[..at]);
        rest = &rest[at..];
        if is_hole {
            let end = rest.find(HOLE_CLOSE)?;
            let id: usize = rest[HOLE_OPEN.len_utf8()..end].parse().ok()?;
            let (node, attr) = holes.get(id)?.clone();
            cuts.push((out.len(), Cut::Hole(node, attr)));
            rest = &rest[end + HOLE_CLOSE.len_utf8()..];
        } else {
            let end = rest.find("/>")?;
            let id: usize = rest[insert_open.len()..end].parse().ok()?;
            cuts.push((out.len(), Cut::Insert(id)));
            rest = &rest[end + 2..];
        }
    }
    out.push_str(rest);
    Some(Pieces { text: out, cuts })
}

impl Template {
    /// The template's text, when variants of this scene can be spliced.
    pub(crate) fn build(
        template: &Document,
        targets: &[Vec<Target>],
        randomizers: &[Randomizer],
    ) -> Option<Template> {
        let root = template.root();
        let keys = Some(Section::Keyframe);
        if template.elements(root).any(|s| {
            Section::from_tag(template.tag(s)) == keys && template.elements(s).next().is_some()
        }) {
            return None; // merging remaps keys
        }
        if has_markers(template) {
            return None;
        }
        let mut doc = template.clone();
        let mut holes = Vec::new();
        let targets: Vec<(usize, &[Target])> = targets
            .iter()
            .enumerate()
            .map(|(k, t)| (k, t.as_slice()))
            .collect();
        mark(&mut doc, &mut holes, &targets, randomizers);
        let mut sections = Vec::new();
        let section_nodes: Vec<Node> = doc.elements(root).collect();
        for s in section_nodes {
            let tag = doc.tag(s).to_string();
            // An empty section is written `<tag/>` until something goes in: such
            // variants take the document path.
            if Section::from_tag(&tag).is_some_and(|x| x != Section::Keyframe)
                && doc.elements(s).next().is_some()
                && !sections.contains(&tag)
            {
                let marker = format!("{INSERT_TAG}-{}", sections.len());
                doc.append_element(s, &marker, &[]);
                sections.push(tag);
            }
        }
        let pieces = cut(&doc.to_xml_string(), &holes)?;
        Some(Template { pieces, sections })
    }

    /// The variant's text, or `None` when one of its objects cannot be spliced or a hole
    /// has no value.
    /// The variant's text into `out` (cleared first; its capacity is reused), or `false`
    /// (with `out` unspecified) when one of its objects cannot be spliced or a hole has no
    /// value.
    pub(crate) fn write(&self, drawn: &Drawn<'_>, out: &mut String) -> bool {
        let start = out.len();
        let ok = self.write_into(drawn, out).is_some();
        if !ok {
            out.truncate(start);
        }
        ok
    }

    fn write_into(&self, drawn: &Drawn<'_>, out: &mut String) -> Option<()> {
        let mut extra = 0;
        for (inst, _) in &drawn.placed {
            extra += inst.fragments.as_ref()?.len();
        }
        out.reserve(self.pieces.text.len() + extra + 1024);
        let mut done = 0;
        for (at, cut) in &self.pieces.cuts {
            out.push_str(&self.pieces.text[done..*at]);
            done = *at;
            match cut {
                Cut::Hole(node, attr) => {
                    crate::document::write::escape_attr(out, drawn.template.get(*node, attr)?);
                }
                Cut::Insert(i) => {
                    for (inst, overlay) in &drawn.placed {
                        let fragments = inst.fragments.as_ref()?;
                        for (_, p) in fragments.parts.iter().filter(|(j, _)| j == i) {
                            p.write(out, overlay)?;
                        }
                    }
                }
            }
        }
        out.push_str(&self.pieces.text[done..]);
        Some(())
    }

    fn insertion_point(&self, tag: &str) -> Option<usize> {
        self.sections.iter().position(|s| s == tag)
    }
}

impl Pieces {
    fn write(&self, out: &mut String, values: &Overlay<'_>) -> Option<()> {
        let mut done = 0;
        for (at, cut) in &self.cuts {
            out.push_str(&self.text[done..*at]);
            done = *at;
            let Cut::Hole(node, attr) = cut else {
                return None;
            };
            crate::document::write::escape_attr(out, values.get(*node, attr)?);
        }
        out.push_str(&self.text[done..]);
        Some(())
    }
}

impl Fragments {
    /// The text an instance adds to each section of `template` when merged into the
    /// world, or `None` when merging it does more than that.
    pub(crate) fn build(
        doc: &Document,
        root: Node,
        targets: &[(usize, Vec<Target>)],
        randomizers: &[Randomizer],
        template_doc: &Document,
        template: &Template,
    ) -> Option<Fragments> {
        if has_markers(doc) {
            return None;
        }
        let mut copy = doc.clone();
        super::place::clear_orientation(&mut copy, root);
        let mut holes = Vec::new();
        hole(&mut copy, &mut holes, root, "pos");
        hole(&mut copy, &mut holes, root, "quat");
        let targets: Vec<(usize, &[Target])> =
            targets.iter().map(|(k, t)| (*k, t.as_slice())).collect();
        mark(&mut copy, &mut holes, &targets, randomizers);
        let mut errors = Vec::new();
        let shared = template_doc.asset_decisions(&copy, &mut errors);
        if !errors.is_empty() || shared.iter().any(|&s| s) {
            return None;
        }
        let mut parts: Vec<(usize, String)> = Vec::new();
        for section in copy.elements(copy.root()) {
            let tag = copy.tag(section);
            match tag {
                "compiler" => continue,
                "keyframe" => return None,
                _ if Section::from_tag(tag).is_none() => return None,
                _ => {}
            }
            let i = template.insertion_point(tag)?;
            let at = match parts.iter().position(|(j, _)| *j == i) {
                Some(at) => at,
                None => {
                    parts.push((i, String::new()));
                    parts.len() - 1
                }
            };
            for child in copy.elements(section) {
                copy.write_node(&mut parts[at].1, child, None);
            }
        }
        let parts = parts
            .into_iter()
            .map(|(i, text)| Some((i, cut(&text, &holes)?)))
            .collect::<Option<Vec<_>>>()?;
        Some(Fragments { parts })
    }

    fn len(&self) -> usize {
        self.parts
            .iter()
            .map(|(_, p)| p.text.len() + 32 * p.cuts.len())
            .sum()
    }
}
