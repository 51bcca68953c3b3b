//! Merge rules one by one: refusals with their exact messages, shared assets, and the
//! settings the base overrides reported as warnings (the merged result judged by MuJoCo).
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

mod common;

use common::root;
use mjcf_forge::{Document, MergeOptions};

fn load(rel: &str) -> Document {
    std::env::set_current_dir(root()).unwrap();
    Document::load(rel).unwrap()
}

fn merge_error(part: &str, prefix: &str, into: Option<&str>) -> String {
    merge_error_into("corpora/errors/merge/base.xml", part, prefix, into)
}

/// The message of merging `part` (prefixed) into `base`, which must be refused and leave
/// the base as it was.
fn merge_error_into(base: &str, part: &str, prefix: &str, into: Option<&str>) -> String {
    let mut base = load(base);
    let before = base.to_xml_string();
    let mut part = load(part);
    part.apply_prefix(prefix).unwrap();
    let err = base
        .merge(&part, into, &MergeOptions::default())
        .unwrap_err()
        .to_string();
    assert_eq!(
        before,
        base.to_xml_string(),
        "a failed merge changes nothing"
    );
    err
}

#[test]
fn same_asset_name_with_other_content_names_both_origins() {
    assert_eq!(
        merge_error("corpora/errors/merge/part_asset_conflict.xml", "", None),
        "corpora/errors/merge/part_asset_conflict.xml:3:5: asset <material> 'red' differs from the base's <material> 'red' at corpora/errors/merge/base.xml:3:5"
    );
}

/// Without MuJoCo, mass settings have no conversion (builds with MuJoCo write the part's
/// inertias out: merge_judge, objects_mass_settings_into_arm).
#[cfg(not(mjcf_mujoco))]
#[test]
fn compiler_settings_without_exact_conversion_are_refused() {
    assert_eq!(
        merge_error("corpora/errors/merge/part_settotalmass.xml", "p_", None),
        "corpora/errors/merge/part_settotalmass.xml:2:3: cannot merge: compiler settotalmass=\"2\" differs from the base's \"-1\" and has no exact conversion: writing the part's inertias out needs a build with the `mujoco` feature"
    );
}

/// alignfree is kept through each <freejoint>'s `align`; a `<joint type="free">` has none.
#[test]
fn alignfree_with_a_free_joint_element_is_refused_with_the_joint() {
    assert_eq!(
        merge_error("corpora/errors/merge/part_alignfree_joint.xml", "p_", None),
        "corpora/errors/merge/part_alignfree_joint.xml:2:3: cannot merge: compiler alignfree=\"true\" differs from the base's \"false\" and has no exact conversion: the <joint type=\"free\"> at corpora/errors/merge/part_alignfree_joint.xml:5:7 has no `align` of its own to keep the part's setting (only <freejoint> has one)"
    );
}

/// Keys over a free body MuJoCo aligns need its compiled qpos0 (merge_judge:
/// free_objects_alignfree_into_arm in builds with MuJoCo).
#[cfg(not(mjcf_mujoco))]
#[test]
fn keys_over_aligned_free_bodies_need_mujoco() {
    assert_eq!(
        merge_error_into(
            "corpora/merge/arm_with_keys.xml",
            "corpora/merge/free_objects_alignfree.xml",
            "p_",
            None
        ),
        "corpora/merge/free_objects_alignfree.xml:11:7: MuJoCo aligns this free body with its inertial frame (alignfree, or the <freejoint>'s align), so its initial pose in the keyframes is known only to MuJoCo's compiler: remapping keyframes over it needs a build with the `mujoco` feature"
    );
}

/// A base with keyframes takes no part whose objects MuJoCo makes at compile time: the
/// keys could not be extended over their joints.
#[test]
fn keys_are_not_remapped_over_replicate() {
    assert_eq!(
        merge_error_into(
            "corpora/merge/arm_with_keys.xml",
            "corpora/errors/merge/part_replicate.xml",
            "p_",
            None
        ),
        "corpora/errors/merge/part_replicate.xml:3:5: cannot remap keyframes: <replicate> creates bodies and joints when MuJoCo compiles, whose places in the keyframes' vectors are not modelled"
    );
}

