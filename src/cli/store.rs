//! `store [--dir DIR] [list|clear]`: the model store that the caches keep compiled
//! structures in across processes (`split::DiskStore`): where it is, what it holds, and
//! emptying it.

use std::path::PathBuf;
use std::process::ExitCode;

use mjcf_forge::split::{DiskStore, STORE_VAR};

use super::USAGE;

#[derive(clap::Args)]
pub struct Args {
    /// The store's folder; without it, the one the caches use: `MJCF_FORGE_STORE`, else
    /// `$XDG_CACHE_HOME/mjcf-forge/models` (`~/.cache/mjcf-forge/models`).
    #[arg(long)]
    dir: Option<PathBuf>,
    /// What to do: `info` (the folder, its entries and bytes), `list` (each entry: key,
    /// bytes, last used, oldest first) or `clear` (remove every entry).
    #[arg(default_value = "info", value_parser = ["info", "list", "clear"])]
    action: String,
}

pub fn run(args: Args) -> ExitCode {
    let store = match args.dir {
        Some(dir) => DiskStore::open(dir, mjcf_forge::split::DEFAULT_STORE_BYTES),
        None => match DiskStore::from_env() {
            Some(store) => store,
            None => {
                println!("no model store ({STORE_VAR} turns it off, or no home folder)");
                return ExitCode::SUCCESS;
            }
        },
    };
    let store = match store {
        Ok(store) => store,
        Err(e) => {
            eprintln!("mjcf-forge: {e}");
            return ExitCode::FAILURE;
        }
    };
    let entries = match store.entries() {
        Ok(entries) => entries,
        Err(e) => {
            eprintln!("mjcf-forge: {e}");
            return ExitCode::FAILURE;
        }
    };
    match args.action.as_str() {
        "info" => {
            let bytes: u64 = entries.iter().map(|e| e.bytes).sum();
            println!(
                "{}: {} entries, {:.1} MB of at most {:.1} MB",
                store.dir().display(),
                entries.len(),
                bytes as f64 / 1e6,
                store.max_bytes() as f64 / 1e6
            );
        }
        "list" => {
            for e in entries {
                let age = e.used.elapsed().map_or(0, |d| d.as_secs());
                println!("{}  {:>12} bytes  used {age} s ago", e.key, e.bytes);
            }
        }
        "clear" => match store.clear() {
            Ok(n) => println!("{}: {n} entries removed", store.dir().display()),
            Err(e) => {
                eprintln!("mjcf-forge: {e}");
                return ExitCode::FAILURE;
            }
        },
        _ => return ExitCode::from(USAGE),
    }
    ExitCode::SUCCESS
}
