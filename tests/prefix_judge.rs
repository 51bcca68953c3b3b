//! Prefixing judged by MuJoCo: every compiling wheel model and every feature and include case,
//! prefixed, compiles to the same model with every name = prefix + name.

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
    prefix_and_judge(&wheel_models(), &scratch("wheel_prefix"), "p0_");
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
