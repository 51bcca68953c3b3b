//! `mjcf-forge export`: a model as a folder (or tar stream) that still compiles to the
//! same model in MuJoCo after it is moved elsewhere and the original is deleted.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{Pair, forge, judge, listing, path_arg, python, root, scratch, stderr};

/// Real models with meshes (STL, OBJ, MSH), textures (cube faces too), height fields,
/// skins, assets named after their files, one file used as a texture and a height field,
/// and compiler folder settings (`assetdir`, `texturedir`, `meshdir`).
const MODELS: [&str; 9] = [
    ".cache/corpus/robosuite-1.5.2/robosuite/models/assets/robots/panda/robot.xml",
    ".cache/corpus/robosuite-1.5.2/robosuite/models/assets/arenas/table_arena.xml",
    ".cache/corpus/robosuite-1.5.2/robosuite/models/assets/arenas/bins_arena.xml",
    ".cache/corpus/dm_control-1.0.50/dm_control/mjcf/test_assets/model_with_assetdir.xml",
    ".cache/corpus/dm_control-1.0.50/dm_control/mjcf/test_assets/model_with_assets.xml",
    ".cache/corpus/dm_control-1.0.50/dm_control/mjcf/test_assets/model_with_nameless_assets.xml",
    ".cache/corpus/dm_control-1.0.50/dm_control/mjcf/test_assets/model_with_separators.xml",
    ".cache/corpus/dm_control-1.0.50/dm_control/suite/dog.xml",
    ".cache/corpus/dm_control-1.0.50/dm_control/locomotion/walkers/assets/fruitfly_v2/fruitfly.xml",
];

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// The values of every `file*="..."` attribute of `xml`.
fn file_values(xml: &str) -> Vec<String> {
    let mut values = Vec::new();
    for (at, _) in xml.match_indices(" file") {
        let rest = &xml[at + 1..];
        let Some(eq) = rest.find("=\"") else { continue };
        if !rest[..eq].chars().all(|c| c.is_ascii_alphabetic()) {
            continue;
        }
        let value = &rest[eq + 2..];
        values.push(value[..value.find('"').unwrap()].to_owned());
    }
    values
}

#[test]
fn exported_folders_compile_to_the_same_model_after_being_moved() {
    let dir = scratch("cli_export_moved");
    let mut pairs = Vec::new();
    for (i, model) in MODELS.iter().enumerate() {
        let exported = dir.join(format!("exported{i}"));
        let out = forge(&["export", model, "-o", path_arg(&exported)]);
        assert!(out.status.success(), "{model}: {}", stderr(&out));
        assert!(out.stdout.is_empty() && out.stderr.is_empty());
        let name = Path::new(model).file_name().unwrap();
        // Moved: copied elsewhere and the original deleted, so nothing can still point
        // into the export folder.
        let moved = dir.join(format!("moved{i}"));
        copy_tree(&exported, &moved);
        std::fs::remove_dir_all(&exported).unwrap();
        let xml = std::fs::read_to_string(moved.join(name)).unwrap();
        let files = file_values(&xml);
        assert!(!files.is_empty(), "{model}: no file reference exported");
        for f in &files {
            assert!(
                f.starts_with("assets/"),
                "{model}: file '{f}' not relocated"
            );
            assert!(moved.join(f).is_file(), "{model}: '{f}' missing");
        }
        // Each asset once; nothing but the model and its assets.
        let mut distinct = files.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(
            listing(&moved.join("assets")).len(),
            distinct.len(),
            "{model}"
        );
        assert_eq!(listing(&moved), ["assets", name.to_str().unwrap()]);
        assert!(
            !xml.contains("meshdir") && !xml.contains("texturedir") && !xml.contains("assetdir")
        );
        pairs.push(Pair {
            a: root().join(model),
            b: moved.join(name),
            prefix: String::new(),
        });
    }
    let failed = judge(&pairs, &dir);
    assert!(
        failed.is_empty(),
        "judge found differences:\n{}",
        failed.join("\n")
    );
}

