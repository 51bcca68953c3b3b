//! What writing outputs costs against the filesystem's own cost per file, same run.
//!
//! `out_dir_cost --runs N --bin PATH MODEL...` times, best of N, interleaved so all see
//! the same machine:
//! - `command`: the real command line, `mjcf-forge inline MODEL... --out-dir D` (a
//!   process of its own: start, load and inline every model, write, one sync);
//! - `inline`: the command's work in this process (load, inline, write through
//!   [`OutputDir`] in parallel, `finish`);
//! - `output_dir`: only the writing: the same bytes through [`OutputDir`], with its one
//!   sync (`finish`) and (`unsynced`) without it;
//! - `fs_write`: the bare cost of creating that many small files: a loop of plain
//!   `std::fs::write` of the same bytes into an empty folder.
//!
//! Prints one JSON line: microseconds per file of each, and their ratios to `fs_write`. Run by `benches/compare/bench_out_dir.sh`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use mjcf_forge::{Document, OutputDir};
use rayon::prelude::*;

fn main() {
    let mut runs = 30usize;
    let mut bin = PathBuf::from("target/release/mjcf-forge");
    let mut scratch = PathBuf::from("target/out-dir-cost");
    let mut copies = 1usize;
    let mut models = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--runs" => runs = args.next().and_then(|v| v.parse().ok()).expect("--runs N"),
            "--bin" => bin = args.next().expect("--bin PATH").into(),
            "--scratch" => scratch = args.next().expect("--scratch DIR").into(),
            "--copies" => {
                copies = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .expect("--copies K")
            }
            _ => models.push(PathBuf::from(a)),
        }
    }
    assert!(
        !models.is_empty(),
        "usage: out_dir_cost [--runs N] [--bin PATH] MODEL..."
    );
    // `--out-dir` names each output after its input and refuses two inputs with one name
    // (a dozen robosuite robots are all `robot.xml`): the command runs on the first model
    // of each file name; the in-process paths write all of them, named after their folder.
    let mut seen = std::collections::HashSet::new();
    let command_models: Vec<&PathBuf> = models
        .iter()
        .filter(|m| seen.insert(m.file_name().unwrap().to_owned()))
        .collect();
    let unique_name = |m: &Path| -> String {
        let folder = m.parent().and_then(Path::file_name).unwrap_or_default();
        format!(
            "{}_{}",
            folder.to_str().unwrap(),
            m.file_name().unwrap().to_str().unwrap()
        )
    };
    // The bytes the command writes, made the way it makes them.
    let outputs: Vec<(String, Vec<u8>)> = models
        .iter()
        .map(|m| {
            let doc = Document::load(m).unwrap_or_else(|e| panic!("{e}"));
            (unique_name(m), doc.to_pretty_string().into_bytes())
        })
        .collect();
    // The writing alone, on `copies` times the outputs: the one sync at the end is paid
    // once whatever the count, as in a batch of many variants.
    let bulk: Vec<(String, Vec<u8>)> = (0..copies)
        .flat_map(|k| {
            outputs
                .iter()
                .map(move |(n, b)| (format!("{k}_{n}"), b.clone()))
        })
        .collect();
    let command_outputs: Vec<(String, Vec<u8>)> = command_models
        .iter()
        .map(|m| {
            let bytes = &outputs[models.iter().position(|x| x == *m).unwrap()].1;
            (
                m.file_name().unwrap().to_str().unwrap().to_owned(),
                bytes.clone(),
            )
        })
        .collect();

    let fresh = |name: &str| -> PathBuf {
        let dir = scratch.join(name);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    };
    let fs_write = |dir: &Path, outputs: &[(String, Vec<u8>)]| -> f64 {
        let start = Instant::now();
        for (name, b) in outputs {
            std::fs::write(dir.join(name), b).unwrap();
        }
        start.elapsed().as_secs_f64()
    };
    // [command, fs_write of its outputs, inline in process, output_dir, fs_write of all,
    //  output_dir before its sync, fs_write of the bulk]
    let mut best = [f64::INFINITY; 7];
    for _ in 0..runs {
        // The command: it creates the folder itself, as users run it.
        let dir = fresh("command");
        std::fs::remove_dir(&dir).unwrap();
        let start = Instant::now();
        let status = Command::new(&bin)
            .arg("inline")
            .args(&command_models)
            .arg("--out-dir")
            .arg(&dir)
            .status()
            .expect("run mjcf-forge");
        best[0] = best[0].min(start.elapsed().as_secs_f64());
        assert!(status.success());
        check(&dir, &command_outputs);

        let dir = fresh("fs_write_command");
        best[1] = best[1].min(fs_write(&dir, &command_outputs));
        check(&dir, &command_outputs);

        // What the command does, in this process: load, inline, write, one sync.
        let dir = fresh("inline");
        let start = Instant::now();
        let out = OutputDir::create(&dir).unwrap();
        models
            .par_iter()
            .try_for_each(|m| {
                let doc = Document::load(m).unwrap();
                out.write(&unique_name(m), doc.to_pretty_string().as_bytes())
            })
            .unwrap();
        out.finish().unwrap();
        best[2] = best[2].min(start.elapsed().as_secs_f64());
        check(&dir, &outputs);

        let dir = fresh("output_dir");
        let start = Instant::now();
        let out = OutputDir::create(&dir).unwrap();
        bulk.par_iter()
            .try_for_each(|(name, b)| out.write(name, b))
            .unwrap();
        let written = start.elapsed().as_secs_f64();
        out.finish().unwrap();
        best[3] = best[3].min(start.elapsed().as_secs_f64());
        best[5] = best[5].min(written);
        check(&dir, &bulk);

        let dir = fresh("fs_write_bulk");
        best[6] = best[6].min(fs_write(&dir, &bulk));
        check(&dir, &bulk);

        let dir = fresh("fs_write");
        best[4] = best[4].min(fs_write(&dir, &outputs));
        check(&dir, &outputs);
    }
    let _ = std::fs::remove_dir_all(&scratch);
    let per_file = |s: f64, n: usize| s / n as f64 * 1e6;
    let (n, nc, nb) = (outputs.len(), command_outputs.len(), bulk.len());
    println!(
        "{{\"files\": {n}, \"command_files\": {nc}, \"output_dir_files\": {nb}, \"runs\": {runs}, \
         \"command_us_per_file\": {:.1}, \"fs_write_us_per_file_command\": {:.1}, \"command_ratio\": {:.2}, \
         \"inline_us_per_file\": {:.1}, \"fs_write_us_per_file\": {:.1}, \
         \"inline_ratio\": {:.2}, \
         \"output_dir_us_per_file\": {:.1}, \"output_dir_unsynced_us_per_file\": {:.1}, \"fs_write_us_per_file_output_dir\": {:.1}, \
         \"output_dir_ratio\": {:.2}, \"output_dir_unsynced_ratio\": {:.2}, \"sync_ms\": {:.2}}}",
        per_file(best[0], nc),
        per_file(best[1], nc),
        best[0] / best[1],
        per_file(best[2], n),
        per_file(best[4], n),
        best[2] / best[4],
        per_file(best[3], nb),
        per_file(best[5], nb),
        per_file(best[6], nb),
        best[3] / best[6],
        best[5] / best[6],
        (best[3] - best[5]) * 1e3,
    );
}

/// Every output is there with the expected bytes, and nothing else.
fn check(dir: &Path, outputs: &[(String, Vec<u8>)]) {
    assert_eq!(std::fs::read_dir(dir).unwrap().count(), outputs.len());
    for (name, b) in outputs {
        assert!(&std::fs::read(dir.join(name)).unwrap() == b, "{name}");
    }
}
