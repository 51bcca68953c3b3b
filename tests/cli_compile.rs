//! `mjcf-forge compile` and `inline --validate` (cargo feature `mujoco`): sizes agree with
//! Python MuJoCo on the whole wheel corpus; compile errors carry MuJoCo's message and the
//! position of our element.
//!
//! Pass: once per MuJoCo the feature `mujoco` links (scripts/test.sh: 3.17.0 and 4.0.0),
//! since what it checks depends on that MuJoCo (a build without the feature has none of it).
#![cfg(mjcf_mujoco)]

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

use common::{
    forge, include_cases, path_arg, python_linked, root, scratch, stderr, stdout, wheel_models,
};
use mjcf_forge::Document;

/// A JSON value of the flat objects both sides print.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Value {
    Int(i64),
    Str(String),
}

/// Parses one flat JSON object of string and integer values (all that `compile --json`
/// and tests/judge/sizes.py print), so the test needs no JSON crate.
fn parse_flat_json(line: &str) -> Result<BTreeMap<String, Value>, String> {
    let mut chars = line.trim().chars().peekable();
    let mut map = BTreeMap::new();
    let skip_ws = |chars: &mut std::iter::Peekable<std::str::Chars>| {
        while chars.peek().is_some_and(|c| c.is_whitespace()) {
            chars.next();
        }
    };
    let string = |chars: &mut std::iter::Peekable<std::str::Chars>| -> Result<String, String> {
        if chars.next() != Some('"') {
            return Err("expected '\"'".into());
        }
        let mut s = String::new();
        loop {
            match chars.next().ok_or("unterminated string")? {
                '"' => return Ok(s),
                '\\' => match chars.next().ok_or("bad escape")? {
                    'n' => s.push('\n'),
                    't' => s.push('\t'),
                    'r' => s.push('\r'),
                    'u' => {
                        let hex: String = chars.by_ref().take(4).collect();
                        let code = u32::from_str_radix(&hex, 16).map_err(|e| e.to_string())?;
                        s.push(char::from_u32(code).unwrap_or('\u{fffd}'));
                    }
                    c => s.push(c),
                },
                c => s.push(c),
            }
        }
    };
    if chars.next() != Some('{') {
        return Err(format!("not an object: {line}"));
    }
    loop {
        skip_ws(&mut chars);
        if chars.peek() == Some(&'}') {
            chars.next();
            break;
        }
        let key = string(&mut chars)?;
        skip_ws(&mut chars);
        if chars.next() != Some(':') {
            return Err(format!("expected ':' after {key:?}"));
        }
        skip_ws(&mut chars);
        let value = if chars.peek() == Some(&'"') {
            Value::Str(string(&mut chars)?)
        } else {
            let mut digits = String::new();
            while let Some(&c) = chars.peek().filter(|c| c.is_ascii_digit() || **c == '-') {
                digits.push(c);
                chars.next();
            }
            Value::Int(
                digits
                    .parse()
                    .map_err(|_| format!("bad number for {key:?} in {line}"))?,
            )
        };
        map.insert(key, value);
        skip_ws(&mut chars);
        match chars.next() {
            Some(',') => {}
            Some('}') => break,
            other => return Err(format!("expected ',' or '}}', found {other:?} in {line}")),
        }
    }
    skip_ws(&mut chars);
    if chars.next().is_some() {
        return Err(format!("text after the object: {line}"));
    }
    Ok(map)
}

/// The keys `compile --json` must print (the issue's list).
const REQUIRED_KEYS: [&str; 9] = [
    "nbody", "njnt", "ngeom", "nsite", "nu", "nsensor", "nq", "nv", "nmesh",
];

