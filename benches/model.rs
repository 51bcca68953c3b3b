//! Criterion benches of the model tier on robosuite parts (`scripts/setup.sh` first):
//! prefix, merge, write, and assembling a Lift-like scene (table arena, Panda with mount and
//! gripper, 5 objects) from documents already loaded.
//!
//! `cargo bench --bench model`

use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mjcf_forge::{Document, MergeOptions, MergePart, MujocoModel, XmlModel};

fn rs(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(".cache/corpus/robosuite-1.5.2/robosuite/models/assets")
        .join(rel)
}

/// The parts of robosuite's Lift task, loaded once.
struct Parts {
    arena: Document,
    robot: Document,
    mount: Document,
    gripper: Document,
    objects: Vec<Document>,
}

fn parts() -> Parts {
    let load = |p: &str| Document::load(rs(p)).unwrap();
    Parts {
        arena: load("arenas/table_arena.xml"),
        robot: load("robots/panda/robot.xml"),
        mount: load("bases/rethink_mount.xml"),
        gripper: load("grippers/panda_gripper.xml"),
        objects: [
            "objects/can.xml",
            "objects/milk.xml",
            "objects/bread.xml",
            "objects/cereal.xml",
            "objects/lemon.xml",
        ]
        .iter()
        .map(|p| load(p))
        .collect(),
    }
}

/// Builds the scene the way robosuite does: instances with prefixes, gripper into the
/// robot's hand, mount under its base, robot and objects into the arena.
fn assemble(p: &Parts) -> Document {
    let mut robot = XmlModel::new(p.robot.clone(), "robot0").unwrap();
    let gripper = XmlModel::new(p.gripper.clone(), "gripper0").unwrap();
    let mount = XmlModel::new(p.mount.clone(), "mount0").unwrap();
    robot
        .merge_all(
            &[
                (&gripper, Some("robot0_right_hand")),
                (&mount, Some("robot0_base")),
            ],
            false,
        )
        .unwrap();
    let objects: Vec<XmlModel> = p
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| XmlModel::new(o.clone(), format!("object{i}")).unwrap())
        .collect();
    let mut scene = p.arena.clone();
    let mut parts = vec![MergePart {
        doc: robot.document(),
        into: None,
        prefix: "robot0_",
    }];
    parts.extend(objects.iter().map(|o| MergePart {
        doc: o.document(),
        into: None,
        prefix: o.naming_prefix(),
    }));
    scene.merge_all(&parts, false).unwrap();
    scene
}

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
