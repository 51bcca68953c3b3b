//! robosuite's Lift scene built from loaded documents: shared by `benches/model.rs` and
//! `benches/tools/assemble_scene.rs` (included with `#[path]`), so both measure the same thing.

use std::path::PathBuf;

use mjcf_forge::{Document, MergePart, MujocoModel, XmlModel};

pub fn rs(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(".cache/corpus/robosuite-1.5.2/robosuite/models/assets")
        .join(rel)
}

/// The parts of robosuite's Lift task, loaded once.
pub struct Parts {
    pub arena: Document,
    pub robot: Document,
    pub mount: Document,
    pub gripper: Document,
    pub objects: Vec<Document>,
}

pub fn parts() -> Parts {
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
pub fn assemble(p: &Parts) -> Document {
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
