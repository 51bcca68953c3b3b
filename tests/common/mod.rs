//! Shared test helpers: the MuJoCo judges (tests/judge/*.py, run under every MuJoCo version
//! that scripts/setup.sh installs, one venv each, in parallel) and the wheel corpus it lists.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The venv's Python, which has the pinned `mujoco` 3.17.0. Missing setup is a failure, not
/// a skip.
pub fn python() -> PathBuf {
    JUDGES[0].python()
}

/// The Python whose MuJoCo is the version this test build links (see [`linked_judge`]).
#[cfg(mjcf_mujoco)]
pub fn python_linked() -> PathBuf {
    linked_judge().python()
}

/// The judge of the MuJoCo version this test build links: build.rs names it in
/// `MJCF_FORGE_MUJOCO_VERSION`, so a build against 4.0.0 (`MJCF_FORGE_MUJOCO_DIR`) is judged
/// by 4.0.0's venv. A version no judge has fails here rather than being judged by another.
#[cfg(mjcf_mujoco)]
pub fn linked_judge() -> &'static Judge {
    let linked = env!("MJCF_FORGE_MUJOCO_VERSION");
    JUDGES
        .iter()
        .find(|j| j.version == linked)
        .unwrap_or_else(|| {
            let known: Vec<&str> = JUDGES.iter().map(|j| j.version).collect();
            panic!(
                "this test build links MuJoCo {linked}, and no judge has that version (the \
                 judges, from scripts/setup.sh: {}): build against one of them \
                 (MJCF_FORGE_MUJOCO_DIR or MJCF_FORGE_PYTHON)",
                known.join(", ")
            )
        })
}

/// One MuJoCo version that judges outputs: its venv (made by scripts/setup.sh) and the list
/// of wheel models that compile under it.
pub struct Judge {
    /// The `mujoco` version installed in the venv.
    pub version: &'static str,
    venv: &'static str,
    models_list: &'static str,
    urdf_list: &'static str,
    prepared_list: &'static str,
}

/// Every judging MuJoCo: what we write must compile under each to what its input compiles to
/// under that same version.
pub const JUDGES: [Judge; 2] = [
    Judge {
        version: "3.17.0",
        venv: ".cache/venv",
        models_list: "models.txt",
        urdf_list: "urdf-models.txt",
        prepared_list: "urdf-prepared.txt",
    },
    Judge {
        version: "4.0.0",
        venv: ".cache/venv-mj4",
        models_list: "models-mj4.txt",
        urdf_list: "urdf-models-mj4.txt",
        prepared_list: "urdf-prepared-mj4.txt",
    },
];

impl Judge {
    /// The venv's Python. Missing setup is a failure, not a skip.
    pub fn python(&self) -> PathBuf {
        let p = root().join(self.venv).join("bin/python");
        assert!(
            p.exists(),
            "{} is missing: run scripts/setup.sh first",
            p.display()
        );
        p
    }

    /// The wheel models that this MuJoCo compiles on their own.
    pub fn wheel_models(&self) -> Vec<PathBuf> {
        Self::listed(self.models_list)
    }

    /// The URDF files of the corpus wheels (`URDF_CORPORA` in scripts/setup.sh) that this
    /// MuJoCo's importer compiles.
    pub fn wheel_urdfs(&self) -> Vec<PathBuf> {
        Self::listed(self.urdf_list)
    }

    /// The corpus URDFs prepared for MuJoCo (scripts/list_urdf.py: a copy with its meshes
    /// beside it and `<compiler strippath="true">`) whose copy this MuJoCo's importer
    /// compiles: (the copy, the file as shipped).
    pub fn prepared_urdfs(&self) -> Vec<(PathBuf, PathBuf)> {
        Self::listed(self.prepared_list)
            .into_iter()
            .map(|line| {
                let text = line.to_string_lossy().into_owned();
                let (copy, shipped) = text
                    .split_once('\t')
                    .unwrap_or_else(|| panic!("{}: not COPY<TAB>SHIPPED", self.prepared_list));
                (root().join(copy), root().join(shipped))
            })
            .collect()
    }

    fn listed(name: &str) -> Vec<PathBuf> {
        let list = root().join(".cache/corpus").join(name);
        let text = std::fs::read_to_string(&list)
            .unwrap_or_else(|e| panic!("{}: {e}: run scripts/setup.sh first", list.display()));
        text.lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| root().join(l))
            .collect()
    }

    /// Whether this MuJoCo judges a pair whose input is `a`: every file of ours, and the
    /// wheel models it compiles (a wheel model that only the other version compiles has no
    /// reference here).
    fn judges_input(&self, a: &Path, own_models: &[PathBuf]) -> bool {
        !a.starts_with(root().join(".cache/corpus")) || own_models.iter().any(|m| m == a)
    }
}

/// The one MuJoCo version that reads a case of ours, from its marker
/// `mjcf-forge-judge: <version>-only` (a case about a difference between versions: the
/// other versions must reject its input, which the judge checks, and judge nothing else).
pub fn only_version(case: &Path) -> Option<String> {
    const MARKER: &str = "mjcf-forge-judge: ";
    let text = std::fs::read_to_string(case).ok()?;
    let at = text.find(MARKER)? + MARKER.len();
    let version = text[at..]
        .split_whitespace()
        .next()?
        .strip_suffix("-only")?;
    assert!(
        JUDGES.iter().any(|j| j.version == version),
        "{}: no judge for MuJoCo {version}",
        case.display()
    );
    Some(version.to_string())
}

