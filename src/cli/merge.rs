//! `merge BASE --part FILE[:PREFIX[:BODY]] ... [--fuse-keys] [-o OUT]`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use mjcf_forge::{Document, MergeOptions};
use rayon::prelude::*;

use super::{USAGE, WriteOptions, emit, finish, refuse_validate_without_mujoco};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    urdf: super::UrdfArgs,
    /// The base model.
    base: PathBuf,
    /// A part: FILE, FILE:PREFIX or FILE:PREFIX:BODY (in order of merging).
    #[arg(long = "part", required = true)]
    parts: Vec<String>,
    /// Fuse each part key PREFIX+NAME into the base key NAME (one "home" pose for the scene).
    #[arg(long)]
    fuse_keys: bool,
    /// Output file; standard output without it.
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[command(flatten)]
    write: WriteOptions,
}

pub fn run(args: Args) -> ExitCode {
    if let Some(code) = refuse_validate_without_mujoco(args.write.validate) {
        return code;
    }
    let specs: Vec<PartSpec> = match args.parts.iter().map(|p| PartSpec::parse(p)).collect() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("mjcf-forge: {e}");
            return ExitCode::from(USAGE);
        }
    };
    let options = args.write;
    finish(&[merge(
        &args.base,
        &specs,
        args.fuse_keys,
        args.output.as_deref(),
        options,
        &super::Loader::new(&args.limits, &args.urdf),
    )])
}

/// One `--part FILE[:PREFIX[:BODY]]` of `merge`.
struct PartSpec {
    file: PathBuf,
    prefix: String,
    body: Option<String>,
}

impl PartSpec {
    fn parse(spec: &str) -> Result<PartSpec, String> {
        let mut it = spec.splitn(3, ':');
        let file = it
            .next()
            .filter(|f| !f.is_empty())
            .ok_or_else(|| format!("--part '{spec}': no file"))?;
        let prefix = it.next().unwrap_or_default().to_string();
        let body = it.next().filter(|b| !b.is_empty()).map(str::to_string);
        Ok(PartSpec {
            file: PathBuf::from(file),
            prefix,
            body,
        })
    }
}

/// Loads the base and every part, prefixes and merges each in order, then writes.
fn merge(
    base: &Path,
    parts: &[PartSpec],
    fuse_keys: bool,
    output: Option<&Path>,
    options: WriteOptions,
    limits: &super::Loader,
) -> Result<(), String> {
    let mut scene = limits.load(base).map_err(|e| e.to_string())?;
    // Parts load in parallel; they merge in the order given.
    let loaded: Vec<Result<Document, String>> = parts
        .par_iter()
        .map(|p| {
            let mut doc = limits.load(&p.file).map_err(|e| e.to_string())?;
            doc.apply_prefix(&p.prefix).map_err(|e| e.to_string())?;
            Ok(doc)
        })
        .collect();
    for (spec, doc) in parts.iter().zip(loaded) {
        let doc = doc?;
        let merge_options = MergeOptions {
            fuse_keys,
            part_prefix: spec.prefix.clone(),
        };
        let report = scene
            .merge(&doc, spec.body.as_deref(), &merge_options)
            .map_err(|e| e.to_string())?;
        for w in report.warnings {
            eprintln!("warning: {w}");
        }
    }
    emit(&scene, output, options)
}
