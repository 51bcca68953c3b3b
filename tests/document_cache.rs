//! The Rust `DocumentCache` (feature `mujoco`), judged by MuJoCo: every model it returns
//! equals, bit for bit in every array and statistic, MuJoCo compiling the same document;
//! for the scenes' variants taken as documents, for random edits of patchable values of
//! real models (a seeded sample of the wheel corpus), and for structural edits, which
//! must be compiled.
//!
//! Pass: once per MuJoCo the feature `mujoco` links (scripts/test.sh: 3.17.0 and 4.0.0),
//! since what it checks depends on that MuJoCo (a build without the feature has none of it).

#![cfg(mjcf_mujoco)]

use std::path::{Path, PathBuf};

use mjcf_forge::compiled::DocumentCache;
use mjcf_forge::mujoco::{CompiledModel, compile_document};
use mjcf_forge::scene::Scene;
use mjcf_forge::split::split_document;
use mjcf_forge::{Document, Node, Section};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn exact(cache: &mut DocumentCache, doc: &Document, what: &str) {
    let want: CompiledModel = compile_document(doc).unwrap_or_else(|e| panic!("{what}: {e}"));
    let got = cache.model(doc).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(got.differences(&want), Vec::<String>::new(), "{what}");
}

/// A seeded generator (splitmix64): the same edits on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn coin(&mut self) -> bool {
        self.next() & 1 == 1
    }
}

fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn parsed(text: &str) -> Vec<f64> {
    text.split_ascii_whitespace()
        .map(|t| t.parse().unwrap_or(0.0))
        .collect()
}

/// A new value for a patchable attribute (`None` for one this test leaves alone): in the
/// range MuJoCo takes, with as many numbers as the attribute had.
fn new_value(tag: &str, attr: &str, old: &str, rng: &mut Rng) -> Option<String> {
    let old_v = parsed(old);
    let n = old_v.len();
    let mut r =
        |lo: f64, hi: f64, k: usize| (0..k).map(|_| rng.uniform(lo, hi)).collect::<Vec<_>>();
    let v = match (tag, attr) {
        (_, "rgba") if n == 4 => r(0.0, 1.0, 4),
        ("geom", "friction") if n == 3 => r(0.1, 2.0, 3),
        ("geom", "solref") if n == 2 => vec![r(0.005, 0.05, 1)[0], r(0.5, 1.5, 1)[0]],
        ("geom", "solimp") if n == 5 => {
            vec![
                r(0.5, 0.9, 1)[0],
                r(0.9, 0.99, 1)[0],
                r(0.001, 0.01, 1)[0],
                0.5,
                2.0,
            ]
        }
        ("geom", "margin" | "gap") if n == 1 => r(0.0, 0.01, 1),
        ("material", "specular" | "shininess" | "reflectance" | "emission") if n == 1 => {
            r(0.0, 1.0, 1)
        }
        ("light", "diffuse" | "specular" | "ambient") if n == 3 => r(0.0, 1.0, 3),
        ("joint", "damping" | "armature" | "frictionloss" | "stiffness") if n == 1 => {
            r(0.0, 2.0, 1)
        }
        ("camera", "fovy") if n == 1 => r(30.0, 90.0, 1),
        ("body", "pos") if n == 3 => old_v.iter().map(|x| x + r(-0.05, 0.05, 1)[0]).collect(),
        ("body", "quat") if n == 4 => {
            let q = r(-1.0, 1.0, 4);
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            q.iter().map(|x| x / norm).collect()
        }
        ("position", "kp") | ("velocity", "kv") if n == 1 => r(1.0, 500.0, 1),
        ("position", "kv") if n == 1 => r(0.0, 50.0, 1),
        ("general", "gainprm") if n >= 1 => {
            let mut v = old_v.clone();
            v[0] = r(1.0, 500.0, 1)[0];
            v
        }
        ("option", "timestep") => r(0.001, 0.005, 1),
        ("option", "gravity") if n == 3 => vec![0.0, 0.0, r(-12.0, -8.0, 1)[0]],
        ("option", "density" | "viscosity") if n == 1 => r(0.0, 1.5, 1),
        _ => return None,
    };
    Some(list(&v))
}

