//! The `mjcf-forge` command line.
//!
//! Every subcommand reports problems on standard error as `file:line:col: message`, one
//! problem per line, and exits non-zero; it never writes a partial output file (outputs go
//! through [`mjcf_forge::write_atomic`], and only after everything that can fail has run).
//! Exit codes: 0 success, 1 a model failed (loading, compiling, writing), 2 bad usage; a
//! run whose standard output was closed by its reader (`| head`) ends quietly with 0.
//!
//! Each subcommand lives in its own file under `src/cli/` with its `Args` and `run`;
//! adding one is that file plus one variant of [`Command`] and one arm of its dispatch.
#![cfg_attr(not(mjcf_mujoco), forbid(unsafe_code))]
#![cfg_attr(mjcf_mujoco, deny(unsafe_code))]

mod cli;

use std::process::ExitCode;

/// mimalloc rather than the system's malloc: `generate` makes about 145 small allocations
/// per variant of a robot scene, a fifth of its time with glibc's; with mimalloc a lift5
/// variant costs about 15% less CPU, on one thread or two (`docs/speed.md`, "Thread scaling").
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "mjcf-forge",
    version,
    about = "Load, inline, prefix and merge MuJoCo MJCF models"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Expand includes, inline default classes and make file paths absolute.
    Inline(cli::inline::Args),
    /// Load a model and give every name in it a prefix (identifiers and every reference).
    Prefix(cli::prefix::Args),
    /// Merge parts into a base model: `--part FILE[:PREFIX[:BODY]]` gives the part the name
    /// prefix PREFIX and puts it into the base's body BODY (the world body without it).
    Merge(cli::merge::Args),
    /// The model tier's view of a model: its lists (bodies, joints, actuators, sites,
    /// sensors, contact and visual geoms) and offsets.
    Info(cli::info::Args),
    /// Load a model as `inline` does, compile it with MuJoCo and print its sizes
    /// (needs the `mujoco` feature).
    Compile(cli::compile::Args),
    /// Write a model as a folder that can be moved: the model, its file references
    /// rewritten to `assets/<content hash>.<ext>`, and those files.
    Export(cli::export::Args),
    /// Make seeded variants of a scene (a TOML scene file, or the built-in demo): a folder
    /// with one XML per variant, `manifest.jsonl` and `assets/`, a `.tar` file, or `-`.
    Generate(cli::generate::Args),
    /// A contact sheet of variants of a scene: each drawn by MuJoCo's renderer, headless
    /// (EGL, else OSMesa), into one cell of a PNG grid, labelled with its index (needs the
    /// `mujoco` feature).
    Preview(cli::preview::Args),
    /// The model store the caches keep compiled structures in across processes: `info`,
    /// `list` its entries, or `clear` it.
    Store(cli::store::Args),
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Inline(args) => cli::inline::run(args),
        Command::Prefix(args) => cli::prefix::run(args),
        Command::Merge(args) => cli::merge::run(args),
        Command::Info(args) => cli::info::run(args),
        Command::Compile(args) => cli::compile::run(args),
        Command::Export(args) => cli::export::run(args),
        Command::Generate(args) => cli::generate::run(args),
        Command::Preview(args) => cli::preview::run(args),
        Command::Store(args) => cli::store::run(args),
    }
}
