//! The command line's edges, as a user meets them (issue 23): a closed standard output
//! (`| head`) ends every command quietly; `info` speaks to a person unless asked for
//! JSON; `generate` shows its progress on long runs (a plain line when standard error is
//! not a terminal, nothing with `--quiet`) and counts what `--validate` compiled and
//! patched; output folders are never mixed with a previous run's; merge name clashes and
//! missing targets say what to do.
//!
//! Pass: once per MuJoCo the feature `mujoco` links (scripts/test.sh: 3.17.0 and 4.0.0),
//! since what it checks depends on that MuJoCo; the build without the feature runs the
//! tests here that need none (they are cheap: not worth a file of their own).

mod common;

use std::process::{Command, Stdio};

use common::{forge, listing, path_arg, root, scratch, stderr, stdout};

const ARM: &str = "corpora/merge/arm_with_keys.xml";

/// Runs the binary with its standard output a pipe whose reader has already gone.
fn with_closed_stdout(args: &[&str]) -> std::process::Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mjcf-forge"))
        .args(args)
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run mjcf-forge");
    // Closed long before the program has loaded anything, let alone written.
    drop(child.stdout.take());
    child.wait_with_output().unwrap()
}

#[test]
fn a_closed_standard_output_ends_every_command_quietly() {
    let dir = scratch("cli_edges_pipe");
    let json_dir = dir.join("generated");
    let mut runs: Vec<Vec<&str>> = vec![
        vec!["--help"],
        vec!["info", ARM, "--json"],
        vec!["info", ARM],
        vec!["inline", ARM],
        vec!["prefix", ARM, "--prefix", "p_"],
        vec![
            "merge",
            ARM,
            "--part",
            "corpora/merge/gripper_radian.xml:g_:hand",
        ],
        vec!["export", "corpora/scenes/demo/arm.xml", "--tar", "-o", "-"],
        vec!["generate", "-n", "300", "-o", "-"],
        vec!["generate", "-n", "3", "--json", "-o", path_arg(&json_dir)],
    ];
    if cfg!(mjcf_mujoco) {
        runs.push(vec!["compile", ARM]);
        runs.push(vec!["compile", ARM, "--json"]);
    }
    for args in &runs {
        let out = with_closed_stdout(args);
        assert_eq!(
            (out.status.code(), stderr(&out)),
            (Some(0), String::new()),
            "{args:?}"
        );
    }
    // The run whose summary could not be printed still wrote its folder whole.
    // (The demo's models refer to no file: no `assets/`.)
    assert_eq!(listing(&json_dir).len(), 3 + 1);
}

