//! `compile IN [--json]`, and the mapping from MuJoCo's error lines back to the user's
//! sources that `--validate` shares.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[cfg(mjcf_mujoco)]
use mjcf_forge::Document;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    urdf: super::UrdfArgs,
    /// Input MJCF file.
    input: PathBuf,
    /// Print the sizes as one JSON object.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> ExitCode {
    compile(
        &args.input,
        args.json,
        &super::Loader::new(&args.limits, &args.urdf),
    )
}

/// `compile IN [--json]`.
#[cfg(mjcf_mujoco)]
fn compile(input: &Path, json: bool, limits: &super::Loader) -> ExitCode {
    let doc = match limits.load(input) {
        Ok(doc) => doc,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let model = match compile_document(&doc) {
        Ok(model) => model,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    if let Some(w) = model.warnings() {
        eprintln!("{}: MuJoCo warning: {w}", input.display());
    }
    let sizes = model.sizes();
    let text = if json {
        format!("{}\n", sizes.to_json())
    } else {
        let width = sizes
            .entries()
            .iter()
            .map(|(k, _)| k.len())
            .max()
            .unwrap_or(0);
        sizes
            .entries()
            .iter()
            .map(|(key, value)| format!("{key:<width$} {value}\n"))
            .collect()
    };
    super::finish(&[super::write_stdout(text.as_bytes())])
}

/// `compile` in a build without MuJoCo: says how to get one.
#[cfg(not(mjcf_mujoco))]
fn compile(_input: &Path, _json: bool, _limits: &super::Loader) -> ExitCode {
    eprintln!("mjcf-forge: compile: {}", super::NO_MUJOCO);
    ExitCode::from(super::USAGE)
}

/// Compiles the document with MuJoCo, MuJoCo's error at the element it names in the
/// user's sources (`mjcf_forge::mujoco::compile_document`), ready to print.
#[cfg(mjcf_mujoco)]
pub(crate) fn compile_document(
    doc: &Document,
) -> Result<mjcf_forge::mujoco::CompiledModel, String> {
    mjcf_forge::mujoco::compile_document(doc).map_err(|e| e.to_string())
}