/// Changes a random half of the document's patchable values; how many it changed.
fn edit_values(doc: &mut Document, rng: &mut Rng) -> usize {
    let nodes: Vec<Node> = doc.descendants(doc.root()).collect();
    let mut changed = 0;
    for node in nodes {
        let tag = doc.tag(node).to_string();
        if tag == "inertial" {
            // Mass and inertia scaled together keep the inertia valid.
            if rng.coin()
                && let (Some(m), Some(i)) = (doc.attr(node, "mass"), doc.attr(node, "diaginertia"))
            {
                let f = rng.uniform(0.5, 2.0);
                let mass = list(&parsed(m).iter().map(|x| x * f).collect::<Vec<_>>());
                let inertia = list(&parsed(i).iter().map(|x| x * f).collect::<Vec<_>>());
                doc.set_attr(node, "mass", &mass);
                doc.set_attr(node, "diaginertia", &inertia);
                changed += 1;
            }
            continue;
        }
        let attrs: Vec<(String, String)> = doc
            .attrs(node)
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        for (attr, old) in attrs {
            if !rng.coin() {
                continue;
            }
            if let Some(value) = new_value(&tag, &attr, &old, rng) {
                doc.set_attr(node, &attr, &value);
                changed += 1;
            }
        }
    }
    changed
}

#[test]
fn scene_variants_as_documents_are_exact() {
    let scenes = [
        "corpora/scenes/patch/patch.toml",
        "corpora/scenes/patch/structural.toml",
        "corpora/scenes/patch/aligned.toml",
        "corpora/scenes/demo/demo.toml",
        "benches/scenes/lift5_fixed.toml",
    ];
    let mut cache = DocumentCache::new(16, None);
    for path in scenes {
        let scene = Scene::load(root().join(path)).unwrap();
        let before = cache.patches();
        for i in 0..8 {
            let doc = scene.variant(i).unwrap().document;
            exact(&mut cache, &doc, &format!("{path} variant {i}"));
        }
        // Scenes whose variants share structures are patched.
        if path.contains("patch.toml") || path.contains("lift5_fixed") {
            assert!(cache.patches() > before, "{path}: nothing patched");
        }
    }
}

/// The wheel models of the sample: robosuite robots, grippers, objects and an arena, and
/// models of six other wheels (one with muscles, one with a fluid).
const SAMPLE: [&str; 20] = [
    "robosuite-1.5.2/robosuite/models/assets/robots/panda/robot.xml",
    "robosuite-1.5.2/robosuite/models/assets/robots/sawyer/robot.xml",
    "robosuite-1.5.2/robosuite/models/assets/robots/ur5e/robot.xml",
    "robosuite-1.5.2/robosuite/models/assets/grippers/panda_gripper.xml",
    "robosuite-1.5.2/robosuite/models/assets/grippers/robotiq_gripper_140.xml",
    "robosuite-1.5.2/robosuite/models/assets/objects/can.xml",
    "robosuite-1.5.2/robosuite/models/assets/objects/milk.xml",
    "robosuite-1.5.2/robosuite/models/assets/arenas/table_arena.xml",
    "brax-0.14.2/brax/envs/assets/ant.xml",
    "brax-0.14.2/brax/envs/assets/reacher.xml",
    "brax-0.14.2/brax/test_data/fluid_box.xml",
    "dm_control-1.0.50/dm_control/mjcf/test_assets/robot_arm.xml",
    "dm_control-1.0.50/dm_control/suite/acrobot.xml",
    "dm_control-1.0.50/dm_control/suite/finger.xml",
    "dm_control-1.0.50/dm_control/suite/point_mass.xml",
    "dm_control-1.0.50/dm_control/third_party/kinova/jaco_arm.xml",
    "fancy_gym-0.3.0/fancy_gym/envs/mujoco/hopper_jump/assets/hopper_jump_on_box.xml",
    "gym_aloha-0.1.5/gym_aloha/assets/bimanual_viperx_end_effector_transfer_cube.xml",
    "gymnasium-1.4.0/gymnasium/envs/mujoco/assets/pusher.xml",
    "myo_sim-0.2.3/myo_sim/models/legacy/elbow/myoelbow_1dof6muscles_1dofSoftexo_sim2.xml",
];

