//! The output module as the batch tier uses it: one `AssetStore` shared by threads, many
//! documents written as a WebDataset-style tar stream (assets once, then `NNNNNNNNN.xml`
//! and `NNNNNNNNN.json` per sample) or into one folder by several "shards" at once; MuJoCo
//! judges what comes out.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

mod common;

use std::process::Command;

use common::{Pair, judge, path_arg, python, root, scratch};
use mjcf_forge::{AssetStore, Document, OutputDir, TarWriter};
use rayon::prelude::*;

const MODELS: [&str; 4] = [
    ".cache/corpus/robosuite-1.5.2/robosuite/models/assets/robots/panda/robot.xml",
    ".cache/corpus/robosuite-1.5.2/robosuite/models/assets/grippers/panda_gripper.xml",
    ".cache/corpus/robosuite-1.5.2/robosuite/models/assets/arenas/table_arena.xml",
    ".cache/corpus/dm_control-1.0.50/dm_control/mjcf/test_assets/model_with_assetdir.xml",
];

/// Every model loaded and relocated in parallel into one store; the XML of each.
fn relocated(store: &AssetStore) -> Vec<String> {
    MODELS
        .par_iter()
        .map(|m| {
            let mut doc = Document::load(root().join(m)).unwrap();
            doc.relocate_assets(store).unwrap();
            doc.to_pretty_string()
        })
        .collect()
}

fn stream(store: &AssetStore, xmls: &[String]) -> Vec<u8> {
    let mut tar = TarWriter::new(Vec::new(), "shard.tar");
    store.write_to_tar(&mut tar).unwrap();
    for (i, xml) in xmls.iter().enumerate() {
        tar.append(&format!("{i:09}.xml"), xml.as_bytes()).unwrap();
        let json = format!("{{\"index\": {i}, \"model\": \"{}\"}}", MODELS[i]);
        tar.append(&format!("{i:09}.json"), json.as_bytes())
            .unwrap();
    }
    tar.finish().unwrap()
}

#[test]
fn a_webdataset_stream_is_read_by_python_and_every_sample_compiles() {
    let dir = scratch("output_stream_tar");
    let store = AssetStore::new();
    let xmls = relocated(&store);
    let bytes = stream(&store, &xmls);
    // Another store, the models relocated in another order: the same bytes.
    let again = AssetStore::new();
    for m in MODELS.iter().rev() {
        let mut doc = Document::load(root().join(m)).unwrap();
        doc.relocate_assets(&again).unwrap();
    }
    assert_eq!(
        stream(&again, &xmls),
        bytes,
        "the stream depends on the order files were seen"
    );

    let tar = dir.join("shard-000000.tar");
    std::fs::write(&tar, &bytes).unwrap();
    let extracted = dir.join("extracted");
    let check = r#"
import json, sys, tarfile
with tarfile.open(sys.argv[1]) as t:
    names = t.getnames()
    n = int(sys.argv[3])
    assets = [x for x in names if x.startswith("assets/")]
    assert names[:len(assets)] == assets and len(set(assets)) == len(assets), names
    samples = names[len(assets):]
    assert samples == [f"{i:09}.{e}" for i in range(n) for e in ("xml", "json")], samples
    for i in range(n):
        assert json.load(t.extractfile(f"{i:09}.json"))["index"] == i
    t.extractall(sys.argv[2], filter="data")
print(len(assets))
"#;
    let out = Command::new(python())
        .args(["-c", check, path_arg(&tar), path_arg(&extracted)])
        .arg(MODELS.len().to_string())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let assets: usize = String::from_utf8_lossy(&out.stdout).trim().parse().unwrap();
    assert_eq!(assets, store.len());
    let pairs: Vec<Pair> = MODELS
        .iter()
        .enumerate()
        .map(|(i, m)| Pair {
            a: root().join(m),
            b: extracted.join(format!("{i:09}.xml")),
            prefix: String::new(),
        })
        .collect();
    let failed = judge(&pairs, &dir);
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// Three "shards" (each its own store, as separate machines would have) write into one
/// folder at once; every asset is whole, each is there once, and every model compiles.
#[test]
fn shards_sharing_a_folder_never_clobber_each_other() {
    let dir = scratch("output_stream_shards");
    let shards: Vec<(AssetStore, Vec<String>)> = (0..3)
        .map(|_| {
            let store = AssetStore::new();
            let xmls = relocated(&store);
            (store, xmls)
        })
        .collect();
    shards
        .par_iter()
        .enumerate()
        .for_each(|(k, (store, xmls))| {
            let out = OutputDir::create(&dir).unwrap();
            store.write_to_dir(&out).unwrap();
            for (i, xml) in xmls.iter().enumerate() {
                out.write(&format!("{k}_{i:09}.xml"), xml.as_bytes())
                    .unwrap();
            }
            out.finish().unwrap();
        });
    let store = &shards[0].0;
    let mut names: Vec<String> = std::fs::read_dir(dir.join("assets"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let expected: Vec<String> = store
        .files()
        .into_iter()
        .map(|(name, source)| {
            assert_eq!(
                std::fs::read(dir.join(&name)).unwrap(),
                std::fs::read(&source).unwrap(),
                "{name}"
            );
            name.trim_start_matches("assets/").to_owned()
        })
        .collect();
    assert_eq!(names, expected, "missing, extra or temporary files");
    let pairs: Vec<Pair> = MODELS
        .iter()
        .enumerate()
        .map(|(i, m)| Pair {
            a: root().join(m),
            b: dir.join(format!("2_{i:09}.xml")),
            prefix: String::new(),
        })
        .collect();
    let failed = judge(&pairs, &scratch("output_stream_shards_judge"));
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
