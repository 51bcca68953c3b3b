// Shared by the targets: the checks every written document must pass.

use mjcf_forge::Document;

/// Where includes and asset files are looked up: a folder that does not exist, so that a
/// relative include fails cleanly (absolute ones are tried, which is part of the test).
pub const BASE: &str = "/nonexistent-mjcf-forge-fuzz";

/// Writes `doc` both ways and checks what every output must be: well-formed XML 1.0 to a
/// strict parser, read back by us without error, and written again to the same bytes.
///
/// For a document that was edited after loading (prefixed, merged), reading back may
/// rename what the reader generates (residual default classes are numbered afresh), so
/// `exact` is false there and the output of the reloaded document must be a fixed point
/// instead.
pub fn check_written(doc: &Document, exact: bool) {
    if !exact {
        for xml in [doc.to_xml_string(), doc.to_pretty_string()] {
            if let Err(e) = roxmltree::Document::parse(&xml) {
                panic!("output is not well-formed XML ({e}):\n{xml}");
            }
        }
        let again = match Document::from_str(&doc.to_xml_string(), BASE) {
            Ok(d) => d,
            Err(e) => panic!("output does not load again ({e}):\n{}", doc.to_xml_string()),
        };
        return check_written(&again, true);
    }
    for (form, xml) in [
        ("compact", doc.to_xml_string()),
        ("pretty", doc.to_pretty_string()),
    ] {
        if let Err(e) = roxmltree::Document::parse(&xml) {
            panic!("{form} output is not well-formed XML ({e}):\n{xml}");
        }
        let again = match Document::from_str(&xml, BASE) {
            Ok(d) => d,
            Err(e) => panic!("{form} output does not load again ({e}):\n{xml}"),
        };
        let rewritten = if form == "compact" {
            again.to_xml_string()
        } else {
            again.to_pretty_string()
        };
        assert_eq!(xml, rewritten, "{form} output changes when read and written again");
    }
}