fn sample() -> Vec<(String, Document)> {
    let corpus = root().join(".cache/corpus");
    assert!(
        corpus.join("models.txt").is_file(),
        "run scripts/setup.sh first"
    );
    SAMPLE
        .iter()
        .map(|p| {
            let doc = Document::load(corpus.join(p)).unwrap_or_else(|e| panic!("{p}: {e}"));
            (p.to_string(), doc)
        })
        .collect()
}

#[test]
fn random_value_edits_of_wheel_models_are_exact() {
    let mut cache = DocumentCache::new(4, None);
    let mut rng = Rng(21);
    let (mut edits, mut hits) = (0, 0);
    for (path, doc) in sample() {
        exact(&mut cache, &doc, &path);
        let key = split_document(&doc).structure_key;
        for round in 0..3 {
            let mut edited = doc.clone();
            edits += edit_values(&mut edited, &mut rng);
            let patches = cache.patches();
            exact(&mut cache, &edited, &format!("{path} round {round}"));
            if split_document(&edited).structure_key == key {
                assert_eq!(
                    cache.patches(),
                    patches + 1,
                    "{path}: same key, not patched"
                );
                hits += 1;
            }
        }
    }
    eprintln!("{edits} values edited; {hits} of 60 edited documents patched");
    // Most edited documents are patched; the others compile: a muscle model (only visual
    // values patch), poses of unnamed bodies, of models with keyframes.
    assert!(edits > 500, "{edits} edits");
    assert!(hits >= 40, "{hits} of 60 rounds patched");
}

#[test]
fn structural_edits_are_compiled_and_exact() {
    let mut cache = DocumentCache::new(64, None);
    for (path, doc) in sample() {
        exact(&mut cache, &doc, &path);
        let key = split_document(&doc).structure_key;
        let world = doc.find_section(Section::Worldbody).unwrap();
        let first_geom = doc.descendants(world).find(|&n| doc.tag(n) == "geom");
        // A geom of the world itself: removing it leaves no body without mass.
        let world_geom = doc.elements(world).find(|&n| doc.tag(n) == "geom");
        let mut edits: Vec<(&str, Document)> = Vec::new();
        // An element added.
        let mut added = doc.clone();
        added.append_element(
            world,
            "site",
            &[("name", "doc_cache_site"), ("size", "0.01")],
        );
        edits.push(("a site added", added));
        // An element removed (unless something may name it).
        if let Some(geom) = world_geom.filter(|&g| doc.attr(g, "name").is_none()) {
            let mut removed = doc.clone();
            removed.remove_element(geom);
            edits.push(("a geom removed", removed));
        }
        if let Some(geom) = first_geom {
            // A value no rule patches.
            let mut grown = doc.clone();
            let other = if doc.attr(geom, "contype") == Some("0") {
                "1"
            } else {
                "0"
            };
            grown.set_attr(geom, "contype", other);
            edits.push(("a geom's contype", grown));
            // A patchable value where there was none changes the patch's layout.
            let mut coloured = doc.clone();
            if doc.attr(geom, "rgba").is_none() {
                coloured.set_attr(geom, "rgba", "0.25 0.5 0.75 1");
                edits.push(("an rgba added", coloured));
            }
        }
        for (what, edited) in edits {
            let compiles = cache.compiles();
            assert_ne!(split_document(&edited).structure_key, key, "{path}: {what}");
            exact(&mut cache, &edited, &format!("{path}: {what}"));
            assert_eq!(
                cache.compiles(),
                compiles + 1,
                "{path}: {what} not compiled"
            );
        }
    }
}

