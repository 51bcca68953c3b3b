//! The Rust `ModelCache` (feature `mujoco`): every patched model equals,
//! bit for bit in every array and statistic, MuJoCo compiling the variant's XML.
//!
//! Pass: once per MuJoCo the feature `mujoco` links (scripts/test.sh: 3.17.0 and 4.0.0),
//! since what it checks depends on that MuJoCo (a build without the feature has none of it).

#![cfg(mjcf_mujoco)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use mjcf_forge::ErrorKind;
use mjcf_forge::compiled::ModelCache;
use mjcf_forge::mujoco::{CompiledModel, compile_str};
use mjcf_forge::scene::Scene;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn compiled(scene: &Scene, i: u64) -> CompiledModel {
    let (xml, _) = scene.variant_xml(i).unwrap();
    compile_str(&xml, Path::new(".")).unwrap()
}

/// A variant's name as the superset has it: its candidate's tag before it (`tags` from
/// `Scene::superset_names`), or as it is for the template's names.
fn superset_name(tags: &[(String, String)], name: &str) -> String {
    tags.iter()
        .find(|(p, _)| name.starts_with(p.as_str()))
        .map_or(name.to_string(), |(_, t)| format!("{t}{name}"))
}

/// A unit model's patch against MuJoCo's compile: what follows from mass properties
/// ([`mjcf_forge::split::MASS_DERIVED`]) within 1e-12 relative, the rest bit for bit.
fn within_mass_bound(got: &CompiledModel, want: &CompiledModel, i: u64) {
    assert_eq!(got.differences_beyond(want, 1e-12), Vec::<String>::new());
    for d in got.differences(want) {
        assert!(
            mjcf_forge::split::MASS_DERIVED
                .iter()
                .any(|a| d.starts_with(a)),
            "variant {i}: {d}"
        );
    }
}

fn by_structure(scene: &Scene, n: u64) -> HashMap<String, Vec<u64>> {
    let mut groups: HashMap<String, Vec<u64>> = HashMap::new();
    for i in 0..n {
        groups
            .entry(scene.patch(i).unwrap().structure_key)
            .or_default()
            .push(i);
    }
    groups
}

#[test]
fn every_patchable_kind_is_patched_bit_for_bit() {
    let scene = Scene::load(root().join("corpora/scenes/patch/patch.toml")).unwrap();
    let groups = by_structure(&scene, 24);
    assert_eq!(groups.len(), 4);
    let mut cache = ModelCache::new(&scene, 4, None);
    for indices in groups.values() {
        for &i in indices.iter().take(4) {
            let want = compiled(&scene, i);
            let got = cache.model(i).unwrap();
            assert_eq!(got.differences(&want), Vec::<String>::new(), "variant {i}");
        }
    }
    assert_eq!(cache.compiles(), 4);
    assert!(cache.patches() > 0);
}

#[test]
fn apply_patches_a_model_of_ones_own_and_refuses_another_structure() {
    let scene = Scene::load(root().join("corpora/scenes/patch/patch.toml")).unwrap();
    let groups: Vec<Vec<u64>> = by_structure(&scene, 24).into_values().collect();
    let mut cache = ModelCache::new(&scene, 8, None);
    let (a, b) = (groups[0].clone(), groups[1].clone());
    let mut mine = cache.model(a[0]).unwrap().clone();
    for &i in &a[1..] {
        cache.apply(i, &mut mine).unwrap();
        assert_eq!(mine.differences(&compiled(&scene, i)), Vec::<String>::new());
    }
    let err = cache.apply(b[0], &mut mine).unwrap_err();
    assert!(
        matches!(
            &err.first().kind,
            ErrorKind::OtherStructure { found: Some(_), .. }
        ),
        "{err:?}"
    );
    assert!(
        err.to_string()
            .contains("a patch cannot change a structure"),
        "{err}"
    );
    let mut fresh = compiled(&scene, a[0]);
    let err = cache.apply(b[0], &mut fresh).unwrap_err();
    assert!(
        matches!(
            &err.first().kind,
            ErrorKind::OtherStructure { found: None, .. }
        ),
        "{err:?}"
    );
    assert!(
        err.to_string().contains("does not have the structure"),
        "{err}"
    );
}

