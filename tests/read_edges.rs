//! Reading edge cases: an include cycle met from a string names the files of the cycle only.

use mjcf_forge::Document;

#[test]
fn include_cycle_from_a_string_names_only_files() {
    let dir = std::env::temp_dir().join(format!("mjcf-forge-cycle-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("a.xml"),
        r#"<mujoco><include file="a.xml"/></mujoco>"#,
    )
    .unwrap();
    let err = Document::from_str(r#"<mujoco><include file="a.xml"/></mujoco>"#, &dir)
        .unwrap_err()
        .to_string();
    let a = dir.join("a.xml");
    let expected = format!(
        "{}:1:9: include cycle: {} -> {} (included from <string>:1:9)",
        a.display(),
        a.display(),
        a.display()
    );
    assert_eq!(err, expected);
    std::fs::remove_dir_all(&dir).unwrap();
}
