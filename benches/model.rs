//! Criterion benches of the model tier on robosuite parts (`scripts/setup.sh` first):
//! prefix, merge, write, and assembling a Lift-like scene (table arena, Panda with mount and
//! gripper, 5 objects) from documents already loaded.
//!
//! `cargo bench --bench model`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mjcf_forge::MergeOptions;

#[path = "lift_scene.rs"]
mod lift_scene;
use lift_scene::{assemble, parts};

fn scene(c: &mut Criterion) {
    let p = parts();
    let mut group = c.benchmark_group("lift_scene");
    group.throughput(Throughput::Elements(1));
    group.bench_function("assemble", |b| {
        b.iter(|| std::hint::black_box(assemble(&p)))
    });
    let built = assemble(&p);
    group.bench_function("assemble_and_write", |b| {
        b.iter(|| std::hint::black_box(assemble(&p).to_xml_string()))
    });
    group.bench_function("write_scene", |b| {
        b.iter(|| std::hint::black_box(built.to_xml_string()))
    });
    group.finish();
}

fn operations(c: &mut Criterion) {
    let p = parts();
    let mut group = c.benchmark_group("panda");
    group.bench_function("prefix", |b| {
        b.iter(|| {
            let mut d = p.robot.clone();
            d.apply_prefix("robot0_").unwrap();
            std::hint::black_box(d)
        })
    });
    group.bench_function("clone", |b| {
        b.iter(|| std::hint::black_box(p.robot.clone()))
    });
    let mut gripper = p.gripper.clone();
    gripper.apply_prefix("gripper0_").unwrap();
    let mut robot = p.robot.clone();
    robot.apply_prefix("robot0_").unwrap();
    group.bench_function("merge_gripper", |b| {
        b.iter(|| {
            let mut r = robot.clone();
            r.merge(
                &gripper,
                Some("robot0_right_hand"),
                &MergeOptions::default(),
            )
            .unwrap();
            std::hint::black_box(r)
        })
    });
    group.bench_function("validate", |b| b.iter(|| robot.validate().unwrap()));
    group.finish();
}

criterion_group!(benches, scene, operations);
criterion_main!(benches);
