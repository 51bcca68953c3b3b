//! The validation pass on real models: every compiling wheel model validates cleanly, also
//! after prefixing; the error corpus for names gives its exact messages.

mod common;

use common::{root, wheel_models};
use mjcf_forge::Document;

#[test]
fn compiling_models_have_no_duplicate_or_dangling_name() {
    let mut bad = Vec::new();
    for model in wheel_models() {
        let mut doc = Document::load(&model).unwrap();
        if let Err(e) = doc.validate() {
            bad.push(format!("{}:\n{e}", model.display()));
        }
        doc.apply_prefix("v_").unwrap();
        if let Err(e) = doc.validate() {
            bad.push(format!("{} (prefixed):\n{e}", model.display()));
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn name_errors_are_all_reported_with_positions() {
    std::env::set_current_dir(root()).unwrap();
    let path = "corpora/errors/names/duplicates_and_dangling.xml";
    let doc = Document::load(path).unwrap();
    let errors = doc.validate().unwrap_err();
    let expected =
        std::fs::read_to_string(root().join("corpora/errors/names/duplicates_and_dangling.err"))
            .unwrap();
    assert_eq!(errors.to_string().trim_end(), expected.trim_end());
}
