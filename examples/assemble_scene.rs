//! Assembles the Lift-like scene of `benches/model.rs` N times (for profiling): `cargo run --release --example assemble_scene -- 100`.

use std::path::PathBuf;

use mjcf_forge::{Document, MergePart, MujocoModel, XmlModel};

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

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(100);
    let p = parts();
    let start = std::time::Instant::now();
    let mut bytes = 0;
    for _ in 0..n {
        let scene = assemble(&p);
        if std::env::var_os("NO_WRITE").is_none() {
            bytes += scene.to_xml_string().len();
        } else {
            bytes += scene.node_count();
        }
    }
    println!(
        "{n} scenes, {bytes} bytes, {:.1} us per scene",
        start.elapsed().as_secs_f64() * 1e6 / n as f64
    );
}
