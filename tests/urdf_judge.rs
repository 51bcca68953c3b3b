//! URDF read as MuJoCo's importer reads it, judged by MuJoCo: every URDF of the corpus
//! wheels that a MuJoCo version's importer compiles (`URDF_CORPORA` in scripts/setup.sh) and
//! every case of corpora/urdf, read with that version's importer rules and written as MJCF,
//! compiles under that version to the model it compiles from the URDF file itself; and every
//! corpus URDF as a user prepares it for MuJoCo (scripts/list_urdf.py: its meshes beside a
//! copy that says `<compiler strippath="true">`), read both as prepared and as shipped
//! (`package://` resolved), compiles to MuJoCo's import of the prepared copy (CI: every
//! fourth file; all with MJCF_FORGE_FULL=1, scripts/test_full.sh). Bad URDF gives every
//! problem at its place.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

mod common;

use std::path::{Path, PathBuf};

use common::{JUDGES, Pair, judge_each, root, scratch};
use mjcf_forge::{Document, UrdfImporter, UrdfOptions};

/// Each input read for `version`'s importer and written to `dir/<version>/`.
fn written(inputs: &[PathBuf], version: &str, dir: &Path) -> Vec<Pair> {
    written_to(inputs, version, &dir.join(version))
}

/// Each input read for `version`'s importer and written into `out_dir`.
fn written_to(inputs: &[PathBuf], version: &str, out_dir: &Path) -> Vec<Pair> {
    std::fs::create_dir_all(out_dir).unwrap();
    let opts = UrdfOptions {
        importer: UrdfImporter::of_version(version),
        ..UrdfOptions::default()
    };
    let mut errors = Vec::new();
    let pairs = inputs
        .iter()
        .enumerate()
        .filter_map(|(i, urdf)| {
            let doc = match Document::load_urdf(urdf, &opts) {
                Ok(d) => d,
                Err(e) => {
                    errors.push(format!("{}: {e}", urdf.display()));
                    return None;
                }
            };
            let name = urdf.file_stem().unwrap().to_string_lossy();
            let out = out_dir.join(format!("{i:03}_{name}.xml"));
            doc.write_file(&out).unwrap();
            Some(Pair {
                a: urdf.clone(),
                b: out,
                prefix: String::new(),
            })
        })
        .collect();
    assert!(
        errors.is_empty(),
        "URDFs MuJoCo compiles that we refused:\n{}",
        errors.join("\n")
    );
    pairs
}

/// Every prepared copy and its file as shipped, each read for `version`'s importer and
/// written: two pairs per file, both against MuJoCo's import of the copy.
fn prepared_pairs(files: &[(PathBuf, PathBuf)], version: &str, dir: &Path) -> Vec<Pair> {
    let copies: Vec<PathBuf> = files.iter().map(|(c, _)| c.clone()).collect();
    let shipped: Vec<PathBuf> = files.iter().map(|(_, s)| s.clone()).collect();
    let mut pairs = written_to(&copies, version, &dir.join(version).join("prepared"));
    let mut as_shipped = written_to(&shipped, version, &dir.join(version).join("shipped"));
    for (pair, copy) in as_shipped.iter_mut().zip(&copies) {
        pair.a = copy.clone();
    }
    pairs.append(&mut as_shipped);
    pairs
}

fn feature_cases() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("corpora/urdf"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "urdf"))
        .collect();
    v.sort();
    assert!(v.len() >= 3, "URDF feature cases missing");
    v
}

#[test]
fn wheel_urdfs_compile_to_mujocos_own_import() {
    for j in &JUDGES {
        let n = j.wheel_urdfs().len();
        assert!(
            n >= 70,
            "MuJoCo {} compiles {n} corpus URDFs: run scripts/setup.sh",
            j.version
        );
    }
    let dir = scratch("urdf_wheels");
    let failed = judge_each(|j| written(&j.wheel_urdfs(), j.version, &dir), &dir);
    assert!(
        failed.is_empty(),
        "judge found differences:\n{}",
        failed.join("\n")
    );
}