/// Python MuJoCo's sizes of each path, from one run of tests/judge/sizes.py.
fn python_sizes(paths: &[PathBuf], dir: &Path) -> Vec<BTreeMap<String, Value>> {
    let list = dir.join("models.txt");
    let body: String = paths.iter().map(|p| format!("{}\n", p.display())).collect();
    std::fs::write(&list, body).unwrap();
    let out = Command::new(python_linked())
        .arg(root().join("tests/judge/sizes.py"))
        .arg("--list")
        .arg(&list)
        .current_dir(dir)
        .output()
        .expect("run tests/judge/sizes.py");
    assert!(
        out.status.success(),
        "tests/judge/sizes.py failed: {}",
        stderr(&out)
    );
    let text = stdout(&out);
    let rows: Vec<BTreeMap<String, Value>> = text
        .lines()
        .map(|l| {
            parse_flat_json(l).unwrap_or_else(|e| panic!("tests/judge/sizes.py printed {l:?}: {e}"))
        })
        .collect();
    assert_eq!(rows.len(), paths.len(), "one JSON line per model");
    for (row, path) in rows.iter().zip(paths) {
        assert_eq!(
            row.get("path"),
            Some(&Value::Str(path.display().to_string())),
            "lines in input order"
        );
    }
    rows
}

/// Runs `f` on every item on all cores; results in item order.
fn parallel_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let threads = std::thread::available_parallelism()
        .map_or(4, |n| n.get())
        .min(16);
    let mut results: Vec<(usize, R)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(item) = items.get(i) else { break done };
                        done.push((i, f(item)));
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    });
    results.sort_by_key(|(i, _)| *i);
    results.into_iter().map(|(_, r)| r).collect()
}