#[test]
fn mujoco_errors_point_at_the_source_and_leave_the_cache_alone() {
    let dir = root().join("corpora/scenes/demo");
    let good = "<mujoco><worldbody><body name='b'><freejoint/>\
                <geom name='g' size='.1' rgba='1 0 0 1'/></body></worldbody></mujoco>";
    let mut cache = DocumentCache::new(4, None);
    cache.model_xml(good, &dir).unwrap();
    let (len, compiles, bytes) = (cache.len(), cache.compiles(), cache.nbytes());
    let bad = "<mujoco>\n<worldbody>\n<body name='b'>\n<freejoint/>\n\
               <geom name='g' type='mesh' mesh='missing' rgba='1 0 0 1'/>\n\
               </body>\n</worldbody>\n</mujoco>";
    let err = cache.model_xml(bad, &dir).unwrap_err().to_string();
    assert!(err.starts_with("<string>:5:1: "), "{err}");
    assert!(err.contains("missing"), "{err}");
    // A material that does not exist on a cached structure: MuJoCo's verdict too.
    let doc = |material: &str| {
        format!(
            "<mujoco><asset><material name='m'/></asset><worldbody>\
             <geom name='g' size='.1' material='{material}'/></worldbody></mujoco>"
        )
    };
    cache.model_xml(&doc("m"), &dir).unwrap();
    let err = cache.model_xml(&doc("nope"), &dir).unwrap_err().to_string();
    assert!(err.contains("nope"), "{err}");
    let text = doc("m");
    let again = Document::from_str(&text, &dir).unwrap();
    exact(&mut cache, &again, "after an error");
    assert_eq!(cache.len(), len + 1);
    assert_eq!(cache.compiles(), compiles + 1);
    assert!(cache.nbytes() > bytes);
}

#[test]
fn the_cache_is_bounded_least_recently_used_out() {
    let xml = |size: &str| {
        format!(
            "<mujoco><worldbody><geom name='g' size='{size}' rgba='1 0 0 1'/></worldbody></mujoco>"
        )
    };
    let dir = Path::new(".");
    let mut cache = DocumentCache::new(2, None);
    for size in ["0.1", "0.2", "0.3"] {
        cache.model_xml(&xml(size), dir).unwrap();
    }
    assert_eq!(cache.len(), 2);
    // 0.3 and 0.2 are kept: asking again patches.
    cache.model_xml(&xml("0.2"), dir).unwrap();
    assert_eq!(cache.compiles(), 3);
    // 0.1 was dropped: compiled again, and 0.3, now the least recent, goes.
    cache.model_xml(&xml("0.1"), dir).unwrap();
    assert_eq!(cache.compiles(), 4);
    cache.model_xml(&xml("0.3"), dir).unwrap();
    assert_eq!(cache.compiles(), 5);
    let mut one = DocumentCache::new(8, None);
    one.model_xml(&xml("0.1"), dir).unwrap();
    let mut small = DocumentCache::new(8, Some(one.nbytes() + 1));
    for size in ["0.1", "0.2", "0.3"] {
        small.model_xml(&xml(size), dir).unwrap();
    }
    assert_eq!(small.len(), 1);
}

/// One model with every kind of value the document split adds to `PATCHABLE`'s: option
/// values, actuator gains (named and unnamed, `kv` given or not), an unnamed free joint's
/// pose, a body with neither inertial nor geoms.
fn rules_model(v: &[&str; 8]) -> String {
    format!(
        "<mujoco><option timestep='{}' gravity='0 0 {}' density='{}' viscosity='0'/>\
         <worldbody>\
         <body name='arm' pos='0 0 1'><joint name='j1'/><geom size='.1' pos='.2 0 0' mass='1'/>\
           <body name='tip' pos='{} 0 0'><joint name='j2'/><geom size='.05'/></body></body>\
         <body name='free' pos='0 1 {}'><freejoint/><geom size='.1' rgba='{}'/></body>\
         <body name='empty' pos='1 1 1'/>\
         </worldbody><actuator>\
         <position name='p' joint='j1' kp='{}'/>\
         <position joint='j2' kp='{}' kv='2'/>\
         <velocity joint='j1' kv='3'/>\
         <general joint='j2' gainprm='4 1' biasprm='0 -4 -1' dynprm='1 2'/>\
         </actuator></mujoco>",
        v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]
    )
}