#[test]
fn wheel_urdfs_prepared_for_mujoco_read_as_mujocos_import_of_the_copy() {
    let full = std::env::var("MJCF_FORGE_FULL").is_ok_and(|v| !v.is_empty() && v != "0");
    let files = |j: &common::Judge| -> Vec<(PathBuf, PathBuf)> {
        let all = j.prepared_urdfs();
        assert!(
            all.len() >= 100,
            "MuJoCo {} compiles {} prepared corpus URDFs: run scripts/setup.sh",
            j.version,
            all.len()
        );
        all.into_iter()
            .enumerate()
            .filter(|(i, _)| full || i % 4 == 0)
            .map(|(_, f)| f)
            .collect()
    };
    let dir = scratch("urdf_prepared");
    let failed = judge_each(|j| prepared_pairs(&files(j), j.version, &dir), &dir);
    assert!(
        failed.is_empty(),
        "judge found differences:\n{}",
        failed.join("\n")
    );
}

#[test]
fn feature_cases_compile_to_mujocos_own_import() {
    let dir = scratch("urdf_features");
    let failed = judge_each(|j| written(&feature_cases(), j.version, &dir), &dir);
    assert!(
        failed.is_empty(),
        "judge found differences:\n{}",
        failed.join("\n")
    );
}