/// Runs `script args...` under every judging MuJoCo at once (one process each) and returns
/// each judge with its output, in [`JUDGES`] order.
pub fn run_each_judge(
    args: impl Fn(&Judge) -> Vec<std::ffi::OsString>,
) -> Vec<(&'static Judge, std::process::Output)> {
    let children: Vec<_> = JUDGES
        .iter()
        .map(|j| {
            let child = Command::new(j.python())
                .args(args(j))
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap_or_else(|e| panic!("run the MuJoCo {} judge: {e}", j.version));
            (j, child)
        })
        .collect();
    children
        .into_iter()
        .map(|(j, child)| (j, child.wait_with_output().expect("wait for a judge")))
        .collect()
}

/// Every MJCF file of the corpus wheels (`CORPORA` in scripts/setup.sh) that MuJoCo compiles
/// on its own, under any judging version.
pub fn wheel_models() -> Vec<PathBuf> {
    let mut models: Vec<PathBuf> = JUDGES.iter().flat_map(Judge::wheel_models).collect();
    models.sort();
    models.dedup();
    assert!(
        models.len() >= 200,
        "expected the full wheel corpus, found {} models",
        models.len()
    );
    models
}

/// Whether this is the full run (`MJCF_FORGE_FULL=1`, scripts/test_full.sh): the judges
/// of the wheel corpus then judge every model; otherwise (scripts/test.sh, CI) every
/// second one ([`sampled`]).
pub fn full_run() -> bool {
    std::env::var("MJCF_FORGE_FULL").is_ok_and(|v| !v.is_empty() && v != "0")
}

/// What a judge of the wheel corpus judges in this run: all of `items` in the full run,
/// else every second one (the first, the third...: in path order, so every wheel and
/// every kind of model is still judged). scripts/test_full.sh judges the rest.
pub fn sampled<T>(items: Vec<T>) -> Vec<T> {
    let full = full_run();
    items
        .into_iter()
        .enumerate()
        .filter(|(i, _)| full || i % 2 == 0)
        .map(|(_, x)| x)
        .collect()
}

/// The wheel models that every judging version compiles on its own (a test that judges one
/// output under every version at once, as the merge judge does, needs a reference in each).
pub fn wheel_models_in_every_version() -> Vec<PathBuf> {
    let lists: Vec<Vec<PathBuf>> = JUDGES.iter().map(Judge::wheel_models).collect();
    wheel_models()
        .into_iter()
        .filter(|m| lists.iter().all(|l| l.contains(m)))
        .collect()
}

/// The include cases of ours: `corpora/includes/<case>/main.xml`. Each case is a folder of
/// files that include each other; the other files there are parts and decoys (files MuJoCo
/// must not read), not models of their own.
pub fn include_cases() -> Vec<PathBuf> {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(root().join("corpora/includes"))
        .unwrap()
        .map(|e| e.unwrap().path().join("main.xml"))
        .filter(|p| p.is_file())
        .collect();
    cases.sort();
    assert!(cases.len() >= 2, "include cases missing");
    cases
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

/// Runs the judge under every judging MuJoCo (in parallel, all pairs in one process per
/// version); returns the lines of failed pairs, each starting with `[MuJoCo <version>]`.
pub fn judge(pairs: &[Pair], scratch_dir: &Path) -> Vec<String> {
    judge_lines(
        |j| {
            let own = j.wheel_models();
            pairs
                .iter()
                .filter(|p| j.judges_input(&p.a, &own))
                .map(|p| {
                    let mode = match only_version(&p.a) {
                        Some(v) if v != j.version => "a-rejected",
                        _ => "same",
                    };
                    format!(
                        "{}\t{}\t{}\t{mode}\n",
                        p.a.display(),
                        p.b.display(),
                        p.prefix
                    )
                })
                .collect()
        },
        scratch_dir,
    )
}

/// [`judge`] with pairs of each version's own: for inputs that the versions read
/// differently (URDF), so that each judge has its own outputs.
pub fn judge_each(pairs: impl Fn(&Judge) -> Vec<Pair>, scratch_dir: &Path) -> Vec<String> {
    judge_lines(
        |j| {
            pairs(j)
                .iter()
                .map(|p| format!("{}\t{}\t{}\tsame\n", p.a.display(), p.b.display(), p.prefix))
                .collect()
        },
        scratch_dir,
    )
}

/// Runs each judge on its pair lines (`A\tB\tPREFIX\tMODE`).
fn judge_lines(lines: impl Fn(&Judge) -> String, scratch_dir: &Path) -> Vec<String> {
    let mut counts = Vec::new();
    for j in &JUDGES {
        let body = lines(j);
        counts.push(body.lines().count());
        std::fs::write(scratch_dir.join(format!("pairs-{}.tsv", j.version)), body).unwrap();
    }
    let runs = run_each_judge(|j| {
        vec![
            root().join("tests/judge/judge.py").into(),
            "--pairs".into(),
            scratch_dir.join(format!("pairs-{}.tsv", j.version)).into(),
            "--verbose".into(),
        ]
    });
    let mut failed = Vec::new();
    for ((j, out), count) in runs.into_iter().zip(counts) {
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let summary = stdout.lines().last().unwrap_or("").to_string();
        let expected = format!("{count} passed, 0 failed");
        if out.status.success() && summary == expected {
            continue;
        }
        let before = failed.len();
        failed.extend(
            stdout
                .lines()
                .filter(|l| !l.starts_with("ok "))
                .map(|l| format!("[MuJoCo {}] {l}", j.version)),
        );
        if failed.len() == before {
            failed.push(format!(
                "[MuJoCo {}] judge exited with {}: {stderr}",
                j.version, out.status
            ));
        }
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

/// The names in a folder, sorted.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
