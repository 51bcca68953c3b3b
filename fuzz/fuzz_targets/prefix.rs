//! Prefixing: see `common::prefix` (input `prefix NUL model`).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| common::prefix(data));