#[test]
fn continuous_joints_follow_the_importer_asked_for() {
    let path = root().join("corpora/urdf/continuous.urdf");
    let read = |importer| {
        let opts = UrdfOptions {
            importer,
            ..UrdfOptions::default()
        };
        Document::load_urdf(&path, &opts).unwrap().to_xml_string()
    };
    let v3 = read(UrdfImporter::MuJoCo3);
    let v4 = read(UrdfImporter::MuJoCo4);
    assert!(
        v3.contains(r#"<joint name="j1" axis="1 0 0" damping="0.2" range="-1 1""#),
        "{v3}"
    );
    assert!(!v4.contains(" range="), "{v4}");
    assert_eq!(v4.matches(r#"limited="false""#).count(), 4, "{v4}");
}

/// The errors of a URDF text, one per line.
fn errors_of(urdf: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.urdf");
    std::fs::write(&path, urdf).unwrap();
    let err = Document::load_urdf(&path, &UrdfOptions::default()).unwrap_err();
    err.0
        .iter()
        .map(|e| {
            e.to_string()
                .replace(&dir.path().display().to_string(), "DIR")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn bad_urdf_gives_every_problem_at_its_place() {
    let tree = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <link name="b"/>
  <link name="c"/>
  <joint name="j1" type="revolute"><parent link="a"/><child link="nowhere"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="c"/></joint>
  <joint name="j3" type="revolute"><parent link="b"/><child link="c"/></joint>
  <joint name="j4" type="revolute"><parent link="a"/></joint>
</robot>"#;
    assert_eq!(
        errors_of(tree),
        "DIR/bad.urdf:4:3: repeated URDF link name 'b'\n\
         DIR/bad.urdf:6:54: URDF joint names link 'nowhere', which no <link> defines\n\
         DIR/bad.urdf:8:3: URDF link 'c' has two parents: this joint and the one at 7:3\n\
         DIR/bad.urdf:9:3: URDF joint without <child>"
    );
    let cycle = r#"<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint>
</robot>"#;
    assert_eq!(
        errors_of(cycle),
        "DIR/bad.urdf:2:3: URDF link 'a' is part of a cycle of joints: no link above it has no parent\n\
         DIR/bad.urdf:3:3: URDF link 'b' is part of a cycle of joints: no link above it has no parent"
    );
    let parts = r#"<robot name="r">
  <link name="a">
    <collision><geometry><mesh filename="missing.stl"/></geometry></collision>
    <collision><geometry><mesh filename="package://nowhere_pkg/m.stl"/></geometry></collision>
    <collision><geometry><mesh filename="arm.dae"/></geometry></collision>
    <collision><geometry><cone radius="1"/></geometry></collision>
    <collision><geometry><box size="1 2"/></geometry></collision>
  </link>
  <link name="b"/>
  <joint name="j" type="hinge"><parent link="a"/><child link="b"/></joint>
</robot>"#;
    assert_eq!(
        errors_of(parts),
        "DIR/bad.urdf:3:26: 'missing.stl': no such file (DIR/missing.stl)\n\
         DIR/bad.urdf:4:26: 'package://nowhere_pkg/m.stl': no such file where MuJoCo looks \
         (DIR/package://nowhere_pkg/m.stl), and package 'nowhere_pkg' is found nowhere: give its folder (the `packages` option; --urdf-package nowhere_pkg=DIR on the command line), or list it on ROS_PACKAGE_PATH\n\
         DIR/bad.urdf:5:26: 'arm.dae' is a COLLADA mesh, which MuJoCo cannot read (it reads STL, OBJ \
         and MSH): convert it, for example with `assimp export arm.dae arm.obj`, and point the URDF at \
         the converted file\n\
         DIR/bad.urdf:6:16: visual geometry specification not found: <geometry> holds none of box, \
         cylinder, sphere, capsule, mesh\n\
         DIR/bad.urdf:7:26: 'size' must be 3 number(s), not '1 2'\n\
         DIR/bad.urdf:10:3: invalid joint type 'hinge' in URDF joint 'j' (revolute, continuous, \
         prismatic, fixed, floating, planar or spherical)"
    );
    assert_eq!(
        errors_of("<robot name=\"r\"><link name=\"a\"></robot>"),
        "DIR/bad.urdf:1:32: malformed XML: ill-formed document: expected `</link>`, but `</robot>` was found"
    );
}

#[test]
fn xacro_files_name_the_expansion() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("arm.urdf.xacro");
    std::fs::write(&path, "<robot name=\"r\" xmlns:xacro=\"x\"/>").unwrap();
    // Where a `xacro` command is installed it expands the file; here none is.
    if std::process::Command::new("xacro")
        .arg("--help")
        .output()
        .is_ok()
    {
        return;
    }
    let err = Document::load(&path).unwrap_err().to_string();
    assert!(
        err.ends_with(
            "arm.urdf.xacro:1:1: a xacro file, which needs expanding into URDF first: \
             `xacro arm.urdf.xacro > arm.urdf` (the `xacro` command: `pip install xacro`, or \
             ROS's xacro package), then load arm.urdf"
        ),
        "{err}"
    );
}

#[test]
fn a_urdf_arm_with_an_mjcf_gripper_in_a_scene_compiles_steps_and_keeps_its_physics() {
    use mjcf_forge::scene::Scene;
    let scene_file = root().join("corpora/scenes/urdf/urdf_arm.toml");
    let scene = Scene::load(&scene_file).unwrap();
    let dir = scratch("urdf_scene");
    for i in 0..20 {
        let v = scene.variant(i).unwrap();
        std::fs::write(dir.join(format!("{i:02}.xml")), v.xml()).unwrap();
    }
    // Each variant steps; the arm's bodies (fused as MuJoCo fuses them) keep the masses,
    // inertias and joints of MuJoCo's own import of the URDF, the gripper its own.
    let check = r#"
import glob, sys, mujoco, numpy as np
arm = mujoco.MjModel.from_xml_path(sys.argv[1])
grip = mujoco.MjModel.from_xml_path(sys.argv[2])
def same(m, ref, prefix):
    for b in range(1, ref.nbody):
        i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, prefix + ref.body(b).name)
        assert i >= 0, ref.body(b).name
        for f in ["body_mass", "body_inertia", "body_ipos", "body_iquat"]:
            assert np.array_equal(getattr(m, f)[i], getattr(ref, f)[b]), (f, ref.body(b).name)
    for j in range(ref.njnt):
        i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, prefix + ref.joint(j).name)
        for f in ["jnt_range", "jnt_limited", "jnt_axis", "jnt_actfrcrange"]:
            assert np.array_equal(getattr(m, f)[i], getattr(ref, f)[j]), (f, ref.joint(j).name)
n = 0
for f in sorted(glob.glob(sys.argv[3] + "/*.xml")):
    m = mujoco.MjModel.from_xml_path(f)
    same(m, arm, "robot0_")
    same(m, grip, "gripper0_")
    d = mujoco.MjData(m)
    for _ in range(200):
        mujoco.mj_step(m, d)
    assert np.isfinite(d.qpos).all(), f
    n += 1
print(n, "variants")
"#;
    let out = std::process::Command::new(common::python())
        .args(["-c", check])
        .arg(root().join("corpora/scenes/urdf/arm.urdf"))
        .arg(root().join("corpora/scenes/demo/gripper.xml"))
        .arg(&dir)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.trim() == "20 variants",
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_scene_file_reads_its_urdf_with_the_options_it_gives() {
    use mjcf_forge::scene::Scene;
    use mjcf_forge::{UrdfActuators, XmlModel, XmlModelOptions};
    let scene = Scene::load(root().join("corpora/scenes/urdf/urdf_arm_options.toml")).unwrap();
    let dir = scratch("urdf_scene_options");
    std::fs::write(dir.join("variant.xml"), scene.variant(0).unwrap().xml()).unwrap();
    // The arm as the library reads it with the same options, prefixed as the scene does.
    let arm = root().join("corpora/scenes/urdf/arm.urdf");
    let options = UrdfOptions {
        visuals: true,
        fuse_static: false,
        actuators: Some(UrdfActuators::Position { kp: 50.0, kv: 2.0 }),
        ..UrdfOptions::default()
    };
    let doc = Document::load_urdf(&arm, &options).unwrap();
    // (A scene's fixture keeps its collision geoms' colours and leaves geoms unnamed.)
    let as_scene = XmlModelOptions {
        contact_geom_rgba: None,
        name_unnamed_geoms: false,
        ..XmlModelOptions::default()
    };
    let alone = XmlModel::with_prefix(doc, "robot0_", as_scene).unwrap();
    alone.document().write_file(dir.join("arm.xml")).unwrap();
    // Its every body, joint, geom and actuator is in the variant with the same values.
    let check = r#"
import sys, mujoco, numpy as np
m = mujoco.MjModel.from_xml_path(sys.argv[1])
ref = mujoco.MjModel.from_xml_path(sys.argv[2])
kinds = {"body": ["body_mass", "body_inertia", "body_ipos", "body_iquat"],
         "jnt": ["jnt_range", "jnt_limited", "jnt_axis", "jnt_type"],
         "actuator": ["actuator_gainprm", "actuator_biasprm", "actuator_ctrlrange"]}
objs = {"body": mujoco.mjtObj.mjOBJ_BODY, "jnt": mujoco.mjtObj.mjOBJ_JOINT,
        "actuator": mujoco.mjtObj.mjOBJ_ACTUATOR}
n = {"body": ref.nbody, "jnt": ref.njnt, "actuator": ref.nu}
seen = {"geom": 0}
for kind, fields in kinds.items():
    for k in range(1 if kind == "body" else 0, n[kind]):
        name = mujoco.mj_id2name(ref, objs[kind], k)
        i = mujoco.mj_name2id(m, objs[kind], name)
        assert name and i >= 0, (kind, k, name)
        for f in fields:
            assert np.array_equal(getattr(m, f)[i], getattr(ref, f)[k]), (f, name)
        seen[kind] = seen.get(kind, 0) + 1
        if kind == "body":
            # The body's geoms (unnamed ones among them), in order.
            ours = np.flatnonzero(m.geom_bodyid == i)
            theirs = np.flatnonzero(ref.geom_bodyid == k)
            assert len(ours) == len(theirs), name
            for a, b in zip(ours, theirs):
                for f in ["geom_type", "geom_size", "geom_group", "geom_contype", "geom_rgba"]:
                    assert np.array_equal(getattr(m, f)[a], getattr(ref, f)[b]), (f, name)
            seen["geom"] += len(ours)
# The options took: a visual geom of group 1, the flange a body of its own, an actuator each.
assert (ref.geom_group == 1).sum() == 1 and ref.nu == 3, (ref.geom_group, ref.nu)
assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "robot0_flange") >= 0
print(seen["body"], seen["jnt"], seen["geom"], seen["actuator"])
"#;
    let out = std::process::Command::new(common::python())
        .args(["-c", check])
        .arg(dir.join("variant.xml"))
        .arg(dir.join("arm.xml"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    // Options for a model that is not URDF, and a key the table does not have, are errors
    // at their places in the scene file.
    let text =
        std::fs::read_to_string(root().join("corpora/scenes/urdf/urdf_arm_options.toml")).unwrap();
    let file = dir.join("bad.toml");
    let copy = |text: &str| {
        std::fs::write(&file, text).unwrap();
        std::fs::copy(
            root().join("corpora/scenes/urdf/arm.urdf"),
            dir.join("arm.urdf"),
        )
        .unwrap();
        let base = root().join("corpora/scenes/demo");
        let text = text.replace("../demo/", &format!("{}/", base.display()));
        std::fs::write(&file, text).unwrap();
        Scene::load(&file).unwrap_err().to_string()
    };
    let mjcf = text.replace("model = \"arm.urdf\"", "model = \"../demo/gripper.xml\"");
    let err = copy(&mjcf);
    assert!(
        err.contains("bad.toml:13:1: urdf options are given for")
            && err.contains("gripper.xml', which is not a URDF file"),
        "{err}"
    );
    // A scene passes its URDF models' load warnings on (python/tests/test_urdf.py judges
    // the messages against MuJoCo's).
    let warned = root().join("corpora/urdf/warned.urdf");
    let with_warnings = format!(
        "base = \"{}\"\n[[fixture]]\nmodel = \"{}\"\nprefix = \"w_\"\n",
        root().join("corpora/scenes/demo/arena.xml").display(),
        warned.display()
    );
    let scene = Scene::from_toml_str(&with_warnings, &dir).unwrap();
    let alone = Document::load(&warned).unwrap();
    assert!(alone.warnings().len() >= 7, "{:?}", alone.warnings());
    assert_eq!(scene.warnings(), alone.warnings());
    assert!(
        Scene::load(root().join("corpora/scenes/urdf/urdf_arm.toml"))
            .unwrap()
            .warnings()
            .is_empty()
    );
    let err = copy(&text.replace("visuals = true", "visual = true"));
    assert!(
        err.contains("bad.toml:14:1: unknown field `visual`"),
        "{err}"
    );
}

#[test]
fn xacro_files_are_expanded_by_the_installed_xacro() {
    // scripts/setup.sh installs PyPI's xacro into .cache/venv; with it on PATH, a .xacro
    // file loads as its expansion, which MuJoCo judges against its own import of it.
    let bin = root().join(".cache/venv/bin");
    assert!(
        bin.join("xacro").is_file(),
        "{}: missing: run scripts/setup.sh",
        bin.join("xacro").display()
    );
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let dir = scratch("urdf_xacro");
    let xacro = root().join("corpora/urdf/xacro/arm.urdf.xacro");
    let expanded = std::process::Command::new(bin.join("xacro"))
        .arg(&xacro)
        .output()
        .unwrap();
    assert!(expanded.status.success());
    let urdf = dir.join("arm.urdf");
    std::fs::write(&urdf, &expanded.stdout).unwrap();
    let ours = dir.join("arm.xml");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mjcf-forge"))
        .args([
            "inline",
            xacro.to_str().unwrap(),
            "-o",
            ours.to_str().unwrap(),
        ])
        .env("PATH", path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let failed = judge_each(
        |_| {
            vec![Pair {
                a: urdf.clone(),
                b: ours.clone(),
                prefix: String::new(),
            }]
        },
        &dir,
    );
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
