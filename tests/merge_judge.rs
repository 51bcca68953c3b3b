//! Merging judged by MuJoCo on real parts: robosuite robots with grippers in their hands,
//! two instances of one robot, Lift-like scenes (arena, robot, mount, gripper, objects),
//! dm-control models in robosuite arenas, degree/radian and eulerseq mixes, keyframes (kept
//! apart and fused), and every wheel model from outside robosuite and dm-control merged
//! into a robosuite arena. Every part's objects compile to the same values inside the merged
//! model as alone, counts add up, keyframe values sit on the right joints
//! (tests/judge/merge_judge.py).
//!
//! Pass: the build without the feature judges every merge that needs no MuJoCo, once; each
//! build that links MuJoCo (scripts/test.sh: 3.17.0 and 4.0.0) judges only the merges that
//! need it (a part's inertias only MuJoCo knows, aligned free bodies' keyframes).

mod common;

use std::path::{Path, PathBuf};

use common::{root, run_each_judge, scratch, wheel_models_in_every_version};
use mjcf_forge::{Document, MergeOptions, MergePart, XmlModel, XmlModelOptions};

fn rs(rel: &str) -> PathBuf {
    root()
        .join(".cache/corpus/robosuite-1.5.2/robosuite/models/assets")
        .join(rel)
}

fn dm(rel: &str) -> PathBuf {
    root()
        .join(".cache/corpus/dm_control-1.0.50/dm_control")
        .join(rel)
}

fn ours(rel: &str) -> PathBuf {
    root().join("corpora/merge").join(rel)
}

/// A part of a scene: a model file, the instance id it gets (None: kept as is, for a base),
/// and the body of the scene it goes into.
struct Part {
    path: PathBuf,
    idn: Option<String>,
    into: Option<String>,
    /// Prefix the document only (no XmlModel naming): the judge then compares against the
    /// original file with the prefix.
    plain: bool,
    /// Parts merged into this one first (a robot with its gripper), judged in their own case.
    with: Vec<Part>,
}

fn part(path: PathBuf, idn: &str, into: Option<&str>) -> Part {
    Part {
        path,
        idn: Some(idn.to_string()),
        into: into.map(str::to_string),
        plain: false,
        with: Vec::new(),
    }
}

fn base(path: PathBuf) -> Part {
    Part {
        path,
        idn: None,
        into: None,
        plain: true,
        with: Vec::new(),
    }
}

/// One scene: its parts merged in order into the first, which is the base.
struct Case {
    name: String,
    parts: Vec<Part>,
    fuse_keys: bool,
    /// Merged only by a build with MuJoCo (builds without refuse it: merge_rules), so judged
    /// in the linked builds' passes; the others are judged once, by the build without.
    needs_mujoco: bool,
}

/// Loads a part and gives it its prefix (as an XmlModel when it has one root body, else
/// by prefixing the document), with the parts it carries merged in.
fn instance(p: &Part) -> Document {
    let doc = Document::load(&p.path).unwrap_or_else(|e| panic!("{}: {e}", p.path.display()));
    let mut doc = match &p.idn {
        None => doc,
        Some(idn) => {
            let options = XmlModelOptions {
                contact_geom_rgba: None,
                ..XmlModelOptions::default()
            };
            match XmlModel::with_options(doc.clone(), idn, options) {
                Ok(m) if !p.plain => m.into_document(),
                _ => {
                    let mut doc = doc;
                    doc.apply_prefix(&format!("{idn}_")).unwrap();
                    doc
                }
            }
        }
    };
    for w in &p.with {
        let d = instance(w);
        doc.merge(&d, w.into.as_deref(), &MergeOptions::default())
            .unwrap();
    }
    doc
}

