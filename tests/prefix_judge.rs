//! Prefixing judged by MuJoCo: every compiling wheel model and every feature and include case,
//! prefixed, compiles to the same model with every name = prefix + name.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

mod common;

use std::path::PathBuf;

use common::{Pair, include_cases, judge, root, scratch, wheel_models};
use mjcf_forge::Document;

fn prefix_and_judge(models: &[PathBuf], dir: &std::path::Path, prefix: &str) {
    let mut pairs = Vec::new();
    for (i, model) in models.iter().enumerate() {
        let mut doc = Document::load(model).unwrap_or_else(|e| panic!("{}: {e}", model.display()));
        doc.apply_prefix(prefix).unwrap();
        let out = dir.join(format!(
            "{i:03}_{}",
            model.file_name().unwrap().to_string_lossy()
        ));
        doc.write_file(&out).unwrap();
        pairs.push(Pair {
            a: model.clone(),
            b: out,
            prefix: prefix.to_string(),
        });
    }
    let failed = judge(&pairs, dir);
    assert!(
        failed.is_empty(),
        "judge found differences:\n{}",
        failed.join("\n")
    );
}

#[test]
fn wheel_models_prefixed_compile_to_the_same_model() {
    // Every second model (all in scripts/test_full.sh): common::sampled.
    prefix_and_judge(
        &common::sampled(wheel_models()),
        &scratch("wheel_prefix"),
        "p0_",
    );
}

#[test]
fn feature_cases_prefixed_compile_to_the_same_model() {
    let mut models: Vec<PathBuf> = std::fs::read_dir(root().join("corpora/features"))
        .unwrap()
        .chain(std::fs::read_dir(root().join("corpora/prefix")).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    models.sort();
    models.extend(include_cases());
    prefix_and_judge(&models, &scratch("feature_prefix"), "robot1/");
}

/// What prefixing refuses (`corpora/errors/prefix/*.xml`, prefix `p_`): each case's exact
/// message is its `.err` file.
#[test]
fn prefix_error_cases_give_their_exact_messages() {
    let dir = root().join("corpora/errors/prefix");
    let mut cases: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    cases.sort();
    assert!(!cases.is_empty());
    let mut wrong = Vec::new();
    for case in cases {
        let relative = case.strip_prefix(root()).unwrap();
        let expected = std::fs::read_to_string(case.with_extension("err")).unwrap();
        // Paths in messages are as the user named them: run from the repository root.
        std::env::set_current_dir(root()).unwrap();
        let mut doc = Document::load(relative).unwrap();
        match doc.apply_prefix("p_") {
            Ok(()) => wrong.push(format!("{}: prefixed without error", relative.display())),
            Err(e) if e.to_string().trim_end() != expected.trim_end() => wrong.push(format!(
                "{}:\n  expected: {}\n  got:      {e}",
                relative.display(),
                expected.trim_end()
            )),
            Err(_) => {}
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
