//! `prefix IN --prefix P [-o OUT]`.

use std::path::PathBuf;
use std::process::ExitCode;

use super::{WriteOptions, emit, finish, refuse_validate_without_mujoco};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    urdf: super::UrdfArgs,
    /// Input MJCF file.
    input: PathBuf,
    /// The prefix.
    #[arg(long)]
    prefix: String,
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
    let options = args.write;
    let limits = super::Loader::new(&args.limits, &args.urdf);
    let result = limits
        .load(&args.input)
        .map_err(|e| e.to_string())
        .and_then(|mut doc| {
            doc.apply_prefix(&args.prefix).map_err(|e| e.to_string())?;
            emit(&doc, args.output.as_deref(), options)
        });
    finish(&[result])
}
