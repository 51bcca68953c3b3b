//! The model store (`split::DiskStore`) with the linked MuJoCo (feature `mujoco`): what a
//! face stores, MuJoCo's binary model (`CompiledModel::to_bytes`), loads back to the model
//! the compile gave, bit for bit in every array and size (`CompiledModel::differences`), for
//! a sample of the wheel corpus (every fifth model of `.cache/corpus/models.txt`: robots with
//! meshes and textures, muscles, height fields) and the scenes' variants; and through a
//! store: written, read back, loaded, the same model.
//!
//! Pass: once per MuJoCo the feature `mujoco` links (scripts/test.sh: 3.17.0 and 4.0.0).

#![cfg(mjcf_mujoco)]

use std::path::PathBuf;

use mjcf_forge::Document;
use mjcf_forge::mujoco::{CompiledModel, compile_document};
use mjcf_forge::scene::Scene;
use mjcf_forge::split::{DiskStore, StoreKey, split_document};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `model` through MuJoCo's binary format, and what differs from it afterwards.
fn round_trip(model: &CompiledModel) -> Vec<String> {
    let back = CompiledModel::from_bytes(&model.to_bytes()).expect("MuJoCo reads its own MJB");
    back.differences(model)
}

#[test]
fn the_binary_model_loads_to_the_compile_for_a_sample_of_the_corpus() {
    let list = root().join(".cache/corpus/models.txt");
    let text = std::fs::read_to_string(&list).expect("run scripts/setup.sh first");
    let (mut checked, mut differing) = (0, Vec::new());
    for line in text.lines().step_by(5) {
        let Ok(doc) = Document::load(root().join(line)) else {
            continue; // the corpus test judges what we cannot load
        };
        let Ok(model) = compile_document(&doc) else {
            continue;
        };
        let diffs = round_trip(&model);
        if !diffs.is_empty() {
            differing.push(format!("{line}: {:?}", &diffs[..diffs.len().min(3)]));
        }
        checked += 1;
    }
    assert!(checked >= 35, "only {checked} models checked");
    assert!(differing.is_empty(), "{}", differing.join("\n"));
}

#[test]
fn a_stored_variant_loads_to_its_compile() {
    let dir = tempfile::tempdir().unwrap();
    let store = DiskStore::open(dir.path(), 1 << 30).unwrap();
    for scene in ["lift5_fixed.toml", "lift5.toml"] {
        let scene = Scene::load(root().join("benches/scenes").join(scene)).unwrap();
        for i in [0, 7] {
            let doc = scene.variant(i).unwrap().document;
            let model = compile_document(&doc).unwrap();
            let mut key = StoreKey::new(&split_document(&doc).structure_key, "linked");
            for file in doc.files() {
                key.file(&file).unwrap();
            }
            let key = key.finish();
            store.put(&key, &model.to_bytes()).unwrap();
            let bytes = store.get(&key).unwrap().expect("just stored");
            let back = CompiledModel::from_bytes(&bytes).unwrap();
            assert_eq!(
                back.differences(&model),
                Vec::<String>::new(),
                "variant {i}"
            );
        }
    }
    assert!(!store.entries().unwrap().is_empty());
}
