//! Criterion benches of the document tier over the robosuite models of the wheel corpus
//! (`scripts/setup.sh` lists them in `.cache/corpus/models.txt`).
//!
//! `cargo bench --bench load`: throughput in bytes of input XML per second.

use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mjcf_forge::Document;

fn robosuite_models() -> Vec<PathBuf> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let list = std::fs::read_to_string(root.join(".cache/corpus/models.txt"))
        .expect(".cache/corpus/models.txt: run scripts/setup.sh first");
    list.lines()
        .filter(|l| l.contains("/robosuite-"))
        .map(|l| root.join(l))
        .collect()
}

fn whole_corpus(c: &mut Criterion) {
    let files = robosuite_models();
    let bytes: u64 = files
        .iter()
        .map(|f| std::fs::metadata(f).unwrap().len())
        .sum();
    let mut group = c.benchmark_group("robosuite_corpus");
    group.throughput(Throughput::Bytes(bytes));
    group.sample_size(20);
    group.bench_function("load", |b| {
        b.iter(|| {
            for f in &files {
                std::hint::black_box(Document::load(f).unwrap());
            }
        })
    });
    group.bench_function("load_and_write", |b| {
        b.iter(|| {
            for f in &files {
                let doc = Document::load(f).unwrap();
                std::hint::black_box(doc.to_xml_string());
            }
        })
    });
    group.finish();
}

/// The URDF files of the corpus wheels that MuJoCo 3.17.0's importer accepts
/// (`.cache/corpus/urdf-models.txt`), read as MuJoCo reads them and written as MJCF.
fn urdf_corpus(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let list = std::fs::read_to_string(root.join(".cache/corpus/urdf-models.txt"))
        .expect(".cache/corpus/urdf-models.txt: run scripts/setup.sh first");
    let files: Vec<PathBuf> = list.lines().map(|l| root.join(l)).collect();
    let bytes: u64 = files
        .iter()
        .map(|f| std::fs::metadata(f).unwrap().len())
        .sum();
    let mut group = c.benchmark_group("urdf_corpus");
    group.throughput(Throughput::Bytes(bytes));
    group.sample_size(20);
    group.bench_function("load_and_write", |b| {
        b.iter(|| {
            for f in &files {
                let doc = Document::load(f).unwrap();
                std::hint::black_box(doc.to_xml_string());
            }
        })
    });
    group.finish();
}

fn small_operations(c: &mut Criterion) {
    let files = robosuite_models();
    let panda = files
        .iter()
        .find(|f| f.ends_with("robots/panda/robot.xml"))
        .expect("panda robot");
    let doc = Document::load(panda).unwrap();
    let xml_len = doc.to_xml_string().len() as u64;
    let mut group = c.benchmark_group("panda_robot");
    group.throughput(Throughput::Bytes(xml_len));
    group.bench_function("clone", |b| b.iter(|| std::hint::black_box(doc.clone())));
    group.bench_function("write_compact", |b| {
        b.iter(|| std::hint::black_box(doc.to_xml_string()))
    });
    group.bench_function("write_pretty", |b| {
        b.iter(|| std::hint::black_box(doc.to_pretty_string()))
    });
    group.finish();
}

criterion_group!(benches, whole_corpus, urdf_corpus, small_operations);
criterion_main!(benches);