#[test]
fn option_values_actuator_gains_and_unnamed_elements_are_patched_exactly() {
    let dir = Path::new(".");
    let a = ["0.002", "-9.81", "0", "0.3", "0.5", "1 0 0 1", "10", "20"];
    let b = ["0.004", "-3", "1.2", "0.35", "0.7", "0 1 0 1", "15", "0"];
    let (da, db) = (
        Document::from_str(&rules_model(&a), dir).unwrap(),
        Document::from_str(&rules_model(&b), dir).unwrap(),
    );
    let (sa, sb) = (split_document(&da), split_document(&db));
    assert_eq!(sa.structure_key, sb.structure_key);
    let fields: Vec<(&str, &str)> = sa.entries.iter().map(|e| (e.object, e.field)).collect();
    for want in [
        ("option", "timestep"),
        ("option", "gravity"),
        ("option", "density"),
        ("actuator", "gainprm"),
        ("actuator", "biasprm"),
        ("actuator", "dynprm"),
        ("joint", "qpos0"),
        ("body", "ipos"),
    ] {
        assert!(fields.contains(&want), "{want:?} not in {fields:?}");
    }
    // Unnamed actuators by their ids.
    assert!(
        sa.entries
            .iter()
            .any(|e| e.object == "actuator" && e.id == Some(3))
    );
    let mut cache = DocumentCache::new(4, None);
    for doc in [&da, &db, &da] {
        exact(&mut cache, doc, "rules model");
    }
    assert_eq!((cache.compiles(), cache.patches()), (1, 2));
}

#[test]
fn derived_values_mujoco_set_const_leaves_stay_structure() {
    let dir = Path::new(".");
    let key = |xml: String| split_document(&Document::from_str(&xml, dir).unwrap()).structure_key;
    // A damping ratio is turned into a damping from the masses at compile time.
    let dampratio = |mass: &str| {
        format!(
            "<mujoco><worldbody><body name='b'><joint name='j'/>\
             <inertial pos='0 0 0' mass='{mass}' diaginertia='1 1 1'/></body></worldbody>\
             <actuator><position joint='j' kp='10' dampratio='1'/></actuator></mujoco>"
        )
    };
    assert_ne!(key(dampratio("1")), key(dampratio("2")));
    // A spatial tendon's spring length is its length at qpos0.
    let tendon = |x: &str| {
        format!(
            "<mujoco><worldbody><site name='s0'/><body name='b' pos='{x} 0 0'><freejoint/>\
             <geom size='.1'/><site name='s1'/></body></worldbody>\
             <tendon><spatial stiffness='1'><site site='s0'/><site site='s1'/></spatial></tendon>\
             </mujoco>"
        )
    };
    assert_ne!(key(tendon("1")), key(tendon("2")));
    // A muscle's length range is simulated from every dynamic value; colours still patch.
    let muscle = |damping: &str, rgba: &str| {
        format!(
            "<mujoco><worldbody><body name='b'><joint name='j' damping='{damping}'/>\
             <geom name='g' size='.1' pos='.2 0 0' rgba='{rgba}'/></body></worldbody>\
             <actuator><muscle joint='j'/></actuator></mujoco>"
        )
    };
    assert_ne!(key(muscle("1", "1 0 0 1")), key(muscle("2", "1 0 0 1")));
    assert_eq!(key(muscle("1", "1 0 0 1")), key(muscle("1", "0 1 0 1")));
    // Values MuJoCo checks are patched only where it takes them as written.
    let inertia = |d: &str| {
        format!(
            "<mujoco><worldbody><body name='b'><freejoint/>\
             <inertial pos='0 0 0' mass='1' diaginertia='{d}'/></body></worldbody></mujoco>"
        )
    };
    assert_eq!(key(inertia("1 1 1")), key(inertia("1 2 2")));
    assert_ne!(key(inertia("1 1 1")), key(inertia("1 1 3")));
}

