//! Criterion benches of the batch tier over `benches/scenes/lift5.toml` (robosuite's table
//! arena, Panda with gripper and mount, 5 objects drawn from 6 robosuite object models,
//! placed without overlap, random z rotation and colours; `scripts/setup.sh` first):
//! a variant made and written as compact XML, on one thread and on all cores.
//!
//! `cargo bench --bench variants`: throughput in variants per second. The scene is loaded
//! once, outside the timings, as `generate` loads it once per run.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, SamplingMode, Throughput, criterion_group, criterion_main};
use mjcf_forge::scene::Scene;
use rayon::prelude::*;

/// Variants per iteration of `all_threads`: enough to keep every core busy for a while
/// (as `generate` makes them in chunks), small enough that `cargo test --all-targets`, which
/// runs each bench once, stays quick.
const BATCH: u64 = 256;

fn lift5() -> Scene {
    Scene::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/scenes/lift5.toml"
    ))
    .unwrap_or_else(|e| panic!("{e}\n(the scene's robosuite models: run scripts/setup.sh)"))
}

fn variants(c: &mut Criterion) {
    let scene = lift5();
    let mut group = c.benchmark_group("variants");

    group.throughput(Throughput::Elements(1));
    // Indices keep increasing across iterations, so every variant is a new draw (and the
    // per-slot instances, made on first use, are made before the measurement starts).
    let mut next = 0u64;
    group.bench_function("one_thread", |b| {
        b.iter(|| {
            let v = scene.variant(next).unwrap();
            next += 1;
            black_box(v.document.to_xml_string())
        })
    });

    let pool = rayon::ThreadPoolBuilder::new().build().unwrap();
    group.throughput(Throughput::Elements(BATCH));
    // One iteration is a batch of BATCH variants (tens of ms): few samples, each of the
    // same size, rather than criterion's default linear ramp of 100.
    group.sampling_mode(SamplingMode::Flat);
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    let mut start = 0u64;
    let threads = pool.current_num_threads();
    group.bench_function("all_threads", |b| {
        b.iter(|| {
            let bytes: usize = pool.install(|| {
                (start..start + BATCH)
                    .into_par_iter()
                    .map(|i| scene.variant(i).unwrap().document.to_xml_string().len())
                    .sum()
            });
            start += BATCH;
            black_box(bytes)
        })
    });
    group.finish();
    eprintln!("variants/all_threads: a pool of {threads} threads");
}

criterion_group!(benches, variants);
criterion_main!(benches);
