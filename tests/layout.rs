//! The house plan, checked: the library's tiers (one folder each, see `src/lib.rs`) use only
//! the tiers below them, so no import ever goes upwards and no two tiers depend on each other.

use std::path::{Path, PathBuf};

/// The tiers from the bottom up: a file of a tier may name itself and anything earlier.
const TIERS: [&str; 9] = [
    "error", "output", "document", "mujoco", "model", "split", "scene", "compiled", "preview",
];

/// The Python bindings' modules (`python/src/`), which mirror the tiers, from the bottom up.
/// `upcalls` (the one way into the package's Python code) sits below them all.
const PY_TIERS: [&str; 5] = ["upcalls", "errors", "document", "model", "scene"];

/// The crate root's re-exports (`crate::Document`) and the tier each belongs to.
const ROOT_ITEMS: [(&str, &str); 20] = [
    ("Error", "error"),
    ("ErrorKind", "error"),
    ("Errors", "error"),
    ("Location", "error"),
    ("AssetStore", "output"),
    ("OutputDir", "output"),
    ("PendingHeader", "output"),
    ("TarWriter", "output"),
    ("frame_text_member", "output"),
    ("write_atomic", "output"),
    ("Document", "document"),
    ("Section", "document"),
    ("Node", "document"),
    ("Limits", "document"),
    ("vocab", "document"),
    ("MergeOptions", "model"),
    ("MergeReport", "model"),
    ("XmlModel", "model"),
    ("MujocoModel", "model"),
    ("geometry", "model"),
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The tiers a source names through `crate::`, with the line of each use.
fn tiers_used(text: &str, tiers: &[&'static str]) -> Vec<(usize, &'static str)> {
    let mut used = Vec::new();
    for (n, line) in text.lines().enumerate() {
        // Doc links name items for the reader; they are no dependency.
        let mut rest = match line.trim_start() {
            l if l.starts_with("//") => continue,
            l => l,
        };
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            let names: Vec<&str> = if let Some(group) = rest.strip_prefix('{') {
                let end = group.find('}').unwrap_or(group.len());
                group[..end].split(',').map(str::trim).collect()
            } else {
                vec![rest]
            };
            for name in names {
                let ident: String = name
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let tier = tiers.iter().find(|t| **t == ident).copied().or_else(|| {
                    ROOT_ITEMS
                        .iter()
                        .find(|(item, _)| *item == ident)
                        .map(|(_, t)| *t)
                });
                if let Some(tier) = tier {
                    used.push((n + 1, tier));
                }
            }
        }
    }
    used
}

/// Every use of a higher tier by a file of a lower one under `src`, as `path:line: ...`,
/// and how many files were checked (files outside the tiers are the faces and the root).
fn upward_uses(src: &Path, tiers: &[&'static str]) -> (Vec<String>, usize) {
    let rank = |tier: &str| tiers.iter().position(|t| *t == tier);
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.sort();
    let mut checked = 0;
    let mut upward = Vec::new();
    for file in &files {
        let rel = file.strip_prefix(src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let tier = first.trim_end_matches(".rs");
        let Some(own) = rank(tier) else {
            continue;
        };
        checked += 1;
        let text = std::fs::read_to_string(file).unwrap();
        for (line, used) in tiers_used(&text, tiers) {
            if rank(used).unwrap() > own {
                upward.push(format!("{}:{line}: {tier} uses {used}", file.display()));
            }
        }
    }
    (upward, checked)
}

#[test]
fn no_tier_uses_a_tier_above_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (upward, checked) = upward_uses(&root.join("src"), &TIERS);
    assert!(checked > 40, "only {checked} files found under src/");
    assert!(upward.is_empty(), "imports upwards:\n{}", upward.join("\n"));
}

#[test]
fn no_module_of_the_bindings_uses_one_above_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (upward, checked) = upward_uses(&root.join("python/src"), &PY_TIERS);
    assert!(checked >= 8, "only {checked} files found under python/src/");
    assert!(upward.is_empty(), "imports upwards:\n{}", upward.join("\n"));
}

#[test]
fn the_check_sees_every_form_of_a_path() {
    let text = "use crate::scene::Scene;\nuse crate::{Document, XmlModel};\n\
                let x = crate::compiled::f();\n/// [`crate::scene::Scene`]";
    assert_eq!(
        tiers_used(text, &TIERS),
        [(1, "scene"), (2, "document"), (2, "model"), (3, "compiled")]
    );
}

/// Hand-written sources and the longest each may grow before it is split along its
/// concepts (generated files, `vocab.rs`, excepted).
const MAX_LINES: usize = 900;

fn long_files(dir: &Path, exts: &[&str], out: &mut Vec<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            if !name.starts_with('.') && name != "target" && name != "__pycache__" {
                long_files(&path, exts, out);
            }
        } else if exts.iter().any(|e| name.ends_with(e)) && name != "vocab.rs" {
            let n = std::fs::read_to_string(&path).unwrap().lines().count();
            if n > MAX_LINES {
                out.push(format!("{} ({n} lines)", path.display()));
            }
        }
    }
}

#[test]
fn no_hand_written_source_is_over_900_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut long = Vec::new();
    for dir in ["src", "python/src", "python/mjcf_forge"] {
        long_files(&root.join(dir), &[".rs", ".py", ".c"], &mut long);
    }
    assert!(
        long.is_empty(),
        "split along their concepts:\n{}",
        long.join("\n")
    );
}

#[test]
fn the_crate_root_holds_at_most_four_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files: Vec<String> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert!(
        files.len() <= 4,
        "src/ holds {files:?}: move one into its tier"
    );
}
