//! Load, write, reload: see `common::roundtrip`.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| common::roundtrip(data));
