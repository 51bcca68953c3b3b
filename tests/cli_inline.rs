//! `mjcf-forge inline` as a user runs it: outputs, exit codes, messages, and the promise
//! that a failure never leaves a partial, clobbered or temporary file behind.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

mod common;

use std::path::{Path, PathBuf};

use common::{forge, listing, path_arg, root, scratch, stderr, stdout};
use mjcf_forge::Document;

fn feature_models() -> Vec<PathBuf> {
    let mut models: Vec<PathBuf> = std::fs::read_dir(root().join("corpora/features"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    models.sort();
    assert!(
        models.len() >= 10,
        "corpora/features has {} models",
        models.len()
    );
    models
}

/// The error cases, relative to the repository root (as their .err files name them).
fn error_cases() -> Vec<PathBuf> {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(root().join("corpora/errors"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .map(|p| p.strip_prefix(root()).unwrap().to_path_buf())
        .collect();
    cases.sort();
    assert!(
        cases.len() >= 11,
        "corpora/errors has {} cases",
        cases.len()
    );
    cases
}

fn expected_error(case: &Path) -> String {
    let text = std::fs::read_to_string(root().join(case).with_extension("err")).unwrap();
    text.trim_end().to_owned()
}

const MODEL: &str = "corpora/features/default_childclass.xml";

#[test]
fn output_file_gets_the_pretty_document() {
    let dir = scratch("cli_inline_output_file");
    let out_path = dir.join("out.xml");
    let out = forge(&["inline", MODEL, "-o", path_arg(&out_path)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "");
    assert_eq!(stderr(&out), "");
    let expected = Document::load(root().join(MODEL))
        .unwrap()
        .to_pretty_string();
    assert_eq!(std::fs::read_to_string(&out_path).unwrap(), expected);
    assert_eq!(listing(&dir), ["out.xml"], "temporary files left behind");

    // Writing over an existing file replaces it whole.
    std::fs::write(&out_path, "old content that is longer than nothing").unwrap();
    let out = forge(&[
        "inline",
        MODEL,
        "--output",
        path_arg(&out_path),
        "--compact",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let compact = Document::load(root().join(MODEL)).unwrap().to_xml_string();
    assert_eq!(std::fs::read_to_string(&out_path).unwrap(), compact);
    assert_eq!(listing(&dir), ["out.xml"]);
}

#[test]
fn without_output_the_document_goes_to_stdout() {
    let doc = Document::load(root().join(MODEL)).unwrap();
    let out = forge(&["inline", MODEL]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), doc.to_pretty_string());
    assert_eq!(stderr(&out), "");

    let out = forge(&["inline", "--compact", MODEL]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), doc.to_xml_string());
}

#[test]
fn out_dir_writes_one_file_per_input_named_after_it() {
    let dir = scratch("cli_inline_out_dir");
    let out_dir = dir.join("made/by/the/tool");
    let models = feature_models();
    let mut args: Vec<&str> = vec!["inline", "--out-dir", path_arg(&out_dir)];
    args.extend(models.iter().map(|p| path_arg(p)));
    // The same input again, once verbatim and once spelled differently, is done once.
    let respelled = root()
        .join("corpora/features/../features")
        .join(models[0].file_name().unwrap());
    args.push(path_arg(&models[0]));
    args.push(path_arg(&respelled));
    let out = forge(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "");

    let mut expected_names: Vec<String> = models
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    expected_names.sort();
    assert_eq!(
        listing(&out_dir),
        expected_names,
        "one output per input, nothing else"
    );
    for model in &models {
        let written = std::fs::read_to_string(out_dir.join(model.file_name().unwrap())).unwrap();
        let expected = Document::load(model).unwrap().to_pretty_string();
        assert_eq!(written, expected, "{}", model.display());
    }
}

#[test]
fn two_inputs_with_one_file_name_are_refused_before_anything_is_written() {
    let dir = scratch("cli_inline_name_clash");
    for sub in ["a", "b"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        std::fs::copy(root().join(MODEL), dir.join(sub).join("model.xml")).unwrap();
    }
    let out_dir = dir.join("out");
    let a = dir.join("a/model.xml");
    let b = dir.join("b/model.xml");
    let other = root().join("corpora/features/include_nested.xml");
    let out = forge(&[
        "inline",
        "--out-dir",
        path_arg(&out_dir),
        path_arg(&other),
        path_arg(&a),
        path_arg(&b),
    ]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with(&format!("{}: ", b.display())), "{err}");
    assert!(err.contains(&a.display().to_string()), "{err}");
    assert!(
        !out_dir.exists(),
        "an output folder was made despite the clash"
    );
}

#[test]
fn several_inputs_need_an_out_dir() {
    let out = forge(&["inline", MODEL, "corpora/features/include_nested.xml"]);
    assert!(!out.status.success());
    assert_eq!(stdout(&out), "");
    assert!(stderr(&out).contains("--out-dir"), "{}", stderr(&out));
}

#[test]
fn each_error_case_prints_its_exact_message() {
    for case in error_cases() {
        let out = forge(&["inline", path_arg(&case)]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{}: {err}", case.display());
        assert_eq!(stdout(&out), "", "{}", case.display());
        assert_eq!(err.trim_end(), expected_error(&case), "{}", case.display());
        for line in err.lines() {
            assert_file_line_col(line);
        }
    }
}

#[test]
fn out_dir_reports_every_failed_input_in_input_order_and_writes_the_rest() {
    let dir = scratch("cli_inline_out_dir_errors");
    let cases = error_cases();
    let mut args: Vec<&str> = vec!["inline", "--out-dir", path_arg(&dir)];
    args.extend(cases.iter().map(|p| path_arg(p)));
    args.push(MODEL);
    let out = forge(&args);
    assert_eq!(out.status.code(), Some(1));
    let expected: Vec<String> = cases.iter().map(|c| expected_error(c)).collect();
    assert_eq!(stderr(&out).trim_end(), expected.join("\n"));
    assert_eq!(listing(&dir), ["default_childclass.xml"]);
}

/// `file:line:col: message`, where `file` may itself hold colons only if it is a path.
fn assert_file_line_col(line: &str) {
    let mut parts = line.splitn(4, ':');
    let (file, l, c, rest) = (parts.next(), parts.next(), parts.next(), parts.next());
    assert!(
        file.is_some_and(|f| !f.is_empty())
            && l.is_some_and(|l| l.parse::<u32>().is_ok())
            && c.is_some_and(|c| c.parse::<u32>().is_ok())
            && rest.is_some_and(|r| r.starts_with(' ') && r.len() > 1),
        "not `file:line:col: message`: {line}"
    );
}

#[test]
fn garbage_inputs_fail_cleanly() {
    let dir = scratch("cli_inline_garbage");
    // Deterministic junk: bytes of a simple LCG, including NUL and invalid UTF-8.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let junk: Vec<u8> = (0..4096)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            (state >> 56) as u8
        })
        .collect();
    std::fs::write(dir.join("junk.xml"), &junk).unwrap();
    let mut tagged = b"<mujoco><worldbody>".to_vec();
    tagged.extend_from_slice(&junk);
    std::fs::write(dir.join("junk_inside.xml"), &tagged).unwrap();
    std::fs::write(dir.join("empty.xml"), "").unwrap();
    std::fs::write(dir.join("spaces.xml"), "  \n\t\n").unwrap();
    std::fs::write(dir.join("unclosed.xml"), "<mujoco><worldbody>").unwrap();
    std::fs::write(dir.join("text_only.xml"), "just words").unwrap();
    std::fs::create_dir_all(dir.join("a_folder.xml")).unwrap();
    let inputs = [
        "junk.xml",
        "junk_inside.xml",
        "empty.xml",
        "spaces.xml",
        "unclosed.xml",
        "text_only.xml",
        "a_folder.xml",
        "does_not_exist.xml",
    ];
    for name in inputs {
        let input = dir.join(name);
        let out_path = dir.join("out").join(name);
        std::fs::create_dir_all(dir.join("out")).unwrap();
        for args in [
            vec!["inline", path_arg(&input)],
            vec!["inline", path_arg(&input), "-o", path_arg(&out_path)],
        ] {
            let out = forge(&args);
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(1), "{name}: {err}");
            assert!(!err.contains("panicked"), "{name}: {err}");
            assert!(!err.trim().is_empty(), "{name}: no message");
            assert!(
                err.contains(path_arg(&input)),
                "{name}: message does not name the file: {err}"
            );
            assert_eq!(stdout(&out), "", "{name}");
        }
        assert!(
            listing(&dir.join("out")).is_empty(),
            "{name}: output written"
        );
    }
    let mut args: Vec<&str> = vec!["inline", "--out-dir"];
    let out_dir = dir.join("out_dir");
    args.push(path_arg(&out_dir));
    let paths: Vec<PathBuf> = inputs.iter().map(|n| dir.join(n)).collect();
    args.extend(paths.iter().map(|p| path_arg(p)));
    let out = forge(&args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        err.lines().count(),
        inputs.len(),
        "one line per bad input: {err}"
    );
    assert!(listing(&out_dir).is_empty());
}

#[test]
fn a_failed_load_keeps_the_old_output_and_leaves_no_temporary_file() {
    let dir = scratch("cli_inline_no_clobber");
    let out_path = dir.join("model.xml");
    std::fs::write(&out_path, "previous output\n").unwrap();
    for case in error_cases() {
        let out = forge(&["inline", path_arg(&case), "-o", path_arg(&out_path)]);
        assert_eq!(out.status.code(), Some(1), "{}", case.display());
        assert_eq!(
            std::fs::read_to_string(&out_path).unwrap(),
            "previous output\n"
        );
        assert_eq!(listing(&dir), ["model.xml"], "{}", case.display());
    }

    // The same through --out-dir: the bad input's old output stays, the good one is
    // replaced, nothing else appears.
    let bad_dir = dir.join("bad");
    std::fs::create_dir_all(&bad_dir).unwrap();
    let bad = bad_dir.join("model.xml");
    std::fs::write(
        &bad,
        "<mujoco><worldbody><geom class='nope'/></worldbody></mujoco>",
    )
    .unwrap();
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    std::fs::write(out_dir.join("model.xml"), "old model\n").unwrap();
    std::fs::write(out_dir.join("include_nested.xml"), "old nested\n").unwrap();
    let good = root().join("corpora/features/include_nested.xml");
    let out = forge(&[
        "inline",
        "--out-dir",
        path_arg(&out_dir),
        path_arg(&bad),
        path_arg(&good),
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert_eq!(
        std::fs::read_to_string(out_dir.join("model.xml")).unwrap(),
        "old model\n"
    );
    assert_eq!(
        std::fs::read_to_string(out_dir.join("include_nested.xml")).unwrap(),
        Document::load(&good).unwrap().to_pretty_string()
    );
    assert_eq!(listing(&out_dir), ["include_nested.xml", "model.xml"]);
}

#[test]
fn an_unwritable_output_is_an_error_not_a_panic() {
    let dir = scratch("cli_inline_unwritable");
    let target = dir.join("no/such/folder/out.xml");
    let out = forge(&["inline", MODEL, "-o", path_arg(&target)]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("cannot write"), "{err}");

    // An output path that is a folder.
    let out = forge(&["inline", MODEL, "-o", path_arg(&dir)]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(!stderr(&out).contains("panicked"));
    assert!(
        listing(&dir).is_empty(),
        "temporary files left behind: {:?}",
        listing(&dir)
    );
}

/// A build without MuJoCo says so, and `--validate` then writes nothing.
#[cfg(not(mjcf_mujoco))]
#[test]
fn compile_and_validate_need_the_mujoco_feature() {
    const MESSAGE: &str = "built without the `mujoco` feature; rebuild with --features mujoco";
    let dir = scratch("cli_inline_no_mujoco");
    let out_path = dir.join("out.xml");
    for args in [
        vec!["compile", MODEL],
        vec!["compile", "--json", MODEL],
        vec!["inline", "--validate", MODEL],
        vec!["inline", "--validate", MODEL, "-o", path_arg(&out_path)],
        vec!["inline", "--validate", "--out-dir", path_arg(&dir), MODEL],
    ] {
        let out = forge(&args);
        assert!(!out.status.success(), "{args:?}");
        assert!(stderr(&out).contains(MESSAGE), "{args:?}: {}", stderr(&out));
        assert_eq!(stdout(&out), "", "{args:?}");
    }
    assert!(listing(&dir).is_empty());
}
