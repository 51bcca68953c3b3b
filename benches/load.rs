//! Criterion benches of the document tier over the robosuite models of the wheel corpus
//! (`scripts/setup.sh` lists them in `.cache/corpus/models.txt`).
//!
//! `cargo bench --bench load`: throughput in bytes of input XML per second.

use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mjcf_forge::Document;

/// The files a list under `.cache/corpus/` names (made by `scripts/setup.sh`), those whose
/// path passes `keep`.
fn listed(list: &str, keep: impl Fn(&str) -> bool) -> Vec<PathBuf> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join(".cache/corpus").join(list))
        .unwrap_or_else(|e| panic!(".cache/corpus/{list}: {e}: run scripts/setup.sh first"));
    text.lines()
        .filter(|l| keep(l))
        .map(|l| root.join(l))
        .collect()
}

fn robosuite_models() -> Vec<PathBuf> {
    listed("models.txt", |l| l.contains("/robosuite-"))
}

/// A group over `files`, in bytes of input a second: `load_and_write` (each read and
/// written back), and `load` alone with `with_load`.
fn corpus_group(c: &mut Criterion, name: &str, files: &[PathBuf], with_load: bool) {
    let bytes: u64 = files
        .iter()
        .map(|f| std::fs::metadata(f).unwrap().len())
        .sum();
    let mut group = c.benchmark_group(name);
    group.throughput(Throughput::Bytes(bytes));
    group.sample_size(20);
    if with_load {
        group.bench_function("load", |b| {
            b.iter(|| {
                for f in files {
                    std::hint::black_box(Document::load(f).unwrap());
                }
            })
        });
    }
    group.bench_function("load_and_write", |b| {
        b.iter(|| {
            for f in files {
                let doc = Document::load(f).unwrap();
                std::hint::black_box(doc.to_xml_string());
            }
        })
    });
    group.finish();
}

fn whole_corpus(c: &mut Criterion) {
    corpus_group(c, "robosuite_corpus", &robosuite_models(), true);
}

/// The URDF files of the corpus wheels that MuJoCo 3.17.0's importer accepts
/// (`.cache/corpus/urdf-models.txt`), read as MuJoCo reads them and written as MJCF.
fn urdf_corpus(c: &mut Criterion) {
    corpus_group(
        c,
        "urdf_corpus",
        &listed("urdf-models.txt", |_| true),
        false,
    );
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