#[test]
fn sizes_json_parser_reads_both_sides() {
    let row = parse_flat_json(r#"{"path": "a \"b\"\nc", "nbody": 2,"nq":-1}"#).unwrap();
    assert_eq!(row["path"], Value::Str("a \"b\"\nc".into()));
    assert_eq!(row["nbody"], Value::Int(2));
    assert_eq!(row["nq"], Value::Int(-1));
    assert!(parse_flat_json(r#"{"a": 1} x"#).is_err());
    assert!(parse_flat_json(r#"{"a" 1}"#).is_err());
}

#[test]
fn compile_json_agrees_with_python_mujoco_on_every_wheel_model() {
    compile_json_agrees_with_python_mujoco(&wheel_models(), "cli_compile_sizes");
}

#[test]
fn compile_json_agrees_with_python_mujoco_on_the_include_cases() {
    compile_json_agrees_with_python_mujoco(&include_cases(), "cli_compile_include_sizes");
}

/// `compile --json` of each model prints the sizes Python MuJoCo compiles it to.
fn compile_json_agrees_with_python_mujoco(models: &[PathBuf], scratch_name: &str) {
    let dir = scratch(scratch_name);
    let expected = python_sizes(models, &dir);
    let got = parallel_map(models, |model| {
        forge(&["compile", "--json", path_arg(model)])
    });

    let mut wrong = Vec::new();
    let mut compared_keys = usize::MAX;
    for ((model, out), python) in models.iter().zip(&got).zip(&expected) {
        let name = model.strip_prefix(root()).unwrap_or(model).display();
        if let Some(Value::Str(e)) = python.get("error") {
            wrong.push(format!("{name}: Python MuJoCo failed: {e}"));
            continue;
        }
        if !out.status.success() {
            wrong.push(format!("{name}: exit {}: {}", out.status, stderr(out)));
            continue;
        }
        let text = stdout(out);
        let lines: Vec<&str> = text.lines().collect();
        if lines.len() != 1 {
            wrong.push(format!("{name}: expected one JSON line, got {text:?}"));
            continue;
        }
        let ours = match parse_flat_json(lines[0]) {
            Ok(map) => map,
            Err(e) => {
                wrong.push(format!("{name}: {e}"));
                continue;
            }
        };
        if let Some(missing) = REQUIRED_KEYS.iter().find(|k| !ours.contains_key(**k)) {
            wrong.push(format!("{name}: no {missing:?} in {}", lines[0]));
        }
        let mut compared = 0;
        for (key, value) in &ours {
            if let Some(theirs) = python.get(key) {
                compared += 1;
                if theirs != value {
                    wrong.push(format!(
                        "{name}: {key} is {value:?}, Python MuJoCo says {theirs:?}"
                    ));
                }
            }
        }
        compared_keys = compared_keys.min(compared);
    }
    assert!(
        wrong.is_empty(),
        "{} problems:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
    assert!(
        compared_keys >= REQUIRED_KEYS.len(),
        "only {compared_keys} keys compared"
    );
}

/// A model whose geom names a mesh that does not exist, with the geom deep in an included
/// file, on a line and column that differ from the geom's line in the XML MuJoCo sees.
fn unknown_mesh_model(dir: &Path) -> (PathBuf, PathBuf) {
    let main = dir.join("robot.xml");
    let part = dir.join("parts/arm.xml");
    std::fs::create_dir_all(part.parent().unwrap()).unwrap();
    std::fs::write(
        &main,
        "<mujoco model=\"robot\">\n\
         \n\
         <!-- comments and blank lines shift the source lines -->\n\
         \n\
         <default><geom rgba=\"1 0 0 1\"/></default>\n\
         <worldbody>\n\
         <light pos=\"0 0 3\"/>\n\
         <include file=\"parts/arm.xml\"/>\n\
         </worldbody>\n\
         </mujoco>\n",
    )
    .unwrap();
    std::fs::write(
        &part,
        "<mujoco>\n\
         <body name=\"arm\">\n\
         \x20   <joint name=\"shoulder\"/>\n\
         \x20   <geom name=\"upper\" size=\"0.1\"/>\n\
         \n\
         \x20       <geom name=\"hand\" type=\"mesh\" mesh=\"no_such_mesh\"/>\n\
         </body>\n\
         </mujoco>\n",
    )
    .unwrap();
    (main, part)
}

#[test]
fn compile_error_names_mujocos_message_and_our_element() {
    let dir = scratch("cli_compile_error");
    let (main, part) = unknown_mesh_model(&dir);

    // Python MuJoCo's message for the same model: ours must carry it (its first line; the
    // rest names a line of the XML each side compiled).
    let python = python_sizes(std::slice::from_ref(&main), &dir);
    let Some(Value::Str(message)) = python[0].get("error") else {
        panic!("Python MuJoCo compiled the broken model: {:?}", python[0]);
    };
    let first_line = message.lines().next().unwrap();
    assert!(first_line.contains("no_such_mesh"), "{message}");

    let out = forge(&["compile", path_arg(&main)]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(stdout(&out), "");
    assert!(!err.contains("panicked"), "{err}");
    let expected_start = format!("{}:6:9: {first_line}\n", part.display());
    assert!(
        err.starts_with(&expected_start),
        "expected {expected_start:?}, got:\n{err}"
    );
    assert!(err.contains("Element name 'hand'"), "{err}");
    assert!(
        err.trim_end()
            .ends_with(&format!("(included from {}:8:1)", main.display())),
        "{err}"
    );

    // --json changes nothing on failure.
    let out = forge(&["compile", "--json", path_arg(&main)]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stdout(&out), "");
    assert!(
        stderr(&out).starts_with(&expected_start),
        "{}",
        stderr(&out)
    );
}

#[test]
fn compile_error_in_the_main_file_points_at_its_line_and_column() {
    let dir = scratch("cli_compile_error_main");
    let model = dir.join("model.xml");
    std::fs::write(
        &model,
        "<mujoco>\n\
         <worldbody>\n\
         \x20 <body name=\"b\"><joint name=\"j\"/><geom size=\"1\"/></body>\n\
         </worldbody>\n\
         \n\
         <actuator>\n\
         \x20     <motor name=\"m\" joint=\"j\"/>    <motor name=\"bad\" joint=\"nope\"/>\n\
         </actuator>\n\
         </mujoco>\n",
    )
    .unwrap();
    let out = forge(&["compile", path_arg(&model)]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let expected = format!(
        "{}:7:38: Error: unknown transmission target 'nope'",
        model.display()
    );
    assert!(
        err.starts_with(&expected),
        "expected {expected:?}, got:\n{err}"
    );
}

#[test]
fn compile_reports_load_errors_like_inline() {
    let case = "corpora/errors/unknown_class.xml";
    let out = forge(&["compile", "--json", case]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stdout(&out), "");
    let expected = std::fs::read_to_string(root().join(case).with_extension("err")).unwrap();
    assert_eq!(stderr(&out).trim_end(), expected.trim_end());
}

#[test]
fn compile_without_json_prints_every_size_by_name() {
    let model = root().join("corpora/features/default_childclass.xml");
    let out = forge(&["compile", path_arg(&model)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    for key in REQUIRED_KEYS {
        assert!(
            text.lines()
                .any(|l| l.split_whitespace().next() == Some(key)
                    && l.split_whitespace()
                        .nth(1)
                        .is_some_and(|v| v.parse::<u64>().is_ok())),
            "no `{key} N` line in:\n{text}"
        );
    }
}

#[test]
fn inline_validate_writes_a_good_model() {
    let dir = scratch("cli_compile_validate_good");
    let model = root().join("corpora/features/include_nested.xml");
    let out_path = dir.join("out.xml");
    let out = forge(&[
        "inline",
        "--validate",
        path_arg(&model),
        "-o",
        path_arg(&out_path),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let expected = Document::load(&model).unwrap().to_pretty_string();
    assert_eq!(std::fs::read_to_string(&out_path).unwrap(), expected);

    let out = forge(&["inline", "--validate", path_arg(&model)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), expected);
}

#[test]
fn inline_validate_refuses_a_bad_model_and_writes_nothing() {
    let dir = scratch("cli_compile_validate_bad");
    let (main, part) = unknown_mesh_model(&dir.join("src"));
    let out_path = dir.join("robot.xml");
    let expected_start = format!("{}:6:9: ", part.display());

    // A fresh output is not created.
    let out = forge(&[
        "inline",
        "--validate",
        path_arg(&main),
        "-o",
        path_arg(&out_path),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(&expected_start) && err.contains("no_such_mesh"),
        "{err}"
    );
    assert!(!out_path.exists());

    // An existing output keeps its content; nothing else appears in its folder.
    std::fs::write(&out_path, "previous\n").unwrap();
    let out = forge(&[
        "inline",
        "--validate",
        path_arg(&main),
        "-o",
        path_arg(&out_path),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(std::fs::read_to_string(&out_path).unwrap(), "previous\n");

    // No document on stdout either.
    let out = forge(&["inline", "--validate", path_arg(&main)]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stdout(&out), "");

    // With --out-dir the good model is written, the bad one is not.
    let out_dir = dir.join("out");
    let good = root().join("corpora/features/default_childclass.xml");
    let out = forge(&[
        "inline",
        "--validate",
        "--out-dir",
        path_arg(&out_dir),
        path_arg(&main),
        path_arg(&good),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).starts_with(&expected_start),
        "{}",
        stderr(&out)
    );
    let names: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["default_childclass.xml"]);

    let mut in_dir: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    in_dir.sort();
    assert_eq!(
        in_dir,
        ["out", "robot.xml", "src"],
        "temporary files left behind"
    );
}

#[test]
fn prefix_and_merge_validate_their_output_with_mujoco() {
    let dir = scratch("cli_validate_model_tier");
    let out = dir.join("scene.xml");
    let merged = forge(&[
        "merge",
        "corpora/merge/arm_with_keys.xml",
        "--part",
        "corpora/merge/gripper_radian.xml:g_:hand",
        "--validate",
        "-o",
        path_arg(&out),
    ]);
    assert!(merged.status.success(), "{}", stderr(&merged));
    assert!(out.exists());
    let prefixed = forge(&[
        "prefix",
        "corpora/merge/arm_with_keys.xml",
        "--prefix",
        "p_",
        "--validate",
    ]);
    assert!(prefixed.status.success(), "{}", stderr(&prefixed));
    assert!(stdout(&prefixed).contains("name=\"p_hand\""));
    // A merge whose result MuJoCo refuses (a flex without its bodies) writes nothing.
    let bad = dir.join("bad.xml");
    std::fs::write(
        &bad,
        r#"<mujoco><deformable><flex name="f" dim="1" body="nowhere nowhere2" vertex="0 0 0 1 0 0" element="0 1"/></deformable></mujoco>"#,
    )
    .unwrap();
    let refused = dir.join("refused.xml");
    let o = forge(&[
        "merge",
        "corpora/merge/arm_with_keys.xml",
        "--part",
        &format!("{}:b_", path_arg(&bad)),
        "--validate",
        "-o",
        path_arg(&refused),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        !refused.exists(),
        "nothing is written for a model MuJoCo refuses"
    );
}
