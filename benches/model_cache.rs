//! Criterion benches of compiled variants at patch cost over
//! `benches/scenes/lift5_fixed.toml` (lift5 with its five objects fixed: random poses,
//! colours, frictions, link masses, light; `scripts/setup.sh` first), in one run:
//!
//! - `model_cache/apply`: a new variant's patch drawn and written in place into the
//!   environment's own model, with `mj_setConst` and the compiler's statistics
//!   (`ModelCache::apply`): a variant ready to step;
//! - `model_cache/compile`: the same variant's XML made and compiled by MuJoCo, what a
//!   new scene costs without the cache.
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
    use mjcf_forge::compiled::ModelCache;
    use mjcf_forge::mujoco::compile_str;
    use mjcf_forge::scene::Scene;

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
}

#[cfg(mjcf_mujoco)]
criterion::criterion_group!(benches, with_mujoco::model_cache);
#[cfg(mjcf_mujoco)]
criterion::criterion_main!(benches);

#[cfg(not(mjcf_mujoco))]
fn main() {
    eprintln!("model_cache: needs MuJoCo: cargo bench --features mujoco --bench model_cache");
}
