//! Where `-o PATH` goes, as a user runs the command line: symlinks are written through,
//! FIFOs and devices are written to (never replaced by a regular file), `/dev/stdout` is
//! the process's own standard output.
//!
//! Pass: once, in the build without features (scripts/test.sh): nothing here depends on the
//! MuJoCo a build links (the judges run both Python MuJoCos, 3.17.0 and 4.0.0, themselves).

mod common;

use std::io::Read as _;
use std::process::{Command, Stdio};

use common::{forge, listing, path_arg, root, scratch, stderr};
use mjcf_forge::Document;

const MODEL: &str = "corpora/features/default_childclass.xml";

fn expected() -> String {
    Document::load(root().join(MODEL))
        .unwrap()
        .to_pretty_string()
}

#[test]
fn a_symlink_output_is_written_through_and_stays_a_link() {
    let dir = scratch("cli_outputs_symlink");
    let target = dir.join("real.xml");
    std::fs::write(&target, "old\n").unwrap();
    let link = dir.join("link.xml");
    std::os::unix::fs::symlink("real.xml", &link).unwrap();
    for command in ["inline", "prefix"] {
        let mut args = vec![command, MODEL, "-o", path_arg(&link)];
        if command == "prefix" {
            args.extend(["--prefix", "p_"]);
        }
        let out = forge(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        let written = std::fs::read_to_string(&target).unwrap();
        assert!(written.starts_with("<mujoco"), "{written}");
    }
    let out = forge(&["inline", MODEL, "-o", path_arg(&link)]);
    assert!(out.status.success());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), expected());
    assert_eq!(listing(&dir), ["link.xml", "real.xml"]);
}

#[test]
fn dev_null_stays_a_device() {
    let out = forge(&["inline", MODEL, "-o", "/dev/null"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(out.stdout.is_empty());
    let m = std::fs::metadata("/dev/null").unwrap();
    assert!(!m.is_file(), "/dev/null was replaced by a regular file");
}

/// `-o /dev/stdout` with standard output redirected to a file opened for appending (as
/// `>>` does): what was there stays and the model follows it. Opening /dev/stdout anew
/// would write at offset 0, and replacing the file it resolves to would lose "before".
#[test]
fn dev_stdout_is_the_process_standard_output() {
    let dir = scratch("cli_outputs_stdout");
    let log = dir.join("log.txt");
    std::fs::write(&log, "before\n").unwrap();
    let file = std::fs::OpenOptions::new().append(true).open(&log).unwrap();
    let status = Command::new(env!("CARGO_BIN_EXE_mjcf-forge"))
        .args(["inline", MODEL, "-o", "/dev/stdout"])
        .current_dir(root())
        .stdout(file)
        .status()
        .unwrap();
    assert!(status.success());
    assert_eq!(
        std::fs::read_to_string(&log).unwrap(),
        format!("before\n{}", expected())
    );
    // Through a pipe too.
    let out = forge(&["inline", MODEL, "-o", "/dev/stdout"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(String::from_utf8(out.stdout).unwrap(), expected());
}

#[test]
fn a_fifo_output_is_streamed_to_its_reader() {
    let dir = scratch("cli_outputs_fifo");
    let fifo = dir.join("pipe");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut text = String::new();
            std::fs::File::open(&fifo)
                .unwrap()
                .read_to_string(&mut text)
                .unwrap();
            text
        })
    };
    let out = Command::new(env!("CARGO_BIN_EXE_mjcf-forge"))
        .args(["inline", MODEL, "-o", path_arg(&fifo)])
        .current_dir(root())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(reader.join().unwrap(), expected());
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::metadata(&fifo).unwrap().file_type().is_fifo(),
        "the FIFO was replaced"
    );
    assert_eq!(listing(&dir), ["pipe"]);
}

#[test]
fn an_output_folder_that_cannot_be_made_is_one_clear_error() {
    let dir = scratch("cli_outputs_bad_dir");
    let file = dir.join("file");
    std::fs::write(&file, "x").unwrap();
    let out_dir = file.join("out");
    let out = forge(&["inline", MODEL, "--out-dir", path_arg(&out_dir)]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr(&out),
        format!(
            "{}: cannot create folder: Not a directory (os error 20)\n",
            out_dir.display()
        )
    );
    assert_eq!(listing(&dir), ["file"]);
}
