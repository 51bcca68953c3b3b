//! The model-tier commands: `prefix`, `merge` and `info`, run as a user would.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

mod common;

use std::process::Command;

use common::{Pair, forge, judge, root, scratch};

#[test]
fn prefix_writes_a_model_that_compiles_the_same_with_prefixed_names() {
    let dir = scratch("cli_prefix");
    let out = dir.join("refs.xml");
    let o = forge(&[
        "prefix",
        "corpora/prefix/references_everywhere.xml",
        "--prefix",
        "r1_",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let failed = judge(
        &[Pair {
            a: root().join("corpora/prefix/references_everywhere.xml"),
            b: out,
            prefix: "r1_".into(),
        }],
        &dir,
    );
    assert!(failed.is_empty(), "{failed:?}");
}

#[test]
fn merge_parses_parts_and_reports_a_missing_body() {
    let o = forge(&[
        "merge",
        "corpora/merge/arm_with_keys.xml",
        "--part",
        "corpora/merge/gripper_radian.xml:g_:nobody",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim_end(),
        "corpora/merge/arm_with_keys.xml:2:1: merge target body 'nobody' is not in the base model"
    );
    assert!(o.stdout.is_empty());
}

#[test]
fn merge_refuses_a_name_clash_in_one_line_per_part() {
    // The same part twice without prefixes: every name of the second copy clashes, which
    // is said once, with the fix (tests/cli_edges.rs has the whole message).
    let o = forge(&[
        "merge",
        "corpora/merge/arm_with_keys.xml",
        "--part",
        "corpora/merge/arm_with_keys.xml",
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("body 'base' first at corpora/merge/arm_with_keys.xml:4:5"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn merge_output_keeps_the_parts() {
    let dir = scratch("cli_merge");
    let out = dir.join("scene.xml");
    let o = forge(&[
        "merge",
        "corpora/merge/arm_with_keys.xml",
        "--part",
        "corpora/merge/gripper_radian.xml:g_:hand",
        "--part",
        "corpora/merge/free_objects_with_key.xml:obj_",
        "--fuse-keys",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let xml = std::fs::read_to_string(&out).unwrap();
    assert!(xml.contains("<body name=\"g_palm\""));
    assert!(xml.contains("<key name=\"home\""));
    assert!(
        !xml.contains("name=\"g_home\""),
        "the part's home key is fused into the scene's"
    );
    let cases = format!(
        "[{{\"merged\": \"{}\", \"base\": \"corpora/merge/arm_with_keys.xml\", \"parts\": [{{\"path\": \"corpora/merge/gripper_radian.xml\", \"prefix\": \"g_\", \"body\": \"hand\"}}, {{\"path\": \"corpora/merge/free_objects_with_key.xml\", \"prefix\": \"obj_\", \"body\": null}}], \"fused\": {{\"home\": [\"\", \"g_\"]}}}}]",
        out.display()
    );
    let file = dir.join("cases.json");
    std::fs::write(&file, cases).unwrap();
    let j = Command::new(common::python())
        .current_dir(root())
        .arg("tests/judge/merge_judge.py")
        .arg("--cases")
        .arg(&file)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&j.stdout);
    assert!(
        j.status.success() && stdout.trim_end().ends_with("1 passed, 0 failed"),
        "{stdout}"
    );
}

#[test]
fn info_lists_the_model_tier_view() {
    let o = forge(&[
        "info",
        "corpora/merge/arm_with_keys.xml",
        "--prefix",
        "a0_",
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json = String::from_utf8_lossy(&o.stdout);
    for expected in [
        "\"root_body\": \"a0_base\"",
        "\"bodies\": [\"a0_base\", \"a0_link1\", \"a0_link2\", \"a0_hand\"]",
        "\"joints\": [\"a0_j1\", \"a0_j2\", \"a0_j3\"]",
        "\"actuators\": [\"a0_a1\", \"a0_a2\"]",
        "\"sites\": [\"a0_grip_site\"]",
        "\"contact_geoms\": [\"a0_g0_col\", \"a0_g1_col\", \"a0_g2_col\", \"a0_g3_col\"]",
        "\"base_offset\": [0, 0, 0.1]",
        "\"bottom_offset\": [0, 0, -0.05]",
    ] {
        assert!(json.contains(expected), "{expected} not in {json}");
    }
    let o = forge(&["info", "corpora/merge/free_objects_with_key.xml", "--json"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&o.stderr)
            .contains("expected exactly one top-level body in <worldbody>, found 3")
    );
}