/// The tar stream: Python's `tarfile` reads it (assets first, the model last,
/// deterministic headers), the same model gives the same bytes, and the extracted
/// folder compiles to the same model.
#[test]
fn a_tar_export_is_read_by_python_and_compiles_once_extracted() {
    let dir = scratch("cli_export_tar");
    let model = MODELS[0];
    let tar = dir.join("robot.tar");
    let out = forge(&["export", model, "--tar", "-o", path_arg(&tar)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let to_stdout = forge(&["export", model, "--tar", "-o", "-"]);
    assert!(to_stdout.status.success());
    assert_eq!(
        std::fs::read(&tar).unwrap(),
        to_stdout.stdout,
        "not deterministic"
    );

    let extracted = dir.join("extracted");
    let check = r#"
import sys, tarfile
with tarfile.open(sys.argv[1]) as t:
    members = t.getmembers()
    names = [m.name for m in members]
    assert names[-1] == "robot.xml", names
    assert all(n.startswith("assets/") for n in names[:-1]), names
    assert len(set(names)) == len(names), names
    for m in members:
        assert m.isfile() and m.mtime == 0 and m.mode == 0o644 and m.uid == 0 and m.gid == 0, m
    t.extractall(sys.argv[2], filter="data")
print(len(names))
"#;
    let py = Command::new(python())
        .args(["-c", check, path_arg(&tar), path_arg(&extracted)])
        .output()
        .unwrap();
    assert!(
        py.status.success(),
        "{}",
        String::from_utf8_lossy(&py.stderr)
    );
    let members: usize = String::from_utf8_lossy(&py.stdout).trim().parse().unwrap();
    assert!(members > 10, "{members} members");
    std::fs::remove_file(&tar).unwrap();
    let failed = judge(
        &[Pair {
            a: root().join(model),
            b: extracted.join("robot.xml"),
            prefix: String::new(),
        }],
        &dir,
    );
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
fn export_errors_are_exact_and_leave_nothing() {
    let dir = scratch("cli_export_errors");
    let out_dir = dir.join("out");

    let out = forge(&["export", "no/such/model.xml", "-o", path_arg(&out_dir)]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr(&out),
        "cannot read 'no/such/model.xml': No such file or directory (os error 2)\n"
    );

    // A mesh file that is missing: reported at its element, nothing written.
    let model = dir.join("model.xml");
    std::fs::write(
        &model,
        "<mujoco>\n  <asset>\n    <mesh file=\"gone.stl\"/>\n  </asset>\n</mujoco>\n",
    )
    .unwrap();
    let out = forge(&["export", path_arg(&model), "-o", path_arg(&out_dir)]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr(&out),
        format!(
            "{}:3:5: cannot read '{}': No such file or directory (os error 2)\n",
            model.display(),
            dir.join("gone.stl").display()
        )
    );

    // An output folder that cannot be made.
    let blocker = dir.join("file");
    std::fs::write(&blocker, "x").unwrap();
    let inside = blocker.join("out");
    let out = forge(&["export", MODELS[0], "-o", path_arg(&inside)]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr(&out),
        format!(
            "{}: cannot create folder: Not a directory (os error 20)\n",
            inside.display()
        )
    );
    assert_eq!(listing(&dir), ["file", "model.xml"]);

    // A folder that holds something (here an assets/ that is a file) is refused before
    // anything is loaded, and what was there stays as it was; with --replace it is
    // replaced whole (the new folder is written beside it, so its old files are in no
    // one's way).
    std::fs::create_dir(&out_dir).unwrap();
    std::fs::write(out_dir.join("assets"), "not a folder").unwrap();
    std::fs::write(out_dir.join("robot.xml"), "old").unwrap();
    let out = forge(&["export", MODELS[0], "-o", path_arg(&out_dir)]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with(&format!(
            "{}: the output folder is not empty (it holds '",
            out_dir.display()
        )) && err.ends_with("'); add --replace to replace it whole, or choose another folder\n"),
        "{err}"
    );
    assert_eq!(listing(&out_dir), ["assets", "robot.xml"]);
    assert_eq!(
        std::fs::read_to_string(out_dir.join("robot.xml")).unwrap(),
        "old"
    );
}

/// A model exported twice into one folder (the second time replacing it): the same
/// files, byte for byte.
#[test]
fn exporting_again_into_the_same_folder_gives_the_same_files() {
    let dir = scratch("cli_export_again");
    let out_dir = dir.join("out");
    let model = MODELS[1];
    let snapshot = |d: &Path| -> Vec<(String, Vec<u8>)> {
        let mut files: Vec<(String, Vec<u8>)> = Vec::new();
        for sub in [PathBuf::new(), PathBuf::from("assets")] {
            for name in listing(&d.join(&sub)) {
                let p = d.join(&sub).join(&name);
                if p.is_file() {
                    files.push((
                        sub.join(name).display().to_string(),
                        std::fs::read(p).unwrap(),
                    ));
                }
            }
        }
        files
    };
    assert!(
        forge(&["export", model, "-o", path_arg(&out_dir)])
            .status
            .success()
    );
    let first = snapshot(&out_dir);
    assert!(
        forge(&["export", model, "-o", path_arg(&out_dir), "--replace"])
            .status
            .success()
    );
    assert_eq!(snapshot(&out_dir), first);
}
