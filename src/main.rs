//! The `mjcf-forge` command line.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use mjcf_forge::{Document, Errors};
use rayon::prelude::*;

#[derive(Parser)]
#[command(name = "mjcf-forge", version, about = "Load, inline, prefix and merge MuJoCo MJCF models")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Expand includes, inline default classes and make file paths absolute.
    Inline {
        /// Input MJCF files.
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// Output file (one input only); standard output without it.
        #[arg(short, long, conflicts_with = "out_dir")]
        output: Option<PathBuf>,
        /// Output folder: one file per input, named after it.
        #[arg(long)]
        out_dir: Option<PathBuf>,
        /// Write compact XML instead of indented XML.
        #[arg(long)]
        compact: bool,
    },
}

fn render(doc: &Document, compact: bool) -> String {
    if compact { doc.to_xml_string() } else { doc.to_pretty_string() }
}

fn report(errors: &Errors) {
    for e in &errors.0 {
        eprintln!("{e}");
    }
}

fn inline(inputs: &[PathBuf], output: Option<&Path>, out_dir: Option<&Path>, compact: bool) -> ExitCode {
    if out_dir.is_none() && inputs.len() > 1 {
        eprintln!("mjcf-forge: several inputs need --out-dir DIR");
        return ExitCode::from(2);
    }
    let Some(dir) = out_dir else {
        return match Document::load(&inputs[0]) {
            Ok(doc) => {
                let text = render(&doc, compact);
                match output {
                    Some(path) => match mjcf_forge::write_atomic(path, text.as_bytes()) {
                        Ok(()) => ExitCode::SUCCESS,
                        Err(e) => {
                            eprintln!("{e}");
                            ExitCode::FAILURE
                        }
                    },
                    None => {
                        print!("{text}");
                        ExitCode::SUCCESS
                    }
                }
            }
            Err(errors) => {
                report(&errors);
                ExitCode::FAILURE
            }
        };
    };
    // One output per distinct input; two different inputs may not claim one output name.
    let mut jobs: BTreeMap<PathBuf, PathBuf> = BTreeMap::new();
    let mut bad = false;
    for input in inputs {
        let Some(name) = input.file_name() else {
            eprintln!("{}: not a file name", input.display());
            bad = true;
            continue;
        };
        let out = dir.join(name);
        let key = std::fs::canonicalize(input).unwrap_or_else(|_| input.clone());
        if let Some((other, _)) = jobs.iter().find(|(k, o)| **o == out && **k != key) {
            eprintln!(
                "{}: output '{}' is already written for '{}'",
                input.display(),
                out.display(),
                other.display()
            );
            bad = true;
            continue;
        }
        jobs.insert(key, out);
    }
    if let Err(e) = std::fs::create_dir_all(dir) {
        eprintln!("{}: cannot create folder: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    let results: Vec<Result<(), Errors>> = jobs
        .par_iter()
        .map(|(input, out)| {
            let doc = Document::load(input)?;
            mjcf_forge::write_atomic(out, render(&doc, compact).as_bytes())?;
            Ok(())
        })
        .collect();
    for r in &results {
        if let Err(errors) = r {
            report(errors);
            bad = true;
        }
    }
    if bad { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Inline { inputs, output, out_dir, compact } => {
            inline(&inputs, output.as_deref(), out_dir.as_deref(), compact)
        }
    }
}
