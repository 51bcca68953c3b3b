//! `compile IN [--json]`, and the mapping from MuJoCo's error lines back to the user's
//! sources that `--validate` shares.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[cfg(mjcf_mujoco)]
use std::io::Write as _;

#[cfg(any(mjcf_mujoco, test))]
use mjcf_forge::Document;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    limits: super::LimitArgs,
    /// Input MJCF file.
    input: PathBuf,
    /// Print the sizes as one JSON object.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> ExitCode {
    compile(&args.input, args.json, &args.limits.limits())
}

/// `compile IN [--json]`.
#[cfg(mjcf_mujoco)]
fn compile(input: &Path, json: bool, limits: &mjcf_forge::Limits) -> ExitCode {
    let doc = match Document::load_with(input, limits) {
        Ok(doc) => doc,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let model = match compile_document(&doc) {
        Ok(model) => model,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    if let Some(w) = model.warnings() {
        eprintln!("{}: MuJoCo warning: {w}", input.display());
    }
    let sizes = model.sizes();
    let text = if json {
        format!("{}\n", sizes.to_json())
    } else {
        let width = sizes
            .entries()
            .iter()
            .map(|(k, _)| k.len())
            .max()
            .unwrap_or(0);
        sizes
            .entries()
            .iter()
            .map(|(key, value)| format!("{key:<width$} {value}\n"))
            .collect()
    };
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("mjcf-forge: cannot write to standard output: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `compile` in a build without MuJoCo: says how to get one.
#[cfg(not(mjcf_mujoco))]
fn compile(_input: &Path, _json: bool, _limits: &mjcf_forge::Limits) -> ExitCode {
    eprintln!("mjcf-forge: compile: {}", super::NO_MUJOCO);
    ExitCode::from(super::USAGE)
}

/// Compiles the document's pretty XML with MuJoCo (relative references resolve from the
/// model's folder, though loading made them absolute already).
///
/// MuJoCo names the offending element by its line in the XML it was given; that XML is
/// ours, so the line is mapped back to the element and on to its place in the user's
/// sources: `robot.xml:12:7: Error: mesh 'nope' not found in geom 0` followed by the rest
/// of MuJoCo's message (whose own `line N` counts lines of the generated XML) and by the
/// include chain, as for load errors.
#[cfg(mjcf_mujoco)]
pub fn compile_document(doc: &Document) -> Result<mjcf_forge::mujoco::CompiledModel, String> {
    let xml = doc.to_pretty_string();
    mjcf_forge::mujoco::compile_str(&xml, doc.model_dir()).map_err(|err| {
        let element = err
            .element_line
            .and_then(|line| element_at_line(doc, &xml, line, &err.message));
        match element.and_then(|node| source_location(doc, node)) {
            Some(location) => mjcf_forge::Error {
                location: Some(location),
                kind: mjcf_forge::ErrorKind::Invalid(err.message),
            }
            .to_string(),
            None => format!(
                "{}: {}",
                doc.location(doc.root()).file.display(),
                err.message
            ),
        }
    })
}

// ------------------------------------------------ from a line of our XML to an element

/// Where each element's start tag begins in `xml` as written by [`Document`]'s writers:
/// `(1-based line, byte offset of its '<')`, in document order, i.e. the order of
/// `doc.descendants(doc.root())`.
///
/// Exact for our writers' output, mixed content included (where several elements share a
/// line), because the writers escape `<` in attribute values and text; the only other
/// markup they emit is closing tags and CDATA sections, which are skipped whole. (Counting
/// lines that start with `<` would miscount inside mixed content and CDATA.)
#[cfg(any(mjcf_mujoco, test))]
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
#[cfg(any(mjcf_mujoco, test))]
fn element_at_line(
    doc: &Document,
    xml: &str,
    line: u32,
    message: &str,
) -> Option<mjcf_forge::Node> {
    let starts = element_starts(xml);
    let elements: Vec<mjcf_forge::Node> = doc.descendants(doc.root()).collect();
    if starts.len() != elements.len() {
        // Not this document's rendering: better no position than a wrong one.
        return None;
    }
    let on_line: Vec<mjcf_forge::Node> = starts
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
#[cfg(any(mjcf_mujoco, test))]
fn quoted_after<'a>(text: &'a str, marker: &str) -> Option<&'a str> {
    let rest = &text[text.find(marker)? + marker.len()..];
    rest.find('\'').map(|end| &rest[..end])
}

/// The source position of `node`, or of its nearest ancestor that has one (elements made
/// while loading, such as a section created on demand, have none: line 0).
#[cfg(any(mjcf_mujoco, test))]
fn source_location(doc: &Document, node: mjcf_forge::Node) -> Option<mjcf_forge::Location> {
    std::iter::successors(Some(node), |&n| doc.parent(n))
        .map(|n| doc.location(n))
        .find(|location| location.line > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

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
