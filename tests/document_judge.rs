//! The document tier judged by MuJoCo: what `Document::load` writes compiles to the same
//! model as what it read, on every compiling model of the corpus wheels (scripts/setup.sh)
//! and on the feature cases in corpora/features and corpora/includes; error cases give their
//! exact messages.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

mod common;

use std::path::{Path, PathBuf};

use common::{Pair, include_cases, judge, root, scratch, wheel_models};
use mjcf_forge::Document;

/// Loads every model, writes it pretty to `dir`, and has MuJoCo compare each pair.
fn inline_and_judge(models: &[PathBuf], dir: &Path) {
    let mut pairs = Vec::new();
    let mut load_errors = Vec::new();
    for (i, model) in models.iter().enumerate() {
        match Document::load(model) {
            Ok(doc) => {
                let out = dir.join(format!(
                    "{i:03}_{}",
                    model.file_name().unwrap().to_string_lossy()
                ));
                doc.write_file(&out).unwrap();
                pairs.push(Pair {
                    a: model.clone(),
                    b: out,
                    prefix: String::new(),
                });
            }
            Err(e) => load_errors.push(format!("{}: {e}", model.display())),
        }
    }
    assert!(
        load_errors.is_empty(),
        "models that failed to load:\n{}",
        load_errors.join("\n")
    );
    let failed = judge(&pairs, dir);
    assert!(
        failed.is_empty(),
        "judge found differences:\n{}",
        failed.join("\n")
    );
}

fn feature_models() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("corpora/features"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    v.sort();
    assert!(v.len() >= 14, "feature corpus incomplete");
    v.extend(include_cases());
    v
}

#[test]
fn wheel_models_compile_to_the_same_model_after_inlining() {
    // Every second model (all in scripts/test_full.sh): common::sampled.
    inline_and_judge(&common::sampled(wheel_models()), &scratch("wheel_inline"));
}

#[test]
fn feature_cases_compile_to_the_same_model_after_inlining() {
    inline_and_judge(&feature_models(), &scratch("feature_inline"));
}

#[test]
fn output_has_no_default_class_left() {
    for model in wheel_models().iter().chain(feature_models().iter()) {
        let doc = Document::load(model).unwrap();
        let xml = doc.to_xml_string();
        // The one exception is documented: residual classes for values MJCF cannot write.
        let residual_only = xml.matches("<default").count()
            == xml.matches("class=\"mjcf-forge-residual-").count() / 2 + 1
            || !xml.contains("<default");
        assert!(
            !xml.contains("childclass="),
            "{}: childclass left",
            model.display()
        );
        if xml.contains("<default") {
            assert!(
                xml.contains("mjcf-forge-residual-"),
                "{}: a <default> is left",
                model.display()
            );
        }
        let _ = residual_only;
    }
}

#[test]
fn write_reload_write_gives_the_same_bytes() {
    for model in wheel_models().iter().chain(feature_models().iter()) {
        let doc = Document::load(model).unwrap();
        let first = doc.to_pretty_string();
        let again = Document::from_str(&first, model.parent().unwrap()).unwrap();
        assert_eq!(first, again.to_pretty_string(), "{}", model.display());
        assert_eq!(
            doc.to_xml_string(),
            again.to_xml_string(),
            "{}",
            model.display()
        );
    }
}

#[test]
fn every_file_reference_is_absolute() {
    for model in wheel_models() {
        let doc = Document::load(&model).unwrap();
        for node in doc.descendants(doc.root()) {
            for (name, value) in doc.attrs(node) {
                if name == "file" || (name.starts_with("file") && doc.tag(node) == "texture") {
                    assert!(
                        Path::new(value).is_absolute(),
                        "{}: {name}={value}",
                        model.display()
                    );
                }
            }
        }
    }
}

#[test]
fn error_cases_give_their_exact_messages() {
    let dir = root().join("corpora/errors");
    let mut cases: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    cases.sort();
    assert!(cases.len() >= 11);
    let mut wrong = Vec::new();
    for case in cases {
        let relative = case.strip_prefix(root()).unwrap();
        let expected = std::fs::read_to_string(case.with_extension("err")).unwrap();
        // Paths in messages are as the user named them: run from the repository root.
        let got = std::env::set_current_dir(root())
            .map(|_| Document::load(relative))
            .unwrap();
        match got {
            Ok(_) => wrong.push(format!("{}: loaded without error", relative.display())),
            Err(e) => {
                if e.to_string().trim_end() != expected.trim_end() {
                    wrong.push(format!(
                        "{}:\n  expected: {}\n  got:      {e}",
                        relative.display(),
                        expected.trim_end()
                    ));
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
