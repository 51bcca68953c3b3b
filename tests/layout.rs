//! The house plan, checked: the library's tiers (one folder each, see `src/lib.rs`) use only
//! the tiers below them, so no import ever goes upwards and no two tiers depend on each other.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

use std::path::{Path, PathBuf};

/// The tiers from the bottom up: a file of a tier may name itself and anything earlier.
const TIERS: [&str; 10] = [
    "error", "output", "document", "mujoco", "model", "split", "scene", "compiled", "sheet",
    "preview",
];

/// The Python bindings' modules (`python/src/`), which mirror the tiers, from the bottom up.
/// `upcalls` (the one way into the package's Python code) sits below them all.
const PY_TIERS: [&str; 6] = ["upcalls", "errors", "document", "model", "split", "scene"];

/// The crate root's re-exports (`crate::Document`) and the tier each belongs to.
const ROOT_ITEMS: [(&str, &str); 21] = [
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
    ("sort", "model"),
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

/// Where a source or page may name a file of ours: the top-level folders, the library's
/// and the bindings' tier folders.
const OUR_FOLDERS: [&str; 21] = [
    "src", "python", "tests", "benches", "scripts", "docs", "corpora", "examples", "fuzz",
    "document", "output", "mujoco", "model", "split", "scene", "compiled", "sheet", "preview",
    "cli", "judge", "drivers",
];

/// The extensions of files a comment or page points to.
const POINTED: [&str; 8] = [".rs", ".py", ".sh", ".c", ".toml", ".md", ".xml", ".json"];

/// Every file of the checkout (outside `.git`, build outputs and caches), relative.
fn checkout_files(root: &Path, dir: &Path, out: &mut Vec<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            if !name.starts_with('.') && !matches!(name.as_str(), "target" | "__pycache__" | "out")
            {
                checkout_files(root, &path, out);
            }
        } else {
            out.push(
                path.strip_prefix(root)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/"),
            );
        }
    }
}

/// The names of our files in `text`: a path whose first folder is one of ours
/// (`scene/patch.rs`, `python/tests/helpers.py`), or a private module or test file of the
/// Python package named alone (`_cache.py`, `test_world_batch.py`).
fn pointers(text: &str) -> Vec<(usize, String)> {
    let part = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '/' | '-');
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let chars: Vec<(usize, char)> = line.char_indices().collect();
        let mut k = 0;
        while k < chars.len() {
            let (at, c) = chars[k];
            let starts = part(c) && (k == 0 || !part(chars[k - 1].1));
            if !starts {
                k += 1;
                continue;
            }
            let mut end = k;
            while end < chars.len() && part(chars[end].1) {
                end += 1;
            }
            let stop = chars.get(end).map_or(line.len(), |x| x.0);
            // A glob or placeholder (`bench_*.py`, `<suite>.npz`) names no one file.
            let open = chars
                .get(end)
                .is_some_and(|x| matches!(x.1, '*' | '<' | '{'));
            let token = line[at..stop].trim_end_matches('.');
            k = end;
            if open || !POINTED.iter().any(|e| token.ends_with(e)) {
                continue;
            }
            let ours = match token.split_once('/') {
                Some((first, _)) => OUR_FOLDERS.contains(&first),
                None => {
                    token.starts_with("_") && token.ends_with(".py")
                        || token.starts_with("test_") && token.ends_with(".py")
                }
            };
            if ours {
                out.push((n + 1, token.to_string()));
            }
        }
    }
    out
}

#[test]
fn every_file_a_comment_or_page_names_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    checkout_files(root, root, &mut files);
    let exists = |token: &str| {
        files
            .iter()
            .any(|f| f == token || f.ends_with(&format!("/{token}")))
    };
    // A folder of ours that holds the pointed file: another project's path that merely
    // starts like ours (MuJoCo's `src/render/...`) is no pointer of ours.
    let folder_exists = |token: &str| {
        let Some((dir, _)) = token.rsplit_once('/') else {
            return true;
        };
        files
            .iter()
            .any(|f| f.starts_with(&format!("{dir}/")) || f.contains(&format!("/{dir}/")))
    };
    // Error cases name files that must not exist (`missing_hand.xml`, `no_such_robot.xml`).
    let meant_missing = |token: &str| {
        let name = token.rsplit('/').next().unwrap_or(token);
        token.contains("..") || name.starts_with("missing_") || name.starts_with("no_such_")
    };
    let mut missing = Vec::new();
    let texts: Vec<&String> = files
        .iter()
        .filter(|f| {
            [".rs", ".py", ".sh", ".c", ".md", ".toml"]
                .iter()
                .any(|e| f.ends_with(e))
                && !f.starts_with("corpora/")
                && !f.ends_with("vocab.rs")
        })
        .collect();
    assert!(texts.len() > 100, "only {} files read", texts.len());
    for file in texts {
        let text = std::fs::read_to_string(root.join(file)).unwrap_or_default();
        for (line, token) in pointers(&text) {
            if folder_exists(&token) && !meant_missing(&token) && !exists(&token) {
                missing.push(format!("{file}:{line}: {token}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "names of files that do not exist:\n{}",
        missing.join("\n")
    );
}

#[test]
fn pointers_are_found_in_prose_and_code() {
    let text = "see `scene/patch.rs` and python/tests/helpers.py.\nbench_*.py, _cache.py, \
                robosuite's binding_utils.py, x/scene/y.rs";
    let found: Vec<String> = pointers(text).into_iter().map(|(_, t)| t).collect();
    assert_eq!(
        found,
        ["scene/patch.rs", "python/tests/helpers.py", "_cache.py"]
    );
}
