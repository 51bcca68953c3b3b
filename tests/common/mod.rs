//! Shared test helpers: the MuJoCo judge (tests/judge/judge.py in the setup's venv) and
//! the wheel corpus listed by scripts/setup.sh.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The venv's Python, which has the pinned `mujoco`. Missing setup is a failure, not a skip.
pub fn python() -> PathBuf {
    let p = root().join(".cache/venv/bin/python");
    assert!(
        p.exists(),
        "{} is missing: run scripts/setup.sh first",
        p.display()
    );
    p
}

/// Every MJCF file of the robosuite and dm-control wheels that MuJoCo compiles on its own.
pub fn wheel_models() -> Vec<PathBuf> {
    let list = root().join(".cache/corpus/models.txt");
    let text = std::fs::read_to_string(&list)
        .unwrap_or_else(|e| panic!("{}: {e}: run scripts/setup.sh first", list.display()));
    let models: Vec<PathBuf> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| root().join(l))
        .collect();
    assert!(
        models.len() >= 100,
        "expected the full wheel corpus, found {} models",
        models.len()
    );
    models
}

/// A fresh scratch folder under target/.
pub fn scratch(name: &str) -> PathBuf {
    let dir = root().join("target/test-scratch").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// One comparison for the judge: A and B compile to the same model, B's names being
/// `prefix` + A's.
pub struct Pair {
    pub a: PathBuf,
    pub b: PathBuf,
    pub prefix: String,
}

/// Runs the judge on all pairs in one process; returns the lines of failed pairs.
pub fn judge(pairs: &[Pair], scratch_dir: &Path) -> Vec<String> {
    let tsv = scratch_dir.join("pairs.tsv");
    let body: String = pairs
        .iter()
        .map(|p| format!("{}\t{}\t{}\n", p.a.display(), p.b.display(), p.prefix))
        .collect();
    std::fs::write(&tsv, body).unwrap();
    let out = Command::new(python())
        .arg(root().join("tests/judge/judge.py"))
        .arg("--pairs")
        .arg(&tsv)
        .arg("--verbose")
        .output()
        .expect("run the judge");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let summary = stdout.lines().last().unwrap_or("").to_string();
    let expected = format!("{} passed, 0 failed", pairs.len());
    if out.status.success() && summary == expected {
        return Vec::new();
    }
    let mut failed: Vec<String> = stdout
        .lines()
        .filter(|l| !l.starts_with("ok "))
        .map(str::to_string)
        .collect();
    if failed.is_empty() {
        failed.push(format!("judge exited with {}: {stderr}", out.status));
    }
    failed
}

/// Runs the binary from the repository root, so paths in messages are as in the .err files.
pub fn forge(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_mjcf-forge"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("run mjcf-forge")
}

/// A run's standard output as text.
pub fn stdout(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A run's standard error as text.
pub fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A test path as a command-line argument.
pub fn path_arg(p: &Path) -> &str {
    p.to_str().expect("UTF-8 test path")
}
