//! Criterion benches of compiled variants at patch cost over
//! `benches/scenes/lift5_fixed.toml` (lift5 with its five objects fixed: random poses,
//! colours, frictions, link masses, light; `scripts/setup.sh` first), in one run:
//!
//! - `model_cache/apply`: a new variant's patch drawn and written in place into the
//!   environment's own model, with `mj_setConst` and the compiler's statistics
//!   (`ModelCache::apply`): a variant ready to step;
//! - `model_cache/compile`: the same variant's XML made and compiled by MuJoCo, what a
//!   new scene costs without the cache;
//! - `document_cache/split`: a variant taken as a plain document, split into its
//!   structure key and patch (`split_document`, no MuJoCo);
//! - `document_cache/hit`: `DocumentCache::model` on such a document of a cached
//!   structure: the split, the patch written, `mj_setConst` and the statistics;
//! - `superset/by_tree` and `superset/set_const`: a variant of `benches/scenes/lift5.toml`
//!   (five slots, six objects each) as a patch of its superset (`ModelCache::model` with
//!   `with_superset`), what `mj_setConst` derives found tree by tree
//!   (`split::TreeDerivation`) or by `mj_setConst` on the whole superset
//!   (`deriving_by_tree(false)`): the same bits, timed in one run.
//!
//! Needs MuJoCo: `cargo bench --features mujoco --bench model_cache` (the MuJoCo build.rs
//! finds: 3.17.0 in the repository, or the one in `MJCF_FORGE_MUJOCO_DIR`). Without the
//! feature it prints how to run it.

#[cfg(mjcf_mujoco)]
mod with_mujoco {
    use std::hint::black_box;
    use std::path::Path;
    use std::time::Duration;

    use criterion::{Criterion, Throughput};
    use mjcf_forge::compiled::{DocumentCache, ModelCache};
    use mjcf_forge::mujoco::compile_str;
    use mjcf_forge::scene::Scene;
    use mjcf_forge::split::split_document;

    fn lift5_fixed() -> Scene {
        Scene::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/benches/scenes/lift5_fixed.toml"
        ))
        .unwrap_or_else(|e| panic!("{e}\n(the scene's robosuite models: run scripts/setup.sh)"))
    }

    pub fn model_cache(c: &mut Criterion) {
        let scene = lift5_fixed();
        let mut cache = ModelCache::new(&scene, 4, None);
        let mut model = cache.model(0).expect("variant 0 compiles").clone();
        let mut group = c.benchmark_group("model_cache");
        group.throughput(Throughput::Elements(1));
        // Indices keep increasing: every iteration is a new variant.
        let mut next = 1u64;
        group.bench_function("apply", |b| {
            b.iter(|| {
                cache.apply(next, &mut model).expect("same structure");
                next += 1;
            });
        });
        group.sample_size(10);
        group.measurement_time(Duration::from_secs(8));
        group.bench_function("compile", |b| {
            b.iter(|| {
                let (xml, _) = scene.variant_xml(next).expect("variant");
                next += 1;
                black_box(compile_str(&xml, Path::new(".")).expect("compiles"));
            });
        });
        group.finish();
    }

    pub fn superset(c: &mut Criterion) {
        let scene = Scene::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/benches/scenes/lift5.toml"
        ))
        .unwrap_or_else(|e| panic!("{e}\n(the scene's robosuite models: run scripts/setup.sh)"));
        let mut group = c.benchmark_group("superset");
        group.throughput(Throughput::Elements(1));
        for (name, by_tree) in [("by_tree", true), ("set_const", false)] {
            let mut cache = ModelCache::new(&scene, 2, None)
                .with_superset()
                .expect("a superset")
                .deriving_by_tree(by_tree);
            cache.model(0).expect("variant 0");
            let mut next = 1u64;
            group.bench_function(name, |b| {
                b.iter(|| {
                    black_box(cache.model(next).expect("patched"));
                    next += 1;
                });
            });
            assert_eq!(cache.derived_by_tree() > 0, by_tree);
        }
        group.finish();
    }

    pub fn document_cache(c: &mut Criterion) {
        let scene = lift5_fixed();
        // Documents made before timing: the cache is what is measured.
        let docs: Vec<_> = (0..32)
            .map(|i| scene.variant(i).expect("variant").document)
            .collect();
        let mut cache = DocumentCache::new(4, None);
        cache.model(&docs[0]).expect("compiles");
        let mut group = c.benchmark_group("document_cache");
        group.throughput(Throughput::Elements(1));
        let mut next = 1usize;
        group.bench_function("split", |b| {
            b.iter(|| {
                black_box(split_document(&docs[next % docs.len()]));
                next += 1;
            });
        });
        group.bench_function("hit", |b| {
            b.iter(|| {
                black_box(cache.model(&docs[next % docs.len()]).expect("patched"));
                next += 1;
            });
        });
        group.finish();
        assert_eq!(cache.compiles(), 1, "lift5_fixed has one structure");
    }
}

#[cfg(mjcf_mujoco)]
criterion::criterion_group!(
    benches,
    with_mujoco::model_cache,
    with_mujoco::document_cache,
    with_mujoco::superset
);
#[cfg(mjcf_mujoco)]
criterion::criterion_main!(benches);

#[cfg(not(mjcf_mujoco))]
fn main() {
    eprintln!("model_cache: needs MuJoCo: cargo bench --features mujoco --bench model_cache");
}
