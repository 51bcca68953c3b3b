//! Prefixing: the input is `prefix NUL model`. A prefix is refused or applied, and the
//! prefixed model is written well-formed and reloads to the same bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Some((prefix, xml)) = text.split_once('\0') else {
        return;
    };
    let Ok(mut doc) = mjcf_forge::Document::from_str(xml, common::BASE) else {
        return;
    };
    if doc.apply_prefix(prefix).is_ok() {
        let _ = doc.validate();
        common::check_written(&doc, false);
    }
});