/// Writes the case's base, parts and merged scene into `dir`; its entry for the judge, or
/// the merge's error.
fn build(case: &Case, dir: &Path) -> Result<String, String> {
    let base_part = &case.parts[0];
    let mut scene = instance(base_part);
    let base_file = dir.join(format!("{}_base.xml", case.name));
    scene.write_file(&base_file).unwrap();
    let mut parts_json = Vec::new();
    let mut fused_prefixes = vec!["\"\"".to_string()];
    for (i, p) in case.parts.iter().enumerate().skip(1) {
        let doc = instance(p);
        let prefix = p.idn.as_ref().map(|i| format!("{i}_")).unwrap_or_default();
        let (file, judge_prefix) = if p.plain && p.with.is_empty() {
            (p.path.clone(), prefix.clone())
        } else {
            let file = dir.join(format!("{}_part{i}.xml", case.name));
            doc.write_file(&file).unwrap();
            (file, String::new())
        };
        let options = MergeOptions {
            fuse_keys: case.fuse_keys,
            part_prefix: prefix.clone(),
        };
        scene
            .merge(&doc, p.into.as_deref(), &options)
            .map_err(|e| format!("{}: merging {}:\n{e}", case.name, p.path.display()))?;
        parts_json.push(format!(
            "{{\"path\": \"{}\", \"prefix\": \"{judge_prefix}\", \"body\": {}}}",
            file.display(),
            // A JSON string: body names may hold white space such as a tab.
            serde_json::to_string(&p.into).unwrap()
        ));
        fused_prefixes.push(format!("\"{prefix}\""));
    }
    let merged = dir.join(format!("{}_merged.xml", case.name));
    scene.write_file(&merged).unwrap();
    let fused = if case.fuse_keys {
        format!(", \"fused\": {{\"home\": [{}]}}", fused_prefixes.join(", "))
    } else {
        String::new()
    };
    Ok(format!(
        "{{\"name\": \"{}\", \"merged\": \"{}\", \"base\": \"{}\", \"base_prefix\": \"\", \"parts\": [{}]{fused}}}",
        case.name,
        merged.display(),
        base_file.display(),
        parts_json.join(", ")
    ))
}

