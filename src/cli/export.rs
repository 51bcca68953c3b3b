//! `export IN -o DIR`: one model as a relocatable folder, `DIR/<input file name>` and
//! `DIR/assets/<hash>.<ext>` for every file it refers to (what dm_control's
//! `export_with_assets` does), or with `--tar` the same as one tar stream.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use mjcf_forge::output::AtomicFile;
use mjcf_forge::{AssetStore, OutputDir, TarWriter};

use super::{USAGE, WriteOptions, finish, refuse_validate_without_mujoco, render};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    urdf: super::UrdfArgs,
    /// Input MJCF file.
    input: PathBuf,
    /// Output folder (created if missing); with `--tar`, the tar file (`-` for standard
    /// output).
    #[arg(short, long)]
    output: PathBuf,
    /// Write one tar stream (the folder's files as members, assets first) instead of a
    /// folder.
    #[arg(long)]
    tar: bool,
    /// Replace an output folder that is not empty, whole (atomically where the filesystem
    /// allows); without it such a folder is refused.
    #[arg(long)]
    replace: bool,
    #[command(flatten)]
    write: WriteOptions,
}

pub fn run(args: Args) -> ExitCode {
    if let Some(code) = refuse_validate_without_mujoco(args.write.validate) {
        return code;
    }
    let Some(name) = args.input.file_name().and_then(|n| n.to_str()) else {
        eprintln!("{}: not a UTF-8 file name", args.input.display());
        return ExitCode::from(USAGE);
    };
    let options = args.write;
    if !args.tar
        && let Err(e) = super::refuse_non_empty(&args.output, args.replace)
    {
        // Before loading anything: nothing runs in vain.
        eprintln!("{e}");
        return ExitCode::FAILURE;
    }
    let result = prepare(
        &args.input,
        options,
        &super::Loader::new(&args.limits, &args.urdf),
    )
    .and_then(|(store, text)| {
        if args.tar {
            export_tar(&store, name, &text, &args.output).map_err(|e| {
                if args.output == Path::new("-") {
                    super::quiet_if_stdout_closed(e)
                } else {
                    e
                }
            })
        } else {
            export_dir(&store, name, &text, &args.output, args.replace)
        }
    });
    finish(&[result])
}

/// Loads, validates (when asked, before anything moves: the model as it compiles from
/// its own folder) and relocates the model; returns its assets and its XML.
fn prepare(
    input: &Path,
    options: WriteOptions,
    limits: &super::Loader,
) -> Result<(AssetStore, String), String> {
    let mut doc = limits.load(input).map_err(|e| e.to_string())?;
    if options.validate {
        super::validate(&doc)?;
    }
    let store = AssetStore::new();
    doc.relocate_assets(&store).map_err(|e| e.to_string())?;
    let text = render(
        &doc,
        WriteOptions {
            validate: false,
            ..options
        },
    )?;
    Ok((store, text))
}

/// Assets first, the model last, into a folder staged beside `dir` and put in place whole
/// at the end (replacing a folder there with `replace`): on failure nothing is left and
/// `dir` stays as it was.
fn export_dir(
    store: &AssetStore,
    name: &str,
    text: &str,
    dir: &Path,
    replace: bool,
) -> Result<(), String> {
    let out: OutputDir = super::open_output_dir(dir, replace)?;
    store
        .write_to_dir(&out)
        .and_then(|()| out.write(name, text.as_bytes()))
        .and_then(|()| out.finish())
        .map_err(|e| e.to_string())
}

/// The tar stream goes straight to its output as it is made (assets first, the model
/// last); a regular file appears whole, under its name, only once the stream is complete.
fn export_tar(store: &AssetStore, name: &str, text: &str, output: &Path) -> Result<(), String> {
    let (path, label) = if output == Path::new("-") {
        (Path::new("/dev/stdout"), PathBuf::from("standard output"))
    } else {
        (output, output.to_path_buf())
    };
    let file = AtomicFile::create(path).map_err(|e| e.to_string())?;
    let mut tar = TarWriter::new(std::io::BufWriter::with_capacity(1 << 20, file), label);
    store
        .write_to_tar(&mut tar)
        .and_then(|()| tar.append(name, text.as_bytes()))
        .map_err(|e| e.to_string())?;
    let buffered = tar.finish().map_err(|e| e.to_string())?;
    // `finish` flushed the buffer, so taking the file out of it cannot fail.
    let file = buffered
        .into_inner()
        .map_err(|e| format!("cannot write '{}': {}", output.display(), e.error()))?;
    file.commit().map_err(|e| e.to_string())
}