#[test]
fn settings_without_a_conversion_say_why() {
    assert_eq!(
        merge_error("corpora/errors/merge/part_discardvisual.xml", "p_", None),
        "corpora/errors/merge/part_discardvisual.xml:2:3: cannot merge: compiler discardvisual=\"true\" differs from the base's \"false\" and has no exact conversion: it decides whether visual geoms, and the assets only they use, are dropped, over the whole merged model"
    );
}

/// A part that fuses static bodies (a URDF robot, as MuJoCo's importer reads it) into a
/// base that does not: the base takes the setting and keeps each of its own bodies
/// (merge_judge's URDF case judges the result with MuJoCo).
#[test]
fn a_base_takes_a_fusing_parts_fusestatic_and_keeps_its_bodies() {
    let mut base = load("corpora/errors/merge/base.xml");
    let part = load("corpora/errors/merge/part_fusestatic.xml");
    base.merge(&part, None, &MergeOptions::default()).unwrap();
    let xml = base.to_xml_string();
    assert!(xml.contains(r#"<compiler fusestatic="true"/>"#), "{xml}");
    assert!(
        xml.contains(r#"<body name="hand" pos="0 0 1" fuse="false">"#),
        "{xml}"
    );
    assert!(
        xml.contains(r#"<body name="shelf" pos="0 0 0.5">"#),
        "{xml}"
    );
}

#[test]
fn a_free_body_only_goes_into_the_world() {
    assert_eq!(
        merge_error(
            "corpora/errors/merge/part_free_body.xml",
            "p_",
            Some("hand")
        ),
        "corpora/errors/merge/part_free_body.xml:3:5: <body> has a free joint: it can only be merged into the world body, not into 'hand'"
    );
}

#[test]
fn name_clashes_of_a_part_are_one_message_with_the_fix() {
    // The material is identical in both, so it is shared rather than a clash.
    assert_eq!(
        merge_error("corpora/errors/merge/base.xml", "", None),
        [
            "corpora/errors/merge/base.xml:6:5: duplicate names: all 2 names this part declares are already in the model (body 'hand' first at corpora/errors/merge/base.xml:6:5, joint 'wrist'); is it merged twice, or without a prefix of its own? give each instance its own name prefix",
        ]
        .join("\n")
    );
}

#[test]
fn identical_assets_are_shared_and_base_settings_win_with_warnings() {
    let mut base = load("corpora/errors/merge/base.xml");
    let part = load("corpora/errors/merge/part_shared_asset.xml");
    let report = base.merge(&part, None, &MergeOptions::default()).unwrap();
    assert_eq!(report.shared_assets, 1);
    assert_eq!(
        report.warnings,
        [
            "corpora/errors/merge/part_shared_asset.xml:2:3: the part's <option timestep=\"0.001\"> is ignored: the base's value (MuJoCo's default) wins",
            "corpora/errors/merge/part_shared_asset.xml:3:3: <size nuser_geom=\"2\"> of the part is used (the larger user-data width)",
        ]
    );
    let xml = base.to_xml_string();
    assert_eq!(xml.matches("<material name=\"red\"").count(), 1);
    assert!(xml.contains("<size nuser_geom=\"2\"/>"));
}

#[test]
fn keys_with_plastic_state_are_refused() {
    // MuJoCo 4.0.0 reads this part (one plastic value for the yielding joint); its layout in
    // the merged model is not modelled, so the merge refuses instead of copying it.
    assert_eq!(
        merge_error(
            "corpora/errors/merge/part_key_plastic.xml",
            "p_",
            Some("hand")
        ),
        "corpora/errors/merge/part_key_plastic.xml:9:5: key plastic (MuJoCo 4.0's plastic state) cannot be remapped onto the merged model; remove it before merging"
    );
}

/// Without MuJoCo, a part with another inertiagrouprange merges only when none of its bodies
/// infers its inertia from geoms; builds with MuJoCo write those inertias out instead
/// (merge_judge: objects_inertiagroups_4_5_into_arm).
#[test]
fn inertiagrouprange_converts_when_no_body_infers_inertia() {
    let mut base = load("corpora/errors/merge/base.xml");
    let part = Document::from_str(
        r#"<mujoco><compiler inertiagrouprange="4 5"/><worldbody>
  <body name="w" pos="0 0 1"><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
    <geom size="0.1" group="1"/></body>
  <body name="empty"/>
</worldbody></mujoco>"#,
        root(),
    )
    .unwrap();
    base.merge(&part, None, &MergeOptions::default()).unwrap();
}

#[cfg(not(mjcf_mujoco))]
#[test]
fn inertiagrouprange_with_inferred_inertia_is_refused_without_mujoco() {
    assert_eq!(
        merge_error("corpora/merge/objects_inertiagroups_4_5.xml", "p_", None),
        "corpora/merge/objects_inertiagroups_4_5.xml:7:3: cannot merge: compiler inertiagrouprange=\"4 5\" differs from the base's \"0 5\" and has no exact conversion: writing the part's inertias out needs a build with the `mujoco` feature"
    );
}

/// A base that rescales or bounds masses itself would change the part's written inertias
/// too: refused in every build, naming the setting.
#[test]
fn mass_settings_of_the_base_are_never_converted() {
    let mut base = Document::from_str(
        r#"<mujoco><compiler settotalmass="5"/><worldbody><body name="hand" pos="0 0 1">
  <joint name="wrist"/><geom size="0.05"/></body></worldbody></mujoco>"#,
        root(),
    )
    .unwrap();
    let part = load("corpora/errors/merge/part_settotalmass.xml");
    let err = base
        .merge(&part, None, &MergeOptions::default())
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        "corpora/errors/merge/part_settotalmass.xml:2:3: cannot merge: compiler settotalmass=\"2\" differs from the base's \"5\" and has no exact conversion: the base's own setting would also change the part's masses and inertias"
    );
}

#[test]
fn merge_maps_tell_where_each_part_node_went() {
    use mjcf_forge::MergePart;
    let mut base = Document::from_str(
        r#"<mujoco><asset><texture name="t" type="2d" builtin="checker" width="8" height="8"/></asset>
           <worldbody><body name="b"><joint name="bj"/><geom size="1"/></body></worldbody>
           <keyframe><key name="home" qpos="0.5"/></keyframe></mujoco>"#,
        ".",
    )
    .unwrap();
    let part = Document::from_str(
        r#"<mujoco><compiler angle="radian"/>
           <asset><texture name="t" type="2d" builtin="checker" width="8" height="8"/></asset>
           <worldbody><body name="p"><joint name="pj"/><geom size="1"/></body></worldbody>
           <keyframe><key name="p_home" qpos="0.25"/></keyframe></mujoco>"#,
        ".",
    )
    .unwrap();
    let of = |doc: &Document, tag: &str| {
        doc.descendants(doc.root())
            .filter(|&n| doc.tag(n) == tag)
            .collect::<Vec<_>>()
    };
    let (base_body, base_texture) = (base.find_body("b").unwrap(), of(&base, "texture")[0]);
    let (part_body, part_joint) = (part.find_body("p").unwrap(), of(&part, "joint")[0]);
    let parts = [MergePart {
        doc: &part,
        into: None,
        prefix: "p_",
    }];
    let (_, maps) = base.merge_all_mapped(&parts, true).unwrap();
    let map = &maps[0];
    // Copied nodes map to their copies; the shared asset to the base's own.
    assert_eq!(map.get(part_body), base.find_body("p"));
    assert_eq!(base.attr(map.get(part_joint).unwrap(), "name"), Some("pj"));
    assert_eq!(map.get(of(&part, "texture")[0]), Some(base_texture));
    // What a merge folds in is not copied: the part's compiler and keys.
    assert_eq!(map.get(of(&part, "compiler")[0]), None);
    assert_eq!(map.get(of(&part, "key")[0]), None);
    // The base's handles are still its elements (the merge worked on a copy).
    assert_eq!(base.attr(base_body, "name"), Some("b"));
    assert_eq!(base.find_body("b"), Some(base_body));
}
