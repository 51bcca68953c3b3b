//! Merging: see `common::merge` (input `base NUL part NUL prefix NUL body`).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| common::merge(data));
