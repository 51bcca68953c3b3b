//! `inline IN [-o OUT]` and `inline IN... --out-dir DIR`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use std::collections::HashMap;

use mjcf_forge::OutputDir;
use rayon::prelude::*;

use super::{USAGE, WriteOptions, emit, finish, refuse_validate_without_mujoco, render};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    urdf: super::UrdfArgs,
    /// Input MJCF files.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Output file (one input only); standard output without it.
    #[arg(short, long, conflicts_with = "out_dir")]
    output: Option<PathBuf>,
    /// Output folder: one file per input, named after it.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    #[command(flatten)]
    write: WriteOptions,
}

pub fn run(args: Args) -> ExitCode {
    // Without MuJoCo, fail before loading anything rather than once per model.
    if let Some(code) = refuse_validate_without_mujoco(args.write.validate) {
        return code;
    }
    let options = args.write;
    let limits = super::Loader::new(&args.limits, &args.urdf);
    match args.out_dir {
        Some(dir) => inline_to_dir(&args.inputs, &dir, options, &limits),
        None => inline_one_input(&args.inputs, args.output.as_deref(), options, &limits),
    }
}

fn inline_one_input(
    inputs: &[PathBuf],
    output: Option<&Path>,
    options: WriteOptions,
    limits: &super::Loader,
) -> ExitCode {
    if inputs.len() > 1 {
        eprintln!("mjcf-forge: several inputs need --out-dir DIR");
        return ExitCode::from(USAGE);
    }
    finish(&[inline_model(&inputs[0], output, options, limits)])
}

/// `inline --out-dir`: plans every output before writing any, so that a clash between two
/// inputs is reported without touching the folder; then runs the models in parallel,
/// writing each into one [`OutputDir`] (no lock, no sync per file; one sync at the end),
/// and reports their problems in input order (never in thread order).
fn inline_to_dir(
    inputs: &[PathBuf],
    dir: &Path,
    options: WriteOptions,
    limits: &super::Loader,
) -> ExitCode {
    let jobs = match plan_outputs(inputs, dir) {
        Ok(jobs) => jobs,
        Err(problems) => {
            for p in problems {
                eprintln!("{p}");
            }
            return ExitCode::from(USAGE);
        }
    };
    let out = match OutputDir::create(dir) {
        Ok(out) => out,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let mut results: Vec<Result<(), String>> = jobs
        .par_iter()
        .map(|job| {
            let doc = limits.load(job.input).map_err(|e| e.to_string())?;
            let text = render(&doc, options)?;
            out.write(job.output, text.as_bytes())
                .map_err(|e| e.to_string())
        })
        .collect();
    results.push(out.finish().map_err(|e| e.to_string()));
    finish(&results)
}

/// One input of `inline --out-dir` and the file it becomes in the folder.
struct Job<'a> {
    input: &'a Path,
    output: &'a str,
}

/// The output of each distinct input, in input order. An input named twice (by any path
/// spelling: the same file) is done once; two different inputs that would write the same
/// output are an error, as is an input without a (UTF-8) file name.
fn plan_outputs<'a>(inputs: &'a [PathBuf], dir: &Path) -> Result<Vec<Job<'a>>, Vec<String>> {
    let mut jobs: Vec<Job<'a>> = Vec::new();
    let mut identities: Vec<FileIdentity> = Vec::new();
    let mut by_output: HashMap<&str, usize> = HashMap::new();
    let mut problems = Vec::new();
    for input in inputs {
        let Some(name) = input.file_name() else {
            problems.push(format!("{}: not a file name", input.display()));
            continue;
        };
        let Some(output) = name.to_str() else {
            problems.push(format!("{}: not a UTF-8 file name", input.display()));
            continue;
        };
        let identity = FileIdentity::of(input);
        match by_output.get(output) {
            Some(&i) if identities[i] == identity => {}
            Some(&i) => problems.push(format!(
                "{}: output '{}' is already taken by '{}'",
                input.display(),
                dir.join(output).display(),
                jobs[i].input.display()
            )),
            None => {
                by_output.insert(output, jobs.len());
                jobs.push(Job { input, output });
                identities.push(identity);
            }
        }
    }
    if problems.is_empty() {
        Ok(jobs)
    } else {
        Err(problems)
    }
}

/// What makes two input paths the same file: its device and inode (one `stat`, where
/// canonicalizing costs one per path component), or its spelling when it cannot be read
/// (loading it then reports the problem).
#[derive(PartialEq, Eq)]
enum FileIdentity {
    #[cfg(unix)]
    Inode(u64, u64),
    Spelling(PathBuf),
}

impl FileIdentity {
    fn of(path: &Path) -> FileIdentity {
        #[cfg(unix)]
        if let Ok(m) = std::fs::metadata(path) {
            use std::os::unix::fs::MetadataExt;
            return FileIdentity::Inode(m.dev(), m.ino());
        }
        FileIdentity::Spelling(path.to_path_buf())
    }
}

/// Loads, optionally validates, and writes one model (standard output without `output`).
fn inline_model(
    input: &Path,
    output: Option<&Path>,
    options: WriteOptions,
    limits: &super::Loader,
) -> Result<(), String> {
    let doc = limits.load(input).map_err(|e| e.to_string())?;
    emit(&doc, output, options)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plan_outputs_allows_repeats_and_refuses_clashes() {
        let same = [PathBuf::from("a/x.xml"), PathBuf::from("a/x.xml")];
        assert_eq!(
            plan_outputs(&same, Path::new("out")).map(|j| j.len()).ok(),
            Some(1)
        );
        let clash = [PathBuf::from("a/x.xml"), PathBuf::from("b/x.xml")];
        let problems = plan_outputs(&clash, Path::new("out")).err().unwrap();
        assert_eq!(problems.len(), 1);
        assert!(
            problems[0].starts_with("b/x.xml: output "),
            "{}",
            problems[0]
        );
    }
}