fn cases() -> Vec<Case> {
    let mut cases = Vec::new();
    let robots = [
        "iiwa", "jaco", "kinova3", "panda", "sawyer", "ur5e", "xarm7", "spot_arm",
    ];
    let grippers = [
        "panda_gripper",
        "rethink_gripper",
        "robotiq_gripper_140",
        "jaco_three_finger_gripper",
    ];
    for r in robots {
        for g in grippers {
            cases.push(Case {
                name: format!("{r}_with_{g}"),
                parts: vec![
                    part(rs(&format!("robots/{r}/robot.xml")), "robot0", None),
                    part(
                        rs(&format!("grippers/{g}.xml")),
                        "gripper0",
                        Some("robot0_right_hand"),
                    ),
                ],
                fuse_keys: false,
                needs_mujoco: false,
            });
        }
    }
    for r in ["panda", "sawyer", "ur5e", "iiwa", "jaco"] {
        cases.push(Case {
            name: format!("two_{r}_in_table_arena"),
            parts: vec![
                base(rs("arenas/table_arena.xml")),
                part(rs(&format!("robots/{r}/robot.xml")), "robot0", None),
                part(rs(&format!("robots/{r}/robot.xml")), "robot1", None),
            ],
            fuse_keys: false,
            needs_mujoco: false,
        });
    }
    let objects = [
        "objects/can.xml",
        "objects/milk.xml",
        "objects/bread.xml",
        "objects/cereal.xml",
        "objects/lemon.xml",
    ];
    for (r, g) in [
        ("panda", "panda_gripper"),
        ("sawyer", "rethink_gripper"),
        ("iiwa", "robotiq_gripper_140"),
        ("ur5e", "robotiq_gripper_140"),
        ("kinova3", "robotiq_gripper_140"),
    ] {
        let mut robot = part(rs(&format!("robots/{r}/robot.xml")), "robot0", None);
        robot.with.push(part(
            rs(&format!("grippers/{g}.xml")),
            "gripper0",
            Some("robot0_right_hand"),
        ));
        robot.with.push(part(
            rs("bases/rethink_mount.xml"),
            "mount0",
            Some("robot0_base"),
        ));
        let mut parts = vec![base(rs("arenas/table_arena.xml")), robot];
        for (i, o) in objects.iter().enumerate() {
            parts.push(part(rs(o), &format!("object{i}"), None));
        }
        cases.push(Case {
            name: format!("lift_like_{r}"),
            parts,
            fuse_keys: false,
            needs_mujoco: false,
        });
    }
    // A URDF arm (read as MuJoCo's importer reads it: its static links fuse) on an MJCF
    // table, a robosuite gripper in its last link, an object beside it: the base takes
    // the arm's fusestatic and keeps its own bodies.
    let kuka = root().join(".cache/corpus/urdf/pybullet-3.2.7/pybullet_data/kuka_iiwa/model.urdf");
    let mut arm = part(kuka, "robot0", None);
    arm.with.push(part(
        rs("grippers/panda_gripper.xml"),
        "gripper0",
        Some("robot0_lbr_iiwa_link_7"),
    ));
    cases.push(Case {
        name: "urdf_kuka_with_panda_gripper_on_table".into(),
        parts: vec![
            base(rs("arenas/table_arena.xml")),
            arm,
            part(rs("objects/can.xml"), "object0", None),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    for (arena, model) in [
        ("arenas/table_arena.xml", "suite/cartpole.xml"),
        ("arenas/table_arena.xml", "suite/acrobot.xml"),
        ("arenas/empty_arena.xml", "suite/reacher.xml"),
        ("arenas/bins_arena.xml", "suite/finger.xml"),
        (
            "arenas/empty_arena.xml",
            "mujoco/testing/assets/cartpole.xml",
        ),
    ] {
        cases.push(Case {
            name: format!(
                "dm_{}_in_{}",
                Path::new(model).file_stem().unwrap().to_string_lossy(),
                Path::new(arena).file_stem().unwrap().to_string_lossy()
            ),
            parts: vec![base(rs(arena)), part(dm(model), "dm0", None)],
            fuse_keys: false,
            needs_mujoco: false,
        });
    }
    // Degree base, radian part with another Euler sequence, keyframes kept apart and fused.
    for fuse in [false, true] {
        cases.push(Case {
            name: format!("arm_degrees_gripper_radians_fused_{fuse}"),
            parts: vec![
                base(ours("arm_with_keys.xml")),
                Part {
                    plain: true,
                    ..part(ours("gripper_radian.xml"), "g0", Some("hand"))
                },
            ],
            fuse_keys: fuse,
            needs_mujoco: false,
        });
    }
    cases.push(Case {
        name: "free_objects_autolimits_off_in_arm_scene".into(),
        parts: vec![
            base(ours("arm_with_keys.xml")),
            part(ours("free_objects_with_key.xml"), "obj", None),
            part(ours("free_objects_with_key.xml"), "obj2", None),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    // Names are exact strings: a part whose names differ from the base's only by white space
    // merges without a prefix (nothing clashes), and a part goes into the base's body
    // "hand\t", not the other part's "hand".
    cases.push(Case {
        name: "arm_into_arm_names_spaced".into(),
        parts: vec![
            base(ours("arm_names_spaced.xml")),
            base(ours("arm_with_keys.xml")),
            Part {
                plain: true,
                ..part(ours("gripper_radian.xml"), "g0", Some("hand\t"))
            },
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    // Parts whose included files include their neighbours and name files beside them.
    cases.push(Case {
        name: "nested_includes_into_arm".into(),
        parts: vec![
            base(ours("arm_with_keys.xml")),
            part(
                root().join("corpora/includes/nested_beside_includer/main.xml"),
                "inc",
                None,
            ),
            part(
                root().join("corpora/includes/strippath/main.xml"),
                "sp",
                None,
            ),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    cases.push(Case {
        name: "robot_radians_into_arm_degrees".into(),
        parts: vec![
            base(ours("arm_with_keys.xml")),
            part(rs("grippers/panda_gripper.xml"), "gripper0", Some("hand")),
            part(ours("free_objects_with_key.xml"), "obj", None),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    // Parts that attach model assets (with `body`, `frame`, the whole model, an unnamed
    // asset, an attach inside the attached model): the attached names come out as the
    // part's prefix + the attach's prefix + their name, into a body and into the world.
    let attach = || root().join("corpora/prefix/attach_model_asset.xml");
    cases.push(Case {
        name: "attach_model_assets_into_attach_model_assets".into(),
        parts: vec![
            base(attach()),
            Part {
                plain: true,
                ..part(attach(), "q", Some("base"))
            },
            Part {
                plain: true,
                ..part(attach(), "r", None)
            },
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    // alignfree differing between base and part: the part's <freejoint>s say their
    // alignment themselves; a `type="free"` joint on a body with children is not aligned
    // by MuJoCo, so it may stay.
    cases.push(Case {
        name: "free_objects_alignfree_into_table".into(),
        parts: vec![
            base(rs("arenas/table_arena.xml")),
            part(ours("free_objects_alignfree.xml"), "obj", None),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    // A base that fuses its static bodies, with parts that do not (robosuite objects, whose
    // outer bodies have no joints, and a robot): every part's body is kept (fuse="false").
    cases.push(Case {
        name: "objects_into_fusestatic_base".into(),
        parts: vec![
            base(ours("table_fusestatic.xml")),
            part(rs("objects/bread.xml"), "bread", Some("door")),
            part(rs("objects/milk.xml"), "milk", None),
            part(ours("free_objects_with_key.xml"), "k", None),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    // With keyframes, both ways: an aligned free body's qpos0 in the keys comes from
    // MuJoCo's compile (builds without MuJoCo refuse: merge_rules).
    {
        cases.push(Case {
            name: "free_objects_alignfree_into_arm".into(),
            parts: vec![
                base(ours("arm_with_keys.xml")),
                part(ours("free_objects_alignfree.xml"), "obj", None),
                part(rs("grippers/panda_gripper.xml"), "gripper0", Some("hand")),
            ],
            fuse_keys: false,
            needs_mujoco: true,
        });
        cases.push(Case {
            name: "free_objects_into_alignfree_base".into(),
            parts: vec![
                base(ours("free_objects_alignfree.xml")),
                part(ours("free_objects_with_key.xml"), "k", None),
            ],
            fuse_keys: false,
            needs_mujoco: true,
        });
    }
    // Keys that <size nkey> adds, in the base and in a part, and user data of another width:
    // next to parts with keys of their own.
    let implicit = || ours("implicit_keys_user_widths.xml");
    cases.push(Case {
        name: "implicit_keys_and_user_widths_into_each_other".into(),
        parts: vec![
            base(implicit()),
            part(implicit(), "k", None),
            part(ours("free_objects_with_key.xml"), "obj", None),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    cases.push(Case {
        name: "implicit_keys_and_user_widths_into_arm".into(),
        parts: vec![
            base(ours("arm_with_keys.xml")),
            Part {
                plain: true,
                ..part(implicit(), "k", None)
            },
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    // Ranges of joints that are not limited stay as written when angles are converted: a
    // radian part into a degree base, and a smaller radian base adopting a degree part's unit.
    cases.push(Case {
        name: "radian_unlimited_ranges_into_degree_arm".into(),
        parts: vec![
            base(ours("arm_with_keys.xml")),
            part(ours("radian_unlimited_ranges.xml"), "r", None),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    cases.push(Case {
        name: "degree_arm_into_radian_unlimited_ranges".into(),
        parts: vec![
            base(ours("radian_unlimited_ranges.xml")),
            part(ours("arm_with_keys.xml"), "a", None),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    // inertiafromgeom="true" into "auto": the <inertial> of bodies that infer nothing from
    // their geoms stays.
    cases.push(Case {
        name: "objects_inertia_from_geom_into_arm".into(),
        parts: vec![
            base(ours("arm_with_keys.xml")),
            part(
                ours("objects_inertia_from_geom_kept_inertials.xml"),
                "t",
                None,
            ),
        ],
        fuse_keys: false,
        needs_mujoco: false,
    });
    // A part with inertiagrouprange="4 5" into a base with "0 5": builds with MuJoCo write
    // the inferred inertias out (mujoco::write_inertials); without MuJoCo it is refused
    // (merge_rules).
    {
        cases.push(Case {
            name: "objects_inertiagroups_4_5_into_arm".into(),
            parts: vec![
                base(ours("arm_with_keys.xml")),
                part(ours("objects_inertiagroups_4_5.xml"), "obj", None),
                part(rs("grippers/panda_gripper.xml"), "gripper0", Some("hand")),
            ],
            fuse_keys: false,
            needs_mujoco: true,
        });
        // Mass settings (settotalmass, boundmass, boundinertia, balanceinertia) and
        // inertiafromgeom="false" in the parts, MuJoCo's defaults in the base.
        cases.push(Case {
            name: "objects_mass_settings_into_arm".into(),
            parts: vec![
                base(ours("arm_with_keys.xml")),
                part(ours("objects_mass_settings.xml"), "m", None),
                part(ours("objects_inertia_from_inertials_only.xml"), "f", None),
                part(ours("objects_inertia_from_geom_total_mass.xml"), "g", None),
            ],
            fuse_keys: false,
            needs_mujoco: true,
        });
    }
    cases
}

/// Every wheel model that every judging MuJoCo compiles (robosuite's and dm-control's, and
/// gymnasium, brax, myo-sim, fancy-gym, gym-xarm, gym-aloha, dexterity: locomotion,
/// musculoskeletal models, arms, hands, their tasks), prefixed as a part of robosuite's empty
/// arena: a base in
/// degrees with MuJoCo's default compiler settings, so radian parts, `inertiafromgeom="true"`
/// and the mass settings (`settotalmass`, `boundmass`...) are converted.
fn corpus_cases() -> Vec<Case> {
    let corpus = root().join(".cache/corpus");
    let models = wheel_models_in_every_version();
    assert!(models.len() >= 200, "{} models", models.len());
    models
        .into_iter()
        .map(|m| {
            let rel = m.strip_prefix(&corpus).unwrap().with_extension("");
            let name: String = rel
                .to_string_lossy()
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
                .collect();
            Case {
                name: format!("corpus_{name}"),
                parts: vec![
                    base(rs("arenas/empty_arena.xml")),
                    Part {
                        plain: true,
                        ..part(m, "m0", None)
                    },
                ],
                fuse_keys: false,
                needs_mujoco: false,
            }
        })
        .collect()
}

/// The cases this build judges: without MuJoCo every case that needs none; with it, only
/// those that need it (the others merge the same way in both builds, so the build without
/// judges them once).
fn this_builds(cases: Vec<Case>) -> Vec<Case> {
    cases
        .into_iter()
        .filter(|c| c.needs_mujoco == cfg!(mjcf_mujoco))
        .collect()
}

#[test]
fn merged_scenes_keep_every_part_s_physics() {
    let dir = scratch("merge");
    let cases = this_builds(cases());
    let least = if cfg!(mjcf_mujoco) { 4 } else { 50 };
    assert!(cases.len() >= least, "{} cases", cases.len());
    judge_merged(&cases, &dir);
}

#[test]
fn corpus_models_merged_into_an_arena_keep_their_physics() {
    let dir = scratch("merge_corpus");
    let mut cases = corpus_cases();
    for case in &mut cases {
        case.needs_mujoco = needs_an_inertia_compiler(case);
    }
    let needing = cases.iter().filter(|c| c.needs_mujoco).count();
    assert!(
        needing >= 20,
        "{needing} corpus models need MuJoCo's inertias"
    );
    // Without MuJoCo, mass settings (Gymnasium's half_cheetah: settotalmass="14") have no
    // exact conversion: such a part must be refused, saying so; a build with MuJoCo judges
    // only those (the others merge as in the build without).
    let cases = if cfg!(mjcf_mujoco) {
        this_builds(cases)
    } else {
        cases
    };
    let refusal = (!cfg!(mjcf_mujoco)).then_some("has no exact conversion");
    // Every case that needs MuJoCo's inertias, and every second of the others (all in
    // scripts/test_full.sh): common::sampled.
    let (needing, others): (Vec<Case>, Vec<Case>) = cases.into_iter().partition(|c| c.needs_mujoco);
    let cases: Vec<Case> = needing.into_iter().chain(common::sampled(others)).collect();
    judge_merged_allowing(&cases, &dir, refusal);
}

/// Whether merging the case's part into its base asks for the inertias only MuJoCo knows
/// (a compiler setting with no exact conversion): a build without MuJoCo refuses it.
fn needs_an_inertia_compiler(case: &Case) -> bool {
    const ASKED: &str = "asked for a compiled inertia";
    let mut scene = instance(&case.parts[0]);
    let part = instance(&case.parts[1]);
    let merged = scene.merge_all_mapped_with(
        &[MergePart {
            doc: &part,
            into: None,
            prefix: "m0_",
        }],
        false,
        &mut |_: &Document| {
            Err(mjcf_forge::Error::new(
                mjcf_forge::ErrorKind::InertiaCompile(ASKED.to_string()),
            ))
        },
    );
    merged.is_err_and(|e| e.to_string().contains(ASKED))
}

/// Builds every case into `dir` and has the merge judge of every MuJoCo version check them.
fn judge_merged(cases: &[Case], dir: &Path) {
    judge_merged_allowing(cases, dir, None);
}

/// [`judge_merged`], where a case whose merge is refused with a message containing
/// `refusal` is left out (any other refusal fails).
fn judge_merged_allowing(cases: &[Case], dir: &Path, refusal: Option<&str>) {
    let (built, refused): (Vec<_>, Vec<_>) =
        cases.iter().map(|c| build(c, dir)).partition(Result::is_ok);
    let (expected, refused): (Vec<String>, Vec<String>) = refused
        .into_iter()
        .filter_map(Result::err)
        .partition(|e| refusal.is_some_and(|r| e.contains(r)));
    assert!(
        refused.is_empty(),
        "merges refused:\n{}",
        refused.join("\n")
    );
    if !expected.is_empty() {
        println!(
            "{} merges refused as expected:\n{}",
            expected.len(),
            expected.join("\n")
        );
    }
    let count = built.len();
    let json = format!(
        "[\n{}\n]\n",
        built
            .into_iter()
            .filter_map(Result::ok)
            .collect::<Vec<_>>()
            .join(",\n")
    );
    let file = dir.join("cases.json");
    std::fs::write(&file, json).unwrap();
    let runs = run_each_judge(|_| {
        vec![
            root().join("tests/judge/merge_judge.py").into(),
            "--cases".into(),
            file.clone().into(),
        ]
    });
    let expected = format!("{count} passed, 0 failed");
    let mut failed = Vec::new();
    for (j, out) in runs {
        let stdout = String::from_utf8_lossy(&out.stdout);
        if !(out.status.success() && stdout.lines().last() == Some(expected.as_str())) {
            failed.push(format!(
                "merge judge, MuJoCo {}:\n{stdout}\n{}",
                j.version,
                String::from_utf8_lossy(&out.stderr)
            ));
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
