//! Load (includes, defaults, paths), write, reload: never a panic, and what is written is
//! well-formed and written again byte for byte.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    let Ok(xml) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(doc) = mjcf_forge::Document::from_str(xml, common::BASE) {
        common::check_written(&doc, true);
    }
});
