//! `info IN [--prefix P] --json`.

use std::path::PathBuf;
use std::process::ExitCode;

use mjcf_forge::{Document, XmlModel, XmlModelOptions};

use super::{USAGE, finish};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    limits: super::LimitArgs,
    /// Input MJCF file (exactly one top-level body).
    input: PathBuf,
    /// Naming prefix of the instance (none by default).
    #[arg(long, default_value = "")]
    prefix: String,
    /// Print one JSON object (the only output form for now).
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> ExitCode {
    if !args.json {
        eprintln!("mjcf-forge: info prints JSON only: add --json");
        return ExitCode::from(USAGE);
    }
    let limits = args.limits.limits();
    let result = Document::load_with(&args.input, &limits)
        .map_err(|e| e.to_string())
        .and_then(|doc| {
            let options = XmlModelOptions {
                contact_geom_rgba: None,
                ..XmlModelOptions::default()
            };
            let model =
                XmlModel::with_prefix(doc, &args.prefix, options).map_err(|e| e.to_string())?;
            println!("{}", model.info_json());
            Ok(())
        });
    finish(&[result])
}
