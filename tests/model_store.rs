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
use mjcf_forge::compiled::DocumentCache;
use mjcf_forge::mujoco::{CompiledModel, compile_document};
use mjcf_forge::scene::Scene;
use mjcf_forge::split::{DiskStore, StoreKey, split_document};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `model` through MuJoCo's binary format, and what differs from it afterwards.
fn round_trip(model: &CompiledModel) -> Vec<String> {
    let back = CompiledModel::from_bytes(&model.to_bytes()).expect("MuJoCo reads its own MJB");
    let mut diffs = back.differences(model);
    if back.signature() != model.signature() {
        diffs.push(format!(
            "signature {} != {}",
            back.signature(),
            model.signature()
        ));
    }
    diffs
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
            assert_eq!(back.signature(), model.signature(), "variant {i}");
            assert_eq!(
                back.differences(&model),
                Vec::<String>::new(),
                "variant {i}"
            );
        }
    }
    assert!(!store.entries().unwrap().is_empty());
}

#[test]
fn a_new_cache_loads_what_another_stored_and_patches_it_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let store = || DiskStore::open(dir.path(), 1 << 30).unwrap();
    let scene = Scene::load(root().join("benches/scenes/lift5_fixed.toml")).unwrap();
    let docs: Vec<Document> = (0..4).map(|i| scene.variant(i).unwrap().document).collect();
    let want: Vec<CompiledModel> = docs.iter().map(|d| compile_document(d).unwrap()).collect();
    let mut first = DocumentCache::new(4, None).with_store(store());
    first.model(&docs[0]).unwrap();
    assert_eq!((first.compiles(), first.loads()), (1, 0));
    // Another process, as far as the store is concerned: a cache of its own.
    let mut second = DocumentCache::new(4, None).with_store(store());
    for (doc, want) in docs.iter().zip(&want).rev() {
        let got = second.model(doc).unwrap();
        assert_eq!(got.signature(), want.signature());
        assert_eq!(got.differences(want), Vec::<String>::new());
    }
    assert_eq!((second.compiles(), second.loads()), (1, 1));
    // A corrupt entry is not loaded: compiled (and stored again), exact.
    for e in store().entries().unwrap() {
        let path = dir.path().join(format!("{}.mjfs", e.key));
        let mut bytes = std::fs::read(&path).unwrap();
        bytes.truncate(bytes.len() / 2);
        std::fs::write(&path, bytes).unwrap();
    }
    let mut third = DocumentCache::new(4, None).with_store(store());
    assert_eq!(
        third.model(&docs[2]).unwrap().differences(&want[2]),
        Vec::<String>::new()
    );
    assert_eq!((third.compiles(), third.loads()), (1, 0));
    let mut fourth = DocumentCache::new(4, None).with_store(store());
    fourth.model(&docs[1]).unwrap();
    assert_eq!(fourth.loads(), 1, "the recompiled model was stored again");
}

#[test]
fn a_changed_mesh_under_a_stored_structure_is_a_miss() {
    let work = tempfile::tempdir().unwrap();
    let mesh = work.path().join("box.obj");
    let obj = |s: f64| {
        let mut t = String::new();
        for (x, y, z) in [(0., 0., 0.), (1., 0., 0.), (0., 1., 0.), (0., 0., 1.)] {
            t += &format!("v {} {} {}\n", x * s, y * s, z * s);
        }
        t + "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
    };
    let xml = "<mujoco><asset><mesh name='m' file='box.obj'/></asset><worldbody><body>\
               <freejoint/><geom type='mesh' mesh='m'/></body></worldbody></mujoco>";
    let store_dir = tempfile::tempdir().unwrap();
    let store = || DiskStore::open(store_dir.path(), 1 << 30).unwrap();
    std::fs::write(&mesh, obj(1.0)).unwrap();
    let doc = Document::from_str(xml, work.path()).unwrap();
    DocumentCache::new(2, None)
        .with_store(store())
        .model(&doc)
        .unwrap();
    std::fs::write(&mesh, obj(2.0)).unwrap();
    let want = compile_document(&doc).unwrap();
    let mut cache = DocumentCache::new(2, None).with_store(store());
    let got = cache.model(&doc).unwrap();
    assert_eq!(got.differences(&want), Vec::<String>::new());
    assert_eq!(
        (cache.compiles(), cache.loads()),
        (1, 0),
        "a stale model was loaded"
    );
    assert_eq!(store().entries().unwrap().len(), 2);
}

#[test]
fn the_command_line_tells_and_clears_the_store() {
    let dir = tempfile::tempdir().unwrap();
    let store = DiskStore::open(dir.path(), 1 << 20).unwrap();
    let key = StoreKey::new("structure", "test").finish();
    store.put(&key, &[7; 1000]).unwrap();
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_mjcf-forge"))
            .arg("store")
            .arg("--dir")
            .arg(dir.path())
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    assert!(run(&[]).contains(": 1 entries, 0.0 MB"), "{}", run(&[]));
    assert!(run(&["list"]).starts_with(&key));
    assert!(run(&["clear"]).contains("1 entries removed"));
    assert!(store.entries().unwrap().is_empty());
    let off = std::process::Command::new(env!("CARGO_BIN_EXE_mjcf-forge"))
        .args(["store"])
        .env("MJCF_FORGE_STORE", "off")
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&off.stdout).starts_with("no model store"));
}

#[test]
fn a_model_cache_loads_a_structure_another_stored_and_patches_each_variant() {
    use mjcf_forge::compiled::ModelCache;
    use mjcf_forge::mujoco::compile_str;

    let scene = Scene::load(root().join("benches/scenes/lift5_fixed.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let store = || DiskStore::open(dir.path(), 1 << 30).unwrap();
    let mut first = ModelCache::new(&scene, 4, None).with_store(store());
    first.model(0).unwrap();
    assert_eq!((first.compiles(), first.loads()), (1, 0));
    // A new cache knows nothing of the first but the store, as a new process would.
    let mut second = ModelCache::new(&scene, 4, None).with_store(store());
    for i in [2, 1, 3] {
        let xml = scene.variant_xml(i).unwrap().0;
        let want = compile_str(&xml, scene.template().model_dir()).unwrap();
        let diffs = second.model(i).unwrap().differences(&want);
        assert!(
            diffs.is_empty(),
            "variant {i}: {:?}",
            &diffs[..diffs.len().min(3)]
        );
    }
    assert_eq!((second.compiles(), second.loads()), (1, 1));
    // apply() on a cache that never compiled: the structure loaded, the model patched.
    let mut third = ModelCache::new(&scene, 4, None).with_store(store());
    let mut own = compile_str(
        &scene.variant_xml(0).unwrap().0,
        scene.template().model_dir(),
    )
    .unwrap();
    third.apply(3, &mut own).unwrap();
    let want = compile_str(
        &scene.variant_xml(3).unwrap().0,
        scene.template().model_dir(),
    )
    .unwrap();
    assert!(own.differences(&want).is_empty());
    assert_eq!(third.loads(), 1);
}