#[test]
fn info_speaks_to_a_person_unless_asked_for_json() {
    let out = forge(&["info", ARM, "--prefix", "a0_"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        stdout(&out),
        "model arm_with_keys (corpora/merge/arm_with_keys.xml), prefix 'a0_'
  root body          a0_base
  bodies (4)         a0_base a0_link1 a0_link2 a0_hand
  joints (3)         a0_j1 a0_j2 a0_j3
  actuators (2)      a0_a1 a0_a2
  sites (1)          a0_grip_site
  sensors (0)        -
  contact geoms (4)  a0_g0_col a0_g1_col a0_g2_col a0_g3_col
  visual geoms (0)   -
  base offset        0 0 0.1
  bottom offset      0 0 -0.05
  top offset         0 0 0.43
  horizontal radius  0.292332
"
    );
    let json = forge(&["info", ARM, "--prefix", "a0_", "--json"]);
    assert!(stdout(&json).starts_with("{\"name\": \"arm_with_keys\""));
}

#[test]
fn generate_shows_progress_on_long_runs_and_nothing_with_quiet() {
    let dir = scratch("cli_edges_progress");
    let run = |name: &str, extra: &[&str], every: Option<&str>| {
        let out_dir = dir.join(name);
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_mjcf-forge"));
        cmd.args(["generate", "-n", "400", "--threads", "1", "-o"])
            .arg(&out_dir)
            .args(extra)
            .current_dir(root());
        if let Some(every) = every {
            cmd.env("MJCF_FORGE_PROGRESS_SECONDS", every);
        }
        let out = cmd.output().unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        stderr(&out)
    };
    // Standard error is a pipe here: plain lines, then the summary.
    let err = run("lines", &[], Some("0.005"));
    let lines: Vec<&str> = err.lines().collect();
    assert!(lines.len() >= 2, "{err}");
    for line in &lines[..lines.len() - 1] {
        assert!(
            line.starts_with("generate: ") && line.contains("/400 written (made "),
            "{line}"
        );
        assert!(line.contains("/s, "), "{line}");
    }
    assert!(lines[lines.len() - 1].starts_with("generated 400 variants"));
    // `--quiet`: nothing at all.
    assert_eq!(run("quiet", &["--quiet"], Some("0.005")), "");
    // A run shorter than a second shows no progress, only its summary.
    let short = forge(&["generate", "-n", "2", "-o", path_arg(&dir.join("short"))]);
    assert_eq!(stderr(&short).lines().count(), 1, "{}", stderr(&short));
    if cfg!(mjcf_mujoco) {
        let err = run("validated", &["--validate"], Some("0.005"));
        let first = err.lines().next().unwrap();
        assert!(first.contains(", validated "), "{err}");
    }
}

#[test]
fn an_output_folder_is_never_mixed_with_a_previous_runs() {
    let dir = scratch("cli_edges_replace");
    let out = dir.join("variants");
    let generate = |n: &str, extra: &[&str]| {
        let mut args = vec!["generate", "-n", n, "-o", path_arg(&out)];
        args.extend_from_slice(extra);
        forge(&args)
    };
    assert!(generate("30", &[]).status.success());
    assert_eq!(listing(&out).len(), 30 + 1);
    // A second run is refused before it starts, and changes nothing.
    let refused = generate("10", &[]);
    assert_eq!(refused.status.code(), Some(1));
    let err = stderr(&refused);
    assert!(
        err.starts_with(&format!(
            "{}: the output folder is not empty (it holds '",
            out.display()
        )) && err
            .trim_end()
            .ends_with("'); add --replace to replace it whole, or choose another folder"),
        "{err}"
    );
    assert_eq!(listing(&out).len(), 30 + 1);
    // `--replace`: the new run's files only, and nothing left beside the folder.
    assert!(generate("10", &["--replace"]).status.success());
    let mut expected: Vec<String> = (0..10).map(|i| format!("{i:09}.xml")).collect();
    expected.push("manifest.jsonl".to_string());
    expected.sort();
    assert_eq!(listing(&out), expected);
    let manifest = std::fs::read_to_string(out.join("manifest.jsonl")).unwrap();
    assert_eq!(manifest.lines().count(), 10);
    assert_eq!(listing(&dir), ["variants"]);
    // Through a symlink: the link stays, its folder is replaced.
    #[cfg(unix)]
    {
        let link = dir.join("link");
        std::os::unix::fs::symlink("variants", &link).unwrap();
        let o = forge(&["generate", "-n", "4", "-o", path_arg(&link), "--replace"]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        assert_eq!(listing(&out).len(), 4 + 1);
        assert_eq!(listing(&dir), ["link", "variants"]);
    }
    // A failed run leaves nothing: not the folder, not its staging folder.
    let missing = dir.join("never");
    let o = forge(&["generate", "no/such/scene.toml", "-o", path_arg(&missing)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(!missing.exists());
}

#[test]
fn shards_share_their_folder_and_refuse_another_runs_files() {
    let dir = scratch("cli_edges_shards");
    let out = dir.join("run");
    let shard = |k: &str, extra: &[&str]| {
        let mut args = vec!["generate", "-n", "20", "--shard", k, "-o", path_arg(&out)];
        args.extend_from_slice(extra);
        forge(&args)
    };
    assert!(shard("0/2", &[]).status.success());
    assert!(shard("1/2", &[]).status.success());
    // Running a shard again is fine: the folder holds only the run's own files.
    assert!(shard("1/2", &[]).status.success());
    assert_eq!(listing(&out).len(), 20 + 2);
    std::fs::write(out.join("000000020.xml"), "another run's").unwrap();
    let o = shard("0/2", &[]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stderr(&o).trim_end(),
        format!(
            "{}: the output folder holds files that are not this run's ('000000020.xml'); the \
             shards of a run need a folder that is empty or holds only their own files",
            out.display()
        )
    );
    let o = shard("0/2", &["--replace"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--replace cannot be used with --shard"));
}

#[test]
fn export_refuses_a_folder_that_is_not_empty_and_replaces_it_whole() {
    let dir = scratch("cli_edges_export");
    let out = dir.join("moveable");
    let export = |extra: &[&str]| {
        let mut args = vec![
            "export",
            "corpora/scenes/demo/arm.xml",
            "-o",
            path_arg(&out),
        ];
        args.extend_from_slice(extra);
        forge(&args)
    };
    assert!(export(&[]).status.success());
    let first = listing(&out);
    std::fs::write(out.join("stale.xml"), "<mujoco/>").unwrap();
    let o = export(&[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("the output folder is not empty"));
    assert!(export(&["--replace"]).status.success());
    assert_eq!(listing(&out), first);
    assert_eq!(listing(&dir), ["moveable"]);
}

#[test]
fn a_part_merged_twice_is_one_message_with_the_fix() {
    let o = forge(&["merge", ARM, "--part", ARM]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stderr(&o).trim_end(),
        "corpora/merge/arm_with_keys.xml:4:5: duplicate names: all 12 names this part declares \
         are already in the model (body 'base' first at corpora/merge/arm_with_keys.xml:4:5, \
         body 'link1', joint 'j1', body 'link2', joint 'j2', and 7 more); is it merged twice, \
         or without a prefix of its own? give each instance its own name prefix"
    );
    assert!(stdout(&o).is_empty());
}

#[test]
fn a_missing_merge_target_says_what_was_meant() {
    let merge = |body: &str| {
        forge(&[
            "merge",
            ARM,
            "--part",
            &format!("{ARM}:a1_"),
            "--part",
            &format!("corpora/merge/gripper_radian.xml:g_:{body}"),
        ])
    };
    let o = merge("hnd");
    assert_eq!(
        stderr(&o).trim_end(),
        "corpora/merge/arm_with_keys.xml:2:1: merge target body 'hnd' is not in the base model \
         (did you mean 'hand'?)"
    );
    // The name without its instance's prefix.
    let o = forge(&[
        "merge",
        "corpora/scenes/demo/arena.xml",
        "--part",
        "corpora/scenes/demo/arm.xml:robot0_",
        "--part",
        "corpora/scenes/demo/gripper.xml:gripper0_:hand",
    ]);
    assert!(
        stderr(&o).trim_end().ends_with(
            "merge target body 'hand' is not in the base model (did you mean 'robot0_hand'?)"
        ),
        "{}",
        stderr(&o)
    );
    let o = merge("zzz");
    assert_eq!(
        stderr(&o).trim_end(),
        "corpora/merge/arm_with_keys.xml:2:1: merge target body 'zzz' is not in the base model"
    );
}

#[cfg(mjcf_mujoco)]
#[test]
fn validate_counts_what_it_compiled_and_what_it_patched() {
    let dir = scratch("cli_edges_validate");
    let o = forge(&[
        "generate",
        "-n",
        "12",
        "--threads",
        "1",
        "--validate",
        "--json",
        "-o",
        path_arg(&dir.join("v")),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    let compiled = summary["models_compiled"].as_u64().unwrap();
    let patched = summary["models_patched"].as_u64().unwrap();
    assert_eq!(compiled + patched, 12, "{summary}");
    let o = forge(&[
        "generate",
        "-n",
        "12",
        "--threads",
        "1",
        "--validate",
        "-o",
        path_arg(&dir.join("w")),
    ]);
    let err = stderr(&o);
    assert!(
        err.contains(&format!("compiled, {patched} patched from a compiled one)"))
            && !err.contains("the other variants"),
        "{err}"
    );
}
