//! `preview [SCENE] -n N -o SHEET.png`: a contact sheet of variants, drawn by MuJoCo's own
//! renderer in a headless OpenGL context (EGL, else OSMesa), one cell per variant labelled
//! with its index (needs the `mujoco` feature).

use std::path::PathBuf;
use std::process::ExitCode;

use super::USAGE;

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (TOML); the built-in demo scene without it.
    scene: Option<PathBuf>,
    /// How many variants (indices START..START+N).
    #[arg(short = 'n', long = "count", default_value_t = 16)]
    count: u64,
    /// The PNG file written.
    #[arg(short, long)]
    output: PathBuf,
    /// First index.
    #[arg(long, default_value_t = 0)]
    start: u64,
    /// These indices instead of START..START+N (comma separated, e.g. `0,7,7,42`).
    #[arg(long, value_delimiter = ',', conflicts_with_all = ["count", "start"])]
    indices: Option<Vec<u64>>,
    /// Seed (overrides the scene file's).
    #[arg(long)]
    seed: Option<u64>,
    /// A cell's size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "320x240", value_parser = parse_cell)]
    cell: (u32, u32),
    /// Cells per row [default: the smallest whose square holds every cell].
    #[arg(long)]
    columns: Option<u32>,
    /// A camera of the scene, by its full name [default: MuJoCo's free camera of the
    /// first variant, the same for every cell].
    #[arg(long)]
    camera: Option<String>,
    /// Which geoms are drawn: default (groups 0-2, as MuJoCo draws), visual, collision, all.
    #[arg(long, default_value = "default")]
    geoms: String,
    /// No index in the cells' corners.
    #[arg(long)]
    no_labels: bool,
}

/// The most cells a sheet takes: a sheet is for looking at.
const MAX_CELLS: u64 = 1024;

/// `WIDTHxHEIGHT`.
fn parse_cell(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{text}' is not WIDTHxHEIGHT"))?;
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|v| (1..=4096).contains(v))
            .ok_or_else(|| format!("'{text}': each side must be a number from 1 to 4096"))
    };
    Ok((side(w)?, side(h)?))
}

pub fn run(args: Args) -> ExitCode {
    // Said before anything is read: without MuJoCo there is nothing to draw with.
    if !cfg!(mjcf_mujoco) {
        eprintln!("mjcf-forge: preview: {}", super::NO_MUJOCO);
        return ExitCode::from(USAGE);
    }
    let indices: Vec<u64> = match &args.indices {
        Some(list) => list.clone(),
        None => match args.start.checked_add(args.count) {
            Some(end) => (args.start..end).collect::<Vec<_>>(),
            None => {
                eprintln!("mjcf-forge: --start + -n is past the last index");
                return ExitCode::from(USAGE);
            }
        },
    };
    if indices.is_empty() || indices.len() as u64 > MAX_CELLS {
        eprintln!("mjcf-forge: a contact sheet takes 1 to {MAX_CELLS} variants");
        return ExitCode::from(USAGE);
    }
    if args.columns == Some(0) {
        eprintln!("mjcf-forge: --columns must be at least 1");
        return ExitCode::from(USAGE);
    }
    draw(&args, &indices)
}

#[cfg(mjcf_mujoco)]
fn draw(args: &Args, indices: &[u64]) -> ExitCode {
    use mjcf_forge::preview::{Geoms, SheetOptions, contact_sheet};
    use mjcf_forge::scene::Scene;

    let geoms: Geoms = match args.geoms.parse() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("mjcf-forge: --geoms: {e}");
            return ExitCode::from(USAGE);
        }
    };

    let loaded = match &args.scene {
        Some(path) => Scene::load(path),
        None => Scene::demo(),
    };
    let mut scene = match loaded {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    for w in scene.warnings() {
        eprintln!("{}: warning: {}", w.location, w.message);
    }
    if let Some(seed) = args.seed {
        scene = scene.with_seed(seed);
    }
    let options = SheetOptions {
        cell_width: args.cell.0,
        cell_height: args.cell.1,
        columns: args.columns,
        camera: args.camera.clone(),
        geoms,
        labels: !args.no_labels,
    };
    let written = contact_sheet(&scene, indices, &options).and_then(|sheet| {
        sheet
            .image
            .write_png(&args.output)
            .map(|()| sheet)
            .map_err(|e| mjcf_forge::Errors(vec![e]))
    });
    match written {
        Ok(sheet) => {
            eprintln!(
                "{}: {} variants, {}x{} cells in {} columns, {}x{} pixels",
                args.output.display(),
                indices.len(),
                options.cell_width,
                options.cell_height,
                sheet.layout.columns,
                sheet.image.width,
                sheet.image.height
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(not(mjcf_mujoco))]
fn draw(_: &Args, _: &[u64]) -> ExitCode {
    eprintln!("mjcf-forge: preview: {}", super::NO_MUJOCO);
    ExitCode::from(USAGE)
}
