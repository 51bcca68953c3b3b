//! Inputs the fuzz targets (fuzz/) found or that stand for cases of issue 11, replayed
//! through the targets' own code: `corpora/fuzz/<target>/<case>`. A crash found by
//! `scripts/fuzz.sh` is copied there (named for what it shows) and stays fixed.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

#[path = "../fuzz/fuzz_targets/common.rs"]
mod targets;

use std::path::PathBuf;

fn cases(target: &str) -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("corpora/fuzz")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no cases in {}", dir.display());
    files
}

fn replay(target: &str, run: fn(&[u8])) {
    for case in cases(target) {
        let data = std::fs::read(&case).unwrap();
        if let Err(e) = std::panic::catch_unwind(|| run(&data)) {
            let msg = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            panic!("{}: {msg}", case.display());
        }
    }
}

#[test]
fn roundtrip_cases() {
    replay("roundtrip", targets::roundtrip);
}

#[test]
fn readers_cases() {
    replay("readers", targets::readers);
}

#[test]
fn prefix_cases() {
    replay("prefix", targets::prefix);
}

#[test]
fn merge_cases() {
    replay("merge", targets::merge);
}

#[test]
fn scene_cases() {
    replay("scene", targets::scene);
}