#[test]
fn the_cache_is_bounded() {
    let scene = Scene::load(root().join("corpora/scenes/patch/patch.toml")).unwrap();
    let firsts: Vec<u64> = by_structure(&scene, 24).values().map(|v| v[0]).collect();
    let mut cache = ModelCache::new(&scene, 2, None);
    for &i in &firsts {
        cache.model(i).unwrap();
    }
    assert_eq!(cache.len(), 2);
    let mut one = ModelCache::new(&scene, 8, None);
    one.model(firsts[0]).unwrap();
    let mut small = ModelCache::new(&scene, 8, Some(one.nbytes() + 1));
    for &i in &firsts {
        small.model(i).unwrap();
    }
    assert_eq!(small.len(), 1);
}

#[test]
fn demo_and_lift5_fixed_are_exact() {
    let demo = Scene::demo().unwrap();
    let mut cache = ModelCache::new(&demo, 16, None);
    for i in 0..6 {
        let want = compiled(&demo, i);
        assert_eq!(
            cache.model(i).unwrap().differences(&want),
            Vec::<String>::new()
        );
    }
    let lift = root().join("benches/scenes/lift5_fixed.toml");
    assert!(
        root().join(".cache/corpus/robosuite-1.5.2").is_dir(),
        ".cache/corpus/robosuite-1.5.2 is missing: run scripts/setup.sh first"
    );
    let scene = Scene::load(lift).unwrap();
    let mut cache = ModelCache::new(&scene, 2, None);
    for i in 0..5 {
        let want = compiled(&scene, i);
        assert_eq!(
            cache.model(i).unwrap().differences(&want),
            Vec::<String>::new(),
            "variant {i}"
        );
    }
    assert_eq!((cache.compiles(), cache.patches()), (1, 4));
}

