//! The documentation's code blocks and links (`README.md` and `docs/*.md`), checked as a
//! user would meet them. The conventions, by a block's language tag (also described in
//! docs/contributing.md, "The documentation's code blocks"):
//!
//! - ` ```sh `: run here with `bash -e -o pipefail`, this build's `mjcf-forge` first on
//!   `PATH`, in a temporary folder that links `corpora/`, `benches/`, `python/`, `scripts/`
//!   and `.cache/` of the repository (so relative paths work and outputs stay out of the
//!   repository). A block whose first line is `# needs a build with --features mujoco`
//!   runs only in such a build.
//! - ` ```toml `: a scene file over the demo's models; loaded here with
//!   `Scene::from_toml_str` (relative to `corpora/scenes/demo/`), twenty variants made.
//! - ` ```rust `: doctests, through `src/doc_pages.rs` (checked here: it lists every page
//!   that has Rust blocks).
//! - ` ```python `: python/tests/test_docs.py.
//! - ` ```text `: not run (synopses, output, setup, installing, benches).
//!
//! Every block must carry one of these tags (an untagged block would be a doctest), and
//! every relative link must name a file, and heading, that exists.
//!
//! Pass: the build without the feature (every block but those that need MuJoCo), and once
//! with MuJoCo 3.17.0 linked (scripts/test.sh), for the blocks that need it.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

use mjcf_forge::scene::Scene;

