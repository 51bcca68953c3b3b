// The fuzz targets' bodies, shared with tests/fuzz_regressions.rs (which includes this file
// by path): a crash found by a target is replayed by the test through the same code.

#![allow(dead_code)]

use mjcf_forge::{Document, MergeOptions};

/// Where includes and asset files are looked up: a folder that does not exist, so that a
/// relative include fails cleanly (absolute ones are tried, which is part of the test).
pub const BASE: &str = "/nonexistent-mjcf-forge-fuzz";

/// Load (includes, defaults, paths), write, reload: never a panic, and what is written is
/// well-formed and written again byte for byte.
pub fn roundtrip(data: &[u8]) {
    let Ok(xml) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(doc) = Document::from_str(xml, BASE) {
        check_written(&doc, true);
    }
}

/// The reader's two paths (the fast scanner and quick-xml's events) against each other:
/// for any bytes, the same document (text and every node's position) or the same error.
pub fn readers(data: &[u8]) {
    let (fast, events) = mjcf_forge::fuzzing::read_both_ways(data, BASE);
    assert_eq!(
        fast,
        events,
        "the two readers disagree on {:?}",
        String::from_utf8_lossy(data)
    );
}

/// Prefixing: the input is `prefix NUL model`. A prefix is refused (leaving the document
/// as it was) or applied, and the prefixed model is written well-formed and reloads.
pub fn prefix(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Some((prefix, xml)) = text.split_once('\0') else {
        return;
    };
    let Ok(mut doc) = Document::from_str(xml, BASE) else {
        return;
    };
    let before = doc.to_xml_string();
    match doc.apply_prefix(prefix) {
        Ok(()) => {
            let _ = doc.validate();
            check_written(&doc, false);
        }
        Err(_) => assert_eq!(
            doc.to_xml_string(),
            before,
            "a refused prefix changed the model"
        ),
    }
}

/// Merging: the input is `base NUL part NUL prefix NUL body`. The part is prefixed and
/// merged into the base (into `body` when not empty); a merge is refused, leaving the base
/// as it was, or gives a document that is written well-formed and reloads.
pub fn merge(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let mut fields = text.split('\0');
    let (Some(base), Some(part)) = (fields.next(), fields.next()) else {
        return;
    };
    let prefix = fields.next().unwrap_or("");
    let into = fields.next().filter(|b| !b.is_empty());
    let (Ok(mut base), Ok(mut part)) = (
        Document::from_str(base, BASE),
        Document::from_str(part, BASE),
    ) else {
        return;
    };
    if part.apply_prefix(prefix).is_err() {
        return;
    }
    let before = base.to_xml_string();
    let options = MergeOptions {
        fuse_keys: data.len().is_multiple_of(2),
        part_prefix: prefix.to_string(),
    };
    match base.merge(&part, into, &options) {
        Ok(_) => {
            let _ = base.validate();
            check_written(&base, false);
        }
        Err(_) => assert_eq!(
            base.to_xml_string(),
            before,
            "a refused merge changed the base"
        ),
    }
}

/// The scene description (TOML, or JSON when the input starts with `{`) and variant
/// generation of the batch tier: a description is refused or gives a scene whose first
/// variants are each refused or written well-formed, reload, and come out the same when
/// made again (a variant depends on the seed and its index only).
pub fn scene(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // The demo scene's models, from the fuzz crate or from the root crate's tests.
    let crate_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut dir = crate_dir.join("corpora/scenes/demo");
    if !dir.exists() {
        dir = crate_dir.join("../corpora/scenes/demo");
    }
    let scene = if text.starts_with('{') {
        mjcf_forge::scene::Scene::from_json_str(text, &dir)
    } else {
        mjcf_forge::scene::Scene::from_toml_str(text, &dir)
    };
    let Ok(scene) = scene else {
        return;
    };
    for index in [0, 1, u64::MAX] {
        let Ok(variant) = scene.variant(index) else {
            continue;
        };
        let again = scene.variant(index).expect("the same variant again");
        assert_eq!(
            variant.xml(),
            again.xml(),
            "variant {index} differs when made again"
        );
        assert_eq!(variant.params_json(), again.params_json());
        check_written(&variant.document, false);
    }
}

/// Writes `doc` both ways and checks what every output must be: well-formed XML 1.0 to a
/// strict parser, read back by us without error, and written again to the same bytes.
///
/// For a document that was edited after loading (prefixed, merged), reading back may
/// rename what the reader generates (residual default classes are numbered afresh), so
/// `exact` is false there and the output of the reloaded document must be a fixed point
/// instead.
pub fn check_written(doc: &Document, exact: bool) {
    for xml in [doc.to_xml_string(), doc.to_pretty_string()] {
        if let Err(e) = roxmltree::Document::parse(&xml) {
            panic!("output is not well-formed XML ({e}):\n{xml}");
        }
    }
    if !exact {
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
        let again = match Document::from_str(&xml, BASE) {
            Ok(d) => d,
            Err(e) => panic!("{form} output does not load again ({e}):\n{xml}"),
        };
        let rewritten = if form == "compact" {
            again.to_xml_string()
        } else {
            again.to_pretty_string()
        };
        assert_eq!(
            xml, rewritten,
            "{form} output changes when read and written again"
        );
    }
}