#[test]
fn discard_visual_variants_are_patched_bit_for_bit() {
    let dir = root().join("corpora/scenes/patch");
    let text = std::fs::read_to_string(dir.join("patch.toml")).unwrap();
    let scene = Scene::from_toml_str(&format!("discard_visual = true\n{text}"), &dir).unwrap();
    let (xml, _) = scene.variant_xml(0).unwrap();
    assert!(xml.contains(r#"discardvisual="true""#));
    let mut cache = ModelCache::new(&scene, 4, None);
    for indices in by_structure(&scene, 16).values() {
        for &i in indices.iter().take(3) {
            let want = compiled(&scene, i);
            assert_eq!(
                cache.model(i).unwrap().differences(&want),
                Vec::<String>::new(),
                "variant {i}"
            );
        }
    }
    assert!(cache.patches() > 0);
}

#[test]
fn superset_holds_every_variant() {
    use mjcf_forge::mujoco::ObjType;
    let scene = Scene::load(root().join("corpora/scenes/patch/patch.toml")).unwrap();
    let superset = scene.superset().unwrap();
    let mut cache = ModelCache::new(&scene, 2, None).with_superset().unwrap();
    for i in 0..6 {
        let want = compiled(&scene, i);
        let tags = scene.superset_names(&superset, i).unwrap();
        let name = |n: &str| superset_name(&tags, n);
        let got = cache.model(i).unwrap();
        let (got_bodies, got_geoms) = (got.names(ObjType::Body), got.names(ObjType::Geom));
        for (b, n) in want.names(ObjType::Body).iter().enumerate().skip(1) {
            let k = got_bodies.iter().position(|x| *x == name(n)).unwrap();
            assert_eq!(got.body_mass()[k], want.body_mass()[b], "variant {i}: {n}");
            assert_eq!(
                got.body_pos()[3 * k..3 * k + 3],
                want.body_pos()[3 * b..3 * b + 3]
            );
            assert_eq!(
                got.body_quat()[4 * k..4 * k + 4],
                want.body_quat()[4 * b..4 * b + 4]
            );
            assert_eq!(
                got.body_inertia()[3 * k..3 * k + 3],
                want.body_inertia()[3 * b..3 * b + 3]
            );
            assert_eq!(
                got.body_ipos()[3 * k..3 * k + 3],
                want.body_ipos()[3 * b..3 * b + 3]
            );
        }
        for (g, n) in want.names(ObjType::Geom).iter().enumerate() {
            if n.is_empty() {
                continue;
            }
            let k = got_geoms.iter().position(|x| *x == name(n)).unwrap();
            assert_eq!(
                got.geom_rgba()[4 * k..4 * k + 4],
                want.geom_rgba()[4 * g..4 * g + 4],
                "variant {i}: {n}"
            );
            assert_eq!(
                got.geom_friction()[3 * k..3 * k + 3],
                want.geom_friction()[3 * g..3 * g + 3]
            );
            assert_eq!(
                got.geom_size()[3 * k..3 * k + 3],
                want.geom_size()[3 * g..3 * g + 3]
            );
        }
        // The same contacts at the initial pose: parked objects touch nothing.
        let pairs = |m: &CompiledModel, rename: &dyn Fn(&str) -> String| {
            let geoms = m.names(ObjType::Geom);
            let mut v: Vec<(String, String)> = m
                .initial_contacts()
                .iter()
                .map(|c| {
                    let (a, b) = (rename(&geoms[c.geom1]), rename(&geoms[c.geom2]));
                    if a < b { (a, b) } else { (b, a) }
                })
                .collect();
            v.sort();
            v
        };
        let got = cache.model(i).unwrap();
        assert_eq!(pairs(got, &|n: &str| n.to_string()), pairs(&want, &name));
    }
    assert_eq!(cache.compiles(), 1);
}

#[test]
fn aligned_free_bodies_make_their_poses_structure() {
    let scene = Scene::load(root().join("corpora/scenes/patch/aligned.toml")).unwrap();
    let mut cache = ModelCache::new(&scene, 4, None);
    let mut aligned = 0;
    for i in 0..8 {
        let (xml, _) = scene.variant_xml(i).unwrap();
        let patch = scene.patch(i).unwrap();
        if xml.contains(r#"align="true""#) {
            aligned += 1;
            // The object's pose is not in the patch: it is compiled.
            assert!(
                !patch
                    .entries
                    .iter()
                    .any(|e| e.field == "qpos0" || e.field == "pos"),
                "variant {i}"
            );
        }
        let got = cache.model(i).unwrap();
        assert_eq!(
            got.differences(&compiled(&scene, i)),
            Vec::<String>::new(),
            "variant {i}"
        );
    }
    assert!(aligned >= 4, "{aligned} variants with an aligned object");
}

#[test]
fn placements_under_keyframes_are_patched_bit_for_bit() {
    // Each key's rows for a placed object's free joint are its pose: patched with it.
    let scene = Scene::load(root().join("corpora/scenes/keyframe/keyframe.toml")).unwrap();
    let groups = by_structure(&scene, 16);
    // One or two objects, each a box or a cylinder: six structures at most, whatever the
    // placements.
    assert!(groups.len() <= 6, "{} structures", groups.len());
    let mut cache = ModelCache::new(&scene, 8, None);
    for indices in groups.values() {
        for &i in indices.iter().take(4) {
            let want = compiled(&scene, i);
            let got = cache.model(i).unwrap();
            assert_eq!(got.differences(&want), Vec::<String>::new(), "variant {i}");
        }
    }
    assert_eq!(cache.compiles(), groups.len() as u64);
    assert!(cache.patches() > 0);
    // Every variant is a patch of the superset (structures of one, two objects).
    let superset = scene.superset().unwrap();
    for i in 0..6 {
        let patch = scene.superset_patch(&superset, i).unwrap();
        assert!(patch.entries.iter().any(|e| e.field == "key_qpos"));
    }
}

#[test]
fn armature_beside_a_damping_ratio_is_compiled() {
    // The compiler derives a damping ratio's damping from the joint-space inertia at qpos0
    // (armature included): armature is structure there, colours stay patches.
    let scene = Scene::load(root().join("corpora/scenes/patch/dampratio.toml")).unwrap();
    let groups = by_structure(&scene, 4);
    assert_eq!(groups.len(), 4, "each armature draw is a structure");
    let patch = scene.patch(0).unwrap();
    assert!(patch.entries.iter().all(|e| e.field != "armature"));
    assert!(patch.entries.iter().any(|e| e.field == "rgba"));
    let mut cache = ModelCache::new(&scene, 4, None);
    for i in 0..4 {
        let want = compiled(&scene, i);
        let got = cache.model(i).unwrap();
        assert_eq!(got.differences(&want), Vec::<String>::new(), "variant {i}");
    }
}

#[test]
fn geom_sizes_frames_and_densities_are_carried_by_body_models() {
    // What MuJoCo derives from them comes from compiling the body's geoms alone: one
    // structure, every variant exact (a variant whose geoms turn the body's inertial frame
    // is compiled instead).
    let scene = Scene::load(root().join("corpora/scenes/patch/geoms.toml")).unwrap();
    assert_eq!(by_structure(&scene, 8).len(), 1);
    let mut cache = ModelCache::new(&scene, 2, None);
    for i in 0..8 {
        let want = compiled(&scene, i);
        let got = cache.model(i).unwrap();
        assert_eq!(got.differences(&want), Vec::<String>::new(), "variant {i}");
    }
    assert_eq!(cache.compiles() + cache.patches(), 8);
    assert!(cache.patches() >= 4);
    // The demo turns a block's slab: its superset carries it.
    let demo = Scene::demo().unwrap();
    let superset = demo.superset().unwrap();
    let patch = demo.superset_patch(&superset, 0).unwrap();
    assert!(patch.entries.iter().any(|e| e.field == "geoms"));
}

#[test]
fn mass_of_bodies_without_inertial_scales_their_geoms() {
    use mjcf_forge::mujoco::ObjType;
    // What the scaled densities compile to, against the same variant without the mass
    // randomizer: each object's mass and inertia multiplied by one factor in the drawn
    // range, its centre of mass and principal axes unchanged.
    let dir = root().join("corpora/scenes/patch");
    let text = std::fs::read_to_string(dir.join("mass.toml")).unwrap();
    let scene = Scene::from_toml_str(&text, &dir).unwrap();
    let cut = text.find("[[randomize]]").unwrap();
    let plain = Scene::from_toml_str(&text[..cut], &dir).unwrap();
    let mut kinds = std::collections::HashSet::new();
    for i in 0..8 {
        let (got, want) = (compiled(&scene, i), compiled(&plain, i));
        assert_eq!(got.names(ObjType::Body), want.names(ObjType::Body));
        for (b, name) in want.names(ObjType::Body).iter().enumerate() {
            if !name.starts_with("clutter") {
                assert_eq!(got.body_mass()[b], want.body_mass()[b], "{name}");
                continue;
            }
            kinds.insert(name.split('_').nth(1).unwrap().to_string());
            let factor = got.body_mass()[b] / want.body_mass()[b];
            assert!(
                (0.5..=2.0).contains(&factor),
                "variant {i}: {name}: {factor}"
            );
            for k in 0..3 {
                let r = got.body_inertia()[3 * b + k] / want.body_inertia()[3 * b + k];
                assert!((r / factor - 1.0).abs() < 1e-9, "variant {i}: {name}");
                let (p, q) = (got.body_ipos()[3 * b + k], want.body_ipos()[3 * b + k]);
                assert!((p - q).abs() < 1e-12, "variant {i}: {name}");
            }
        }
        // The variant's record: every geom of the object, one factor per body.
        let (_, params) = scene.variant_xml(i).unwrap();
        assert!(params.to_json(i, None).contains("\"density\""));
    }
    assert_eq!(kinds.len(), 3, "box, framed and meshbox drawn: {kinds:?}");
    // Patches: the densities of each body's geoms through its unit model, compiled once
    // (no mesh processed per variant), so masses and inertial frames are MuJoCo's within
    // 1e-12 relative (its eigen-decomposition's last bits), everything else bit for bit;
    // the superset holds them.
    let mut cache = ModelCache::new(&scene, 4, None);
    for indices in by_structure(&scene, 24).values() {
        for &i in indices.iter().take(3) {
            within_mass_bound(cache.model(i).unwrap(), &compiled(&scene, i), i);
        }
    }
    let groups: Vec<usize> = by_structure(&scene, 24).values().map(Vec::len).collect();
    assert!(
        cache.patches() >= 4,
        "{} patches, {} compiles, groups {groups:?}",
        cache.patches(),
        cache.compiles()
    );
    let superset = scene.superset().unwrap();
    let mut cache = ModelCache::new(&scene, 2, None).with_superset().unwrap();
    for i in 0..6 {
        superset_masses_are_the_variants(&scene, &superset, &mut cache, i, true);
    }
    assert_eq!(cache.compiles(), 1);
}

#[test]
fn densities_per_geom_are_patches_of_unit_models() {
    // densities.toml: a density (or mass) drawn per geom of bodies of several geoms, a mesh
    // and a frame among them. Each body's unit model is compiled once; per variant the
    // centre of mass moves and the principal axes turn, the bounding-volume tree is built
    // again in the new inertial frame (its shape too, where the turn reorders the geoms).
    // Every variant of a structure a patch: what follows from the masses within 1e-12
    // relative of MuJoCo's compile, everything else bit for bit; the superset holds them.
    let scene = Scene::load(root().join("corpora/scenes/patch/densities.toml")).unwrap();
    let patch = scene.patch(0).unwrap();
    assert!(patch.entries.iter().any(|e| e.field == "unit_geoms"));
    assert!(!patch.entries.iter().any(|e| e.field == "geoms"));
    let groups = by_structure(&scene, 16);
    let mut cache = ModelCache::new(&scene, 8, None);
    let mut moved = 0;
    for indices in groups.values() {
        for &i in indices.iter().take(4) {
            let got = cache.model(i).unwrap();
            within_mass_bound(got, &compiled(&scene, i), i);
            moved += usize::from(got.body_ipos() != compiled(&scene, indices[0]).body_ipos());
        }
    }
    assert_eq!(cache.compiles() as usize, groups.len());
    assert!(moved > 0, "no variant moved a centre of mass");
    let superset = scene.superset().unwrap();
    let mut cache = ModelCache::new(&scene, 2, None).with_superset().unwrap();
    for i in 0..6 {
        superset_masses_are_the_variants(&scene, &superset, &mut cache, i, true);
    }
    assert_eq!(cache.compiles(), 1);
}

/// One of a compiled model's body arrays.
type BodyArray = fn(&CompiledModel) -> &[f64];

/// Variant `i` patched into the superset `cache`: every body's mass, inertia and inertial
/// frame are the variant's own compile's, bit for bit; `body_models`: whether its patch carries
/// body models.
fn superset_masses_are_the_variants(
    scene: &Scene,
    superset: &mjcf_forge::scene::Superset,
    cache: &mut ModelCache<'_>,
    i: u64,
    body_models: bool,
) {
    use mjcf_forge::mujoco::ObjType;
    let patch = scene.superset_patch(superset, i).unwrap();
    assert_eq!(
        patch
            .entries
            .iter()
            .any(|e| mjcf_forge::split::MODEL_FIELDS.contains(&e.field)),
        body_models,
        "variant {i}"
    );
    let want = compiled(scene, i);
    let tags = scene.superset_names(superset, i).unwrap();
    let got = cache.model(i).unwrap();
    let got_bodies = got.names(ObjType::Body);
    for (b, n) in want.names(ObjType::Body).iter().enumerate().skip(1) {
        let k = got_bodies
            .iter()
            .position(|x| *x == superset_name(&tags, n))
            .unwrap();
        assert_eq!(got.body_mass()[k], want.body_mass()[b], "variant {i}: {n}");
        let arrays: [(BodyArray, usize); 3] = [
            (CompiledModel::body_inertia, 3),
            (CompiledModel::body_ipos, 3),
            (CompiledModel::body_iquat, 4),
        ];
        // Bit for bit, or within 1e-12 where a unit model combines the geoms.
        for (array, width) in arrays {
            let (g, w) = (array(got), array(&want));
            let (g, w) = (
                &g[width * k..width * (k + 1)],
                &w[width * b..width * (b + 1)],
            );
            let close = g
                .iter()
                .zip(w)
                .all(|(x, y)| (x - y).abs() <= 1e-12 * x.abs().max(y.abs()).max(1.0));
            assert!(
                if body_models { close } else { g == w },
                "variant {i}: {n}: {g:?} {w:?}"
            );
        }
    }
}

#[test]
fn absolute_mass_of_a_body_without_inertial_is_refused_with_the_fix() {
    let dir = root().join("corpora/scenes/patch");
    let text = std::fs::read_to_string(dir.join("mass.toml"))
        .unwrap()
        .replace("scale = true\n", "");
    let err = Scene::from_toml_str(&text, &dir).unwrap_err().to_string();
    assert!(err.contains("its mass comes from its geoms"), "{err}");
    assert!(err.contains("scale = true"), "{err}");
}

#[test]
fn written_inertials_make_masses_patches_of_the_superset() {
    // write_inertials: the objects' bodies carry MuJoCo's own <inertial>, so a mass scale
    // is a patch of that <inertial> (no body model), bit for bit.
    let scene = Scene::load(root().join("corpora/scenes/patch/inertials.toml")).unwrap();
    let superset = scene.superset().unwrap();
    let mut cache = ModelCache::new(&scene, 2, None).with_superset().unwrap();
    for i in 0..6 {
        superset_masses_are_the_variants(&scene, &superset, &mut cache, i, false);
    }
    assert_eq!(cache.compiles(), 1);
}

#[test]
fn masses_of_geom_bodies_are_patches_by_default() {
    use mjcf_forge::mujoco::ObjType;
    // mass_auto.toml: mass.toml with `write_inertials` unset. The build's MuJoCo writes each
    // object body's own <inertial> when the scene loads, so a mass scale is a patch of it
    // (no body model) and the superset compiles once; against mass.toml's variants (the
    // same draws on the geoms' densities), masses and inertias within 1e-12 relative,
    // inertial frames within 1e-12.
    let dir = root().join("corpora/scenes/patch");
    let auto = Scene::load(dir.join("mass_auto.toml")).unwrap();
    let densities = Scene::load(dir.join("mass.toml")).unwrap();
    for i in 0..8 {
        let (xml, _) = auto.variant_xml(i).unwrap();
        assert!(xml.contains("<inertial"), "variant {i}");
        let (got, want) = (compiled(&auto, i), compiled(&densities, i));
        assert_eq!(got.names(ObjType::Body), want.names(ObjType::Body));
        let close = |a: &[f64], b: &[f64], relative: bool| {
            a.iter().zip(b).all(|(x, y)| {
                let d = (x - y).abs();
                if relative && *y != 0.0 {
                    d / y.abs() < 1e-12
                } else {
                    d < 1e-12
                }
            })
        };
        assert!(
            close(got.body_mass(), want.body_mass(), true),
            "variant {i}"
        );
        assert!(
            close(got.body_inertia(), want.body_inertia(), true),
            "variant {i}"
        );
        assert!(
            close(got.body_ipos(), want.body_ipos(), false),
            "variant {i}"
        );
        assert!(
            close(got.body_iquat(), want.body_iquat(), false),
            "variant {i}"
        );
    }
    let superset = auto.superset().unwrap();
    let mut cache = ModelCache::new(&auto, 2, None).with_superset().unwrap();
    for i in 0..6 {
        superset_masses_are_the_variants(&auto, &superset, &mut cache, i, false);
    }
    assert_eq!(cache.compiles(), 1);
}

#[test]
fn per_world_arrays_hold_each_worlds_superset_model() {
    use mjcf_forge::compiled::Dtype;
    let scene = Scene::load(root().join("corpora/scenes/patch/boxes.toml")).unwrap();
    let mut cache = ModelCache::new(&scene, 2, None).with_superset().unwrap();
    let worlds = [3u64, 0, 5, 3, 7];
    let batch = cache.worlds(&worlds).unwrap();
    assert_eq!(batch.world_variant, worlds);
    assert_eq!(batch.parked.len(), worlds.len());
    // Objects stand in different places, have their own colours and frictions per world.
    for name in [
        "qpos0",
        "body_pos",
        "geom_rgba",
        "geom_friction",
        "body_invweight0",
    ] {
        let f = batch
            .field(name)
            .unwrap_or_else(|| panic!("{name} is not per world"));
        assert_eq!(f.to_f64().unwrap().len(), worlds.len() * f.len, "{name}");
    }
    assert_eq!(batch.field("geom_rgba").unwrap().dtype, Dtype::F32);
    assert_eq!(batch.field("body_pos").unwrap().dtype, Dtype::F64);
    assert!(batch.field("geom_type").is_none()); // shared by every world
    // Each world's rows are its variant's superset model, bit for bit, and that model is
    // the variant's own compile (superset_holds_every_variant).
    for (w, &i) in worlds.iter().enumerate() {
        let want = cache.model(i).unwrap().clone();
        let bytes = |v: &[f64]| v.iter().flat_map(|x| x.to_ne_bytes()).collect::<Vec<u8>>();
        let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_ne_bytes()).collect::<Vec<u8>>();
        // A per-world field's row, or the shared model's array.
        let rows = |name: &str, shared: Vec<u8>| {
            batch
                .field(name)
                .map_or(shared, |f| f.row_bytes(w).to_vec())
        };
        let m = &batch.model;
        let arrays = [
            ("body_pos", bytes(m.body_pos()), bytes(want.body_pos())),
            ("body_mass", bytes(m.body_mass()), bytes(want.body_mass())),
            (
                "body_inertia",
                bytes(m.body_inertia()),
                bytes(want.body_inertia()),
            ),
            ("geom_rgba", f32s(m.geom_rgba()), f32s(want.geom_rgba())),
            (
                "geom_friction",
                bytes(m.geom_friction()),
                bytes(want.geom_friction()),
            ),
        ];
        for (name, shared, wanted) in arrays {
            assert_eq!(rows(name, shared), wanted, "world {w}: {name}");
        }
        assert_eq!(
            batch.parked[w],
            scene
                .superset_parked(&scene.superset().unwrap(), i)
                .unwrap()
        );
    }
    // The same variant in two worlds: the same rows.
    for f in &batch.fields {
        assert_eq!(f.row_bytes(0), f.row_bytes(3), "{}", f.name);
    }
    // Bad input, before any array: zero worlds; no superset.
    let none = cache.worlds(&[]).unwrap_err();
    assert_eq!(none.first().kind, ErrorKind::NoWorlds);
    assert!(none.to_string().contains("0 worlds"));
    let mut plain = ModelCache::new(&scene, 2, None);
    let plain_err = plain.worlds(&[0]).unwrap_err();
    assert_eq!(plain_err.first().kind, ErrorKind::NeedsSuperset);
    assert!(plain_err.to_string().contains("with_superset"));
}

/// A superset's worlds derived tree by tree (each placed tree's skeleton through
/// `mj_setConst`, parked trees' values kept, what spans trees on the superset) against
/// `mj_setConst` on the whole model: every array and statistic bit for bit, world after
/// world (placed and parked trees changing between them), and through `apply` into a
/// model of one's own. A scene whose patches write a robot's armature (`patch.toml`) has no
/// tree derivation: `mj_setConst` runs.
#[test]
fn superset_worlds_derived_tree_by_tree_are_mj_setconsts() {
    let mut scenes = vec![
        ("corpora/scenes/patch/mass.toml", true),
        ("corpora/scenes/patch/fixed.toml", true),
        ("corpora/scenes/patch/boxes.toml", true),
        ("corpora/scenes/patch/patch.toml", false),
    ];
    if root().join(".cache/corpus/robosuite-1.5.2").is_dir() {
        scenes.push(("benches/scenes/lift5.toml", true));
    }
    for (path, by_tree) in scenes {
        let scene = Scene::load(root().join(path)).unwrap();
        let mut fast = ModelCache::new(&scene, 2, None).with_superset().unwrap();
        let mut whole = ModelCache::new(&scene, 2, None)
            .with_superset()
            .unwrap()
            .deriving_by_tree(false);
        let n = 12;
        for i in 0..n {
            let want = whole.model(i).unwrap().clone();
            let got = fast.model(i).unwrap();
            assert_eq!(
                got.differences(&want),
                Vec::<String>::new(),
                "{path}: variant {i}"
            );
        }
        assert_eq!(
            fast.derived_by_tree(),
            if by_tree { n } else { 0 },
            "{path}"
        );
        assert_eq!(whole.derived_by_tree(), 0);
        let mut mine = fast.model(0).unwrap().clone();
        for i in [5, 3, 5] {
            fast.apply(i, &mut mine).unwrap();
            let want = whole.model(i).unwrap();
            assert_eq!(
                mine.differences(want),
                Vec::<String>::new(),
                "{path}: apply {i}"
            );
        }
    }
}

#[test]
fn the_patch_plan_refuses_with_errors_of_its_kind() {
    use mjcf_forge::split::{PatchModel, PatchPlan, PatchValues};
    let mut model = compile_str(
        "<mujoco><worldbody><body><joint/><geom size='0.1'/></body></worldbody></mujoco>",
        Path::new("."),
    )
    .unwrap();
    let stat = model.stat();
    let mut plan = PatchPlan::new(&model, "key", 0, stat).unwrap();
    let none: &[&str] = &[];
    let values = PatchValues {
        numbers: &[],
        materials: none,
        bodies: none,
    };
    let e = plan.write(&mut model, values).unwrap_err();
    assert_eq!(
        e.kind,
        ErrorKind::Patch("the plan has no layout to write".into())
    );
    let e = plan.mean_inertia(&mut model, &[]).unwrap_err();
    assert_eq!(e.to_string(), "no dofs to take the mean inertia over");
    assert!(matches!(e.kind, ErrorKind::Patch(_)), "{e:?}");
    // The model's own refusal (an array this MuJoCo does not have) comes back as it is.
    let e = model.target("no_such_array", false).err().unwrap();
    assert_eq!(
        e.kind,
        ErrorKind::Patch("this MuJoCo's mjModel has no array no_such_array".into())
    );
}
