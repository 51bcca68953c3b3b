//! The batch tier's scene description and variant generation: see `common::scene`.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| common::scene(data));
