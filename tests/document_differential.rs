//! The document caches against MuJoCo on random documents (`fuzzing::random_mjcf`): every
//! answer of `DocumentCache::model` equals MuJoCo compiling the same text, bit for bit in
//! every array and statistic, or both refuse it; a random scene's variants likewise, what
//! follows from mass properties a unit model combines (geom densities) within 1e-12
//! relative. Fixed seeds here (a short run in CI); the long campaigns are
//! `scripts/differential.sh`'s, with their results in docs/limits.md.
//!
//! Pass: once per MuJoCo the feature `mujoco` links (scripts/test.sh: 3.17.0 and 4.0.0),
//! since what it checks depends on that MuJoCo (a build without the feature has none of it).

#![cfg(mjcf_mujoco)]

use std::path::Path;

use mjcf_forge::Document;
use mjcf_forge::compiled::DocumentCache;
use mjcf_forge::fuzzing::random_mjcf;
use mjcf_forge::mujoco::compile_str;

/// Seeds and variants of the run: `MJCF_FORGE_DIFFERENTIAL=SEEDS,VARIANTS` (e.g.
/// `2000,8`) for a longer one.
fn extent() -> (u64, u64) {
    std::env::var("MJCF_FORGE_DIFFERENTIAL")
        .ok()
        .and_then(|v| {
            let (a, b) = v.split_once(',')?;
            Some((a.trim().parse().ok()?, b.trim().parse().ok()?))
        })
        .unwrap_or((60, 6))
}

/// What a cache's answer is against MuJoCo's own verdict on the same input: `Some(true)`
/// answered alike, `Some(false)` refused by both, `None` a finding (pushed, named by
/// `what`).
fn verdict<E1: std::fmt::Display, E2: std::fmt::Display>(
    what: &str,
    want: Result<mjcf_forge::mujoco::CompiledModel, E1>,
    got: Result<&mjcf_forge::mujoco::CompiledModel, E2>,
    findings: &mut Vec<String>,
) -> Option<bool> {
    verdict_within(what, want, got, findings, None)
}

/// [`verdict`], with `bound`: the arrays of [`MASS_DERIVED`] within it, the rest bit for
/// bit.
fn verdict_within<E1: std::fmt::Display, E2: std::fmt::Display>(
    what: &str,
    want: Result<mjcf_forge::mujoco::CompiledModel, E1>,
    got: Result<&mjcf_forge::mujoco::CompiledModel, E2>,
    findings: &mut Vec<String>,
    bound: Option<f64>,
) -> Option<bool> {
    match (want, got) {
        (Ok(want), Ok(got)) => {
            let mut diffs = got.differences(&want);
            if let Some(bound) = bound {
                diffs.retain(|d| {
                    !mjcf_forge::split::MASS_DERIVED
                        .iter()
                        .any(|a| d.starts_with(a))
                });
                diffs.extend(got.differences_beyond(&want, bound));
            }
            if diffs.is_empty() {
                return Some(true);
            }
            findings.push(format!("{what}: {diffs:?}"));
        }
        (Err(_), Err(_)) => return Some(false),
        (Ok(_), Err(e)) => findings.push(format!(
            "{what}: MuJoCo compiles it, the cache refuses: {e}"
        )),
        (Err(e), Ok(_)) => findings.push(format!(
            "{what}: MuJoCo refuses it ({e}), the cache answers"
        )),
    }
    None
}

#[test]
fn random_documents_are_answered_as_mujoco_compiles_them() {
    let (seeds, variants) = extent();
    let mut cache = DocumentCache::new(8, None);
    let mut findings = Vec::new();
    let (mut answered, mut refused) = (0u64, 0u64);
    for seed in 0..seeds {
        for variant in 0..variants {
            let text = random_mjcf(seed, variant);
            let want = compile_str(&text, Path::new("."));
            let doc = match Document::from_str(&text, ".") {
                Ok(doc) => doc,
                Err(e) => {
                    if want.is_ok() {
                        findings.push(format!(
                            "{seed}/{variant}: MuJoCo compiles it, we cannot read it: {e}"
                        ));
                    }
                    continue;
                }
            };
            match verdict(
                &format!("{seed}/{variant}"),
                want,
                cache.model(&doc),
                &mut findings,
            ) {
                Some(true) => answered += 1,
                Some(false) => refused += 1,
                None => {}
            }
        }
    }
    assert!(
        findings.is_empty(),
        "{} findings:\n{}",
        findings.len(),
        findings.join("\n")
    );
    // The run exercised both ways of answering.
    assert!(
        answered >= seeds * variants / 2,
        "{answered} answered, {refused} refused"
    );
    assert!(
        cache.patches() >= answered / 6,
        "{} patches of {answered}",
        cache.patches()
    );
    eprintln!(
        "{answered} answered ({} compiles, {} patches), {refused} refused by both",
        cache.compiles(),
        cache.patches()
    );
}

/// `scene`'s files written into a fresh folder of the system's temporary one.
fn written(seed: u64, scene: &mjcf_forge::fuzzing::RandomScene) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "mjcf-forge-differential-{}-{seed}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in &scene.files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    std::fs::write(dir.join("scene.toml"), &scene.toml).unwrap();
    dir
}