const LANGUAGES: &[&str] = &["rust", "python", "sh", "toml", "text"];
const NEEDS_MUJOCO: &str = "# needs a build with --features mujoco";
/// What the shell blocks may read, linked into their working folder.
const LINKED: &[&str] = &["corpora", "benches", "python", "scripts", ".cache"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and docs/*.md.
fn pages() -> Vec<PathBuf> {
    let mut pages: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .expect("docs/")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    pages.sort();
    pages.insert(0, root().join("README.md"));
    pages
}

fn shown(page: &Path) -> String {
    page.strip_prefix(root())
        .unwrap_or(page)
        .display()
        .to_string()
}

struct Block {
    page: PathBuf,
    /// 1-based line of the block's first line of code.
    line: usize,
    lang: String,
    code: String,
}

/// A fence: optional indentation, three or more backticks, the info string.
fn fence(line: &str) -> Option<(usize, usize, String)> {
    let indent = line.len() - line.trim_start().len();
    let rest = &line[indent..];
    let ticks = rest.len() - rest.trim_start_matches('`').len();
    if ticks < 3 {
        return None;
    }
    let info = rest[ticks..].trim();
    let lang = info.split([' ', ',']).next().unwrap_or("").to_string();
    Some((indent, ticks, lang))
}

/// Every fenced block of a page; the rest of its lines (the prose) as the second value.
fn parse(page: &Path) -> (Vec<Block>, Vec<(usize, String)>) {
    let text = std::fs::read_to_string(page).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let (mut blocks, mut prose) = (Vec::new(), Vec::new());
    let mut i = 0;
    while i < lines.len() {
        let Some((indent, ticks, lang)) = fence(lines[i]) else {
            prose.push((i + 1, lines[i].to_string()));
            i += 1;
            continue;
        };
        let start = i + 1;
        let mut code = String::new();
        i += 1;
        while i < lines.len() {
            let l = lines[i];
            let t = l.trim_start();
            if t.starts_with(&"`".repeat(ticks)) && t.trim_start_matches('`').trim().is_empty() {
                break;
            }
            // Blocks inside list items are indented: take the fence's indentation off.
            let cut = l.len().min(indent);
            code.push_str(if l[..cut].trim().is_empty() {
                &l[cut..]
            } else {
                l
            });
            code.push('\n');
            i += 1;
        }
        blocks.push(Block {
            page: page.to_path_buf(),
            line: start + 1,
            lang,
            code,
        });
        i += 1;
    }
    (blocks, prose)
}

fn all_blocks() -> Vec<Block> {
    pages().iter().flat_map(|p| parse(p).0).collect()
}

#[test]
fn every_block_has_a_known_language() {
    let bad: Vec<String> = all_blocks()
        .iter()
        .filter(|b| !LANGUAGES.contains(&b.lang.as_str()))
        .map(|b| format!("{}:{}: ```{}", shown(&b.page), b.line - 1, b.lang))
        .collect();
    assert!(
        bad.is_empty(),
        "blocks without one of {LANGUAGES:?}:\n{}",
        bad.join("\n")
    );
}

/// A folder that links what the blocks read, for them to run in.
fn workspace() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for name in LINKED {
        let target = root().join(name);
        if target.exists() {
            std::os::unix::fs::symlink(&target, dir.path().join(name)).unwrap();
        }
    }
    dir
}

#[test]
fn shell_blocks_run() {
    let forge = PathBuf::from(env!("CARGO_BIN_EXE_mjcf-forge"));
    let path = format!(
        "{}:{}",
        forge.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let blocks: Vec<Block> = all_blocks()
        .into_iter()
        .filter(|b| b.lang == "sh")
        .collect();
    assert!(blocks.len() >= 4, "only {} sh blocks", blocks.len());
    let mut ran = 0;
    for b in &blocks {
        let needs_mujoco = b
            .code
            .lines()
            .next()
            .is_some_and(|l| l.trim() == NEEDS_MUJOCO);
        if needs_mujoco && !cfg!(feature = "mujoco") {
            continue;
        }
        let dir = workspace();
        let out = Command::new("bash")
            .args(["-e", "-o", "pipefail", "-c", &b.code])
            .current_dir(dir.path())
            .env("PATH", &path)
            .output()
            .expect("bash");
        assert!(
            out.status.success(),
            "{}:{}: the block failed ({}):\n{}\n--- stdout\n{}\n--- stderr\n{}",
            shown(&b.page),
            b.line,
            out.status,
            b.code,
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        ran += 1;
    }
    assert!(ran >= 3, "only {ran} sh blocks ran");
}

#[test]
fn toml_blocks_are_scenes_that_make_variants() {
    let demo = root().join("corpora/scenes/demo");
    let blocks: Vec<Block> = all_blocks()
        .into_iter()
        .filter(|b| b.lang == "toml")
        .collect();
    assert!(!blocks.is_empty(), "no toml block");
    for b in &blocks {
        let at = format!("{}:{}", shown(&b.page), b.line);
        let scene = Scene::from_toml_str(&b.code, &demo)
            .unwrap_or_else(|e| panic!("{at}: the scene is refused:\n{e}"));
        for i in 0..20 {
            scene
                .variant_xml(i)
                .unwrap_or_else(|e| panic!("{at}: variant {i}:\n{e}"));
        }
    }
}

#[test]
fn pages_with_rust_blocks_are_doctests() {
    let pages = std::fs::read_to_string(root().join("src/doc_pages.rs")).unwrap();
    let mut missing = BTreeSet::new();
    for b in all_blocks().iter().filter(|b| b.lang == "rust") {
        let rel = shown(&b.page);
        if !pages.contains(&format!("\"../{rel}\"")) {
            missing.insert(rel);
        }
    }
    assert!(
        missing.is_empty(),
        "src/doc_pages.rs does not list these pages, so their blocks are not doctests: \
         {missing:?}"
    );
}

/// GitHub's anchor of a heading.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

fn anchors(page: &Path) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    for (_, line) in parse(page).1 {
        let t = line.trim_start();
        if t.starts_with('#') {
            let base = slug(t.trim_start_matches('#'));
            let mut s = base.clone();
            let mut n = 0;
            while seen.contains(&s) {
                n += 1;
                s = format!("{base}-{n}");
            }
            seen.insert(s);
        }
    }
    seen
}

/// Removes inline code spans, whose brackets are not links.
fn without_code(line: &str) -> String {
    let mut out = String::new();
    for (k, part) in line.split('`').enumerate() {
        if k % 2 == 0 {
            out.push_str(part);
        }
    }
    out
}

#[test]
fn relative_links_point_at_what_exists() {
    let mut bad = Vec::new();
    let mut count = 0;
    for page in pages() {
        for (n, line) in parse(&page).1 {
            let line = without_code(&line);
            let mut rest = line.as_str();
            while let Some(at) = rest.find("](") {
                let after = &rest[at + 2..];
                let Some(end) = after.find(')') else { break };
                let target = &after[..end];
                rest = &after[end..];
                if target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                count += 1;
                let (file, anchor) = target.split_once('#').unwrap_or((target, ""));
                let file = if file.is_empty() {
                    page.clone()
                } else {
                    page.parent().unwrap().join(file)
                };
                let here = format!("{}:{n}: {target}", shown(&page));
                if !file.exists() {
                    bad.push(format!("{here}: no such file"));
                } else if !anchor.is_empty()
                    && file.extension().is_some_and(|e| e == "md")
                    && !anchors(&file).contains(anchor)
                {
                    bad.push(format!("{here}: no such heading"));
                }
            }
        }
    }
    assert!(count > 20, "only {count} links found");
    assert!(bad.is_empty(), "broken links:\n{}", bad.join("\n"));
}

#[test]
fn the_readme_stays_short_and_names_what_exists() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(lines <= 200, "README.md has {lines} lines (at most 200)");
    for path in [
        "scripts/run-example.sh",
        "scripts/test.sh",
        ".ci/run",
        "corpora/scenes/demo/demo.toml",
    ] {
        assert!(readme.contains(path), "README.md no longer names {path}");
        assert!(
            root().join(path).exists(),
            "README.md names {path}, which is gone"
        );
    }
}
