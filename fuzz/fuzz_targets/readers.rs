//! The reader's two paths (the fast scanner and quick-xml's events) against each other:
//! for any bytes, the same document (text and every node's position) or the same error.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (fast, events) = mjcf_forge::fuzzing::read_both_ways(data, "/nonexistent-mjcf-forge-fuzz");
    assert_eq!(fast, events, "the two readers disagree on {:?}", String::from_utf8_lossy(data));
});