#[test]
fn sizes_of_primitive_geoms_are_patched_through_their_bodies_body_models() {
    let xml = |a: &str, r: &str, b: &str| {
        format!(
            r#"<mujoco><compiler angle="degree"/><asset><material name="m" rgba="1 0 0 1"/></asset>
            <worldbody><geom name="floor" type="plane" size="1 1 0.1"/>
            <body name="cube" pos="0 0 0.1"><freejoint/>
              <geom name="c" type="box" size="{a}" material="m" euler="0 0 30"/>
              <geom name="c_vis" type="box" size="{a}" contype="0" conaffinity="0" group="1" mass="0"/></body>
            <body name="arm" pos="0.3 0 0.2"><joint name="j" axis="0 1 0"/>
              <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>
              <geom type="capsule" size="{r} 0.1"/><geom type="cylinder" size="{r} 0.05" pos="0 0 0.1"/></body>
            <body name="pair" pos="0 0.3 0.1"><freejoint/><geom type="box" size="{b}"/>
              <geom type="box" size="{b}"/></body>
            </worldbody></mujoco>"#
        )
    };
    let mut cache = DocumentCache::new(4, None);
    let mut rng = Rng(7);
    let mut keys = std::collections::HashSet::new();
    for k in 0..6 {
        let a = list(&[
            rng.uniform(0.02, 0.04),
            rng.uniform(0.02, 0.04),
            rng.uniform(0.02, 0.04),
        ]);
        let r = list(&[rng.uniform(0.01, 0.03)]);
        let mut b = [
            rng.uniform(0.01, 0.03),
            rng.uniform(0.01, 0.03),
            rng.uniform(0.01, 0.03),
        ];
        b.sort_by(f64::total_cmp);
        let doc = Document::from_str(&xml(&a, &r, &list(&b)), ".").unwrap();
        keys.insert(
            mjcf_forge::split::split_document_with(
                &doc,
                mjcf_forge::split::SplitOptions { body_models: true },
            )
            .structure_key,
        );
        exact(&mut cache, &doc, &format!("sizes {k}"));
    }
    assert_eq!(keys.len(), 1);
    assert_eq!((cache.compiles(), cache.patches()), (1, 5));
    // Boxes in the other order turn the pair's principal axes (body_sameframe): compiled.
    let turned = Document::from_str(&xml("0.03 0.03 0.03", "0.02", "0.03 0.02 0.01"), ".").unwrap();
    exact(&mut cache, &turned, "turned");
    assert_eq!(cache.compiles(), 2);
}

#[test]
fn files_meant_for_inclusion_are_answered_as_mujoco_compiles_them() {
    // Bodies and frames directly under <mujoco> (a file meant to be included into a
    // <worldbody>): MuJoCo reads them and compiles the file to the world alone. The cache
    // answers the same, for the first document of a structure and for its patches (the
    // timestep), and for other values in what MuJoCo leaves out (in the key: compiled).
    let mut cache = DocumentCache::new(4, None);
    for (k, mass) in ["1", "1", "1", "2.5"].iter().enumerate() {
        let text = format!(
            r#"<mujoco model="part"><option timestep="0.00{}"/>
                 <body name="b" pos="0 0 1"><geom name="g" size="0.1" mass="{mass}" rgba="1 0 0 1"/></body>
                 <frame pos="1 0 0"><body name="c"><joint name="j" damping="{mass}"/><geom size="0.2"/></body></frame>
               </mujoco>"#,
            k + 1
        );
        let doc = Document::from_str(&text, ".").unwrap();
        exact(&mut cache, &doc, &format!("fragment {k}"));
    }
    assert_eq!((cache.compiles(), cache.patches()), (2, 2));
}
