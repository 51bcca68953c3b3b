//! Merging: the input is `base NUL part NUL prefix NUL body`. The part is prefixed and
//! merged into the base (into `body` when not empty); a merge is refused or gives a
//! document that is written well-formed and reloads to the same bytes, and a refused merge
//! leaves the base as it was.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mjcf_forge::{Document, MergeOptions};

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
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
        Document::from_str(base, common::BASE),
        Document::from_str(part, common::BASE),
    ) else {
        return;
    };
    if part.apply_prefix(prefix).is_err() {
        return;
    }
    let before = base.to_xml_string();
    let options = MergeOptions {
        fuse_keys: data.len() % 2 == 0,
        part_prefix: prefix.to_string(),
    };
    match base.merge(&part, into, &options) {
        Ok(_) => common::check_written(&base, false),
        Err(_) => assert_eq!(base.to_xml_string(), before, "a refused merge changed the base"),
    }
});