#[test]
fn random_scenes_variants_are_patched_as_mujoco_compiles_them() {
    use mjcf_forge::compiled::ModelCache;
    use mjcf_forge::fuzzing::random_scene;
    use mjcf_forge::scene::Scene;
    let (seeds, variants) = extent();
    let (seeds, variants) = (seeds / 2, variants + 4);
    let mut findings = Vec::new();
    let (mut answered, mut patches, mut refused) = (0u64, 0u64, 0u64);
    let mut supersets = 0u64;
    for seed in 0..seeds {
        let random = random_scene(seed);
        let dir = written(seed, &random);
        let scene = match Scene::load(dir.join("scene.toml")) {
            Ok(scene) => scene,
            Err(_) => {
                // A scene file the loader refuses (a randomizer that selects nothing...):
                // no variant to judge.
                refused += 1;
                let _ = std::fs::remove_dir_all(&dir);
                continue;
            }
        };
        let mut cache = ModelCache::new(&scene, 4, None);
        for i in 0..variants {
            let (xml, _) = scene.variant_xml(i).unwrap();
            let what = format!("scene {seed}, variant {i}");
            if verdict_within(
                &what,
                compile_str(&xml, &dir),
                cache.model(i),
                &mut findings,
                Some(1e-12),
            ) == Some(true)
            {
                answered += 1;
            }
        }
        patches += cache.patches();
        supersets += superset_findings(&scene, &dir, variants.min(4), &mut findings);
        let _ = std::fs::remove_dir_all(&dir);
    }
    assert!(
        findings.is_empty(),
        "{} findings:\n{}",
        findings.len(),
        findings.join("\n")
    );
    assert!(
        answered >= seeds * variants / 2,
        "{answered} answered, {refused} scenes refused"
    );
    assert!(patches >= answered / 8, "{patches} patches of {answered}");
    assert!(
        supersets >= seeds / 8,
        "{supersets} supersets of {seeds} scenes"
    );
    eprintln!(
        "scenes: {answered} variants answered ({patches} patches), {supersets} supersets judged, {refused} of {seeds} scenes refused when loading"
    );
}

#[test]
fn random_documents_with_includes_are_answered_as_mujoco_compiles_them() {
    use mjcf_forge::fuzzing::random_mjcf_files;
    use mjcf_forge::mujoco::compile_file;
    let (seeds, variants) = extent();
    let mut cache = DocumentCache::new(8, None);
    let mut findings = Vec::new();
    let mut included = 0u64;
    for seed in 0..seeds * 2 {
        if random_mjcf_files(seed, 0).len() < 2 {
            continue;
        }
        let dir =
            std::env::temp_dir().join(format!("mjcf-forge-include-{}-{seed}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for variant in 0..variants {
            let files = random_mjcf_files(seed, variant);
            for (name, text) in &files {
                std::fs::write(dir.join(name), text).unwrap();
            }
            let path = dir.join("model.xml");
            let want = compile_file(&path);
            let Ok(doc) = Document::load(&path) else {
                if want.is_ok() {
                    findings.push(format!(
                        "{seed}/{variant}: MuJoCo compiles it, we cannot load it"
                    ));
                }
                continue;
            };
            included += u64::from(files.len() == 2);
            verdict(
                &format!("{seed}/{variant}"),
                want,
                cache.model(&doc),
                &mut findings,
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    assert!(
        findings.is_empty(),
        "{} findings:\n{}",
        findings.len(),
        findings.join("\n")
    );
    assert!(included >= seeds, "{included} documents with an include");
    eprintln!("includes: {included} documents with an include judged");
}

/// `scene`'s superset patched for variants `0..n` in turn: every body of each variant's own
/// compile has the same mass, inertia and frames (bit for bit) under its superset name.
/// Returns 1 when the superset was judged, 0 when the scene has none (refused, said so).
fn superset_findings(
    scene: &mjcf_forge::scene::Scene,
    dir: &Path,
    n: u64,
    findings: &mut Vec<String>,
) -> u64 {
    use mjcf_forge::compiled::ModelCache;
    use mjcf_forge::mujoco::ObjType;
    let Ok(superset) = scene.superset() else {
        return 0;
    };
    let Ok(mut cache) = ModelCache::new(scene, 2, None).with_superset() else {
        return 0;
    };
    for i in 0..n {
        let (xml, _) = scene.variant_xml(i).unwrap();
        let Ok(want) = compile_str(&xml, dir) else {
            continue;
        };
        let Ok(tags) = scene.superset_names(&superset, i) else {
            return 0;
        };
        let Ok(got) = cache.model(i) else {
            return 0;
        };
        let names = got.names(ObjType::Body);
        for (b, name) in want.names(ObjType::Body).iter().enumerate().skip(1) {
            let tagged = tags
                .iter()
                .find(|(p, _)| name.starts_with(p.as_str()))
                .map_or(name.clone(), |(_, t)| format!("{t}{name}"));
            let Some(k) = names.iter().position(|x| *x == tagged) else {
                findings.push(format!("variant {i}: no body {tagged} in the superset"));
                continue;
            };
            let rows = |a: &[f64], w: usize, r: usize| a[w * r..w * (r + 1)].to_vec();
            // Inertias and principal axes within 1e-12 where a unit model combines the
            // geoms (relative; the axes' unit vectors, absolute).
            let close = |a: Vec<f64>, b: Vec<f64>, floor: f64| {
                a.iter()
                    .zip(&b)
                    .all(|(x, y)| (x - y).abs() <= 1e-12 * x.abs().max(y.abs()).max(floor))
            };
            let same = got.body_mass()[k].to_bits() == want.body_mass()[b].to_bits()
                && close(
                    rows(got.body_inertia(), 3, k),
                    rows(want.body_inertia(), 3, b),
                    0.0,
                )
                && rows(got.body_ipos(), 3, k) == rows(want.body_ipos(), 3, b)
                && close(
                    rows(got.body_iquat(), 4, k),
                    rows(want.body_iquat(), 4, b),
                    1.0,
                );
            if !same {
                findings.push(format!("variant {i}: body {name} differs in the superset"));
            }
        }
    }
    1
}
