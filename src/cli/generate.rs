//! `generate [SCENE] -n N -o OUT`: seeded variants of a scene, in parallel, streamed to a
//! folder (one XML per variant, `manifest*.jsonl`, `assets/`), a tar file or standard
//! output (`-`: a WebDataset-style tar stream: `assets/...` first, then
//! `NNNNNNNNN.xml` and `NNNNNNNNN.json` per variant).
//!
//! Variants are made in chunks, each chunk in parallel and written in index order, so
//! memory stays bounded and the output is the same bytes for any thread count. With
//! `--shard K/N` this process makes only its share of the indices; N processes given the
//! same folder together write what one process writes (each its own manifest).

use std::io::{BufWriter, IsTerminal as _, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use mjcf_forge::output::AtomicFile;
use mjcf_forge::scene::{Params, Scene};
use mjcf_forge::{AssetStore, OutputDir, TarWriter, frame_text_member};
use rayon::prelude::*;

use super::{USAGE, refuse_validate_without_mujoco};

/// Variants made in parallel before their chunk is written: enough to keep every thread
/// busy, few enough that the chunk's texts (~50 KB each for a robot scene) are reused
/// memory rather than fresh pages for every chunk (512 spent a fifth of the time in
/// page faults).
const CHUNK: u64 = 64;

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (TOML); the built-in demo scene without it.
    scene: Option<PathBuf>,
    /// How many variants (indices START..START+N).
    #[arg(short = 'n', long = "count", default_value_t = 10)]
    count: u64,
    /// A folder, a `.tar` file (with `--shard K/N`: `NAME-KKKKKK.tar`), or `-` for a tar
    /// stream on standard output.
    #[arg(short, long)]
    output: PathBuf,
    /// Seed (overrides the scene file's).
    #[arg(long)]
    seed: Option<u64>,
    /// First index.
    #[arg(long, default_value_t = 0)]
    start: u64,
    /// Worker threads (all cores without it).
    #[arg(long)]
    threads: Option<usize>,
    /// This process's share, K/N with K counted from 0 (as Slurm array task ids are).
    #[arg(long)]
    shard: Option<String>,
    /// Compile every variant with MuJoCo and check that no placed object interpenetrates
    /// another object or a fixture (needs the `mujoco` feature).
    #[arg(long)]
    validate: bool,
    /// Print the summary as JSON on standard output (standard error when the variants go
    /// to standard output).
    #[arg(long)]
    json: bool,
    /// Indented XML instead of compact XML.
    #[arg(long)]
    pretty: bool,
}

/// Where the variants go.
/// A chunk position's reused buffer: the variant's XML, or for a tar stream its two
/// members (XML and JSON) framed.
#[derive(Default)]
struct Slot {
    framed: String,
}

enum Sink {
    Dir {
        out: OutputDir,
        manifest: BufWriter<AtomicFile>,
    },
    Tar {
        tar: TarWriter<BufWriter<AtomicFile>>,
        /// Assets written out for `--validate` (the stream itself is not on disk).
        check_dir: Option<tempfile::TempDir>,
    },
}

pub fn run(args: Args) -> ExitCode {
    if let Some(code) = refuse_validate_without_mujoco(args.validate) {
        return code;
    }
    let shard = match args.shard.as_deref().map(parse_shard).transpose() {
        Ok(s) => s.unwrap_or((0, 1)),
        Err(e) => {
            eprintln!("mjcf-forge: --shard: {e}");
            return ExitCode::from(USAGE);
        }
    };
    let pool = match rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
    {
        Ok(p) => p,
        Err(e) => {
            eprintln!("mjcf-forge: cannot start worker threads: {e}");
            return ExitCode::FAILURE;
        }
    };
    match pool.install(|| generate(&args, shard)) {
        Ok(summary) => {
            let text = summary.text();
            if args.json {
                let json = summary.json();
                if args.output == Path::new("-") {
                    eprintln!("{json}");
                } else {
                    println!("{json}");
                }
            } else {
                eprintln!("{text}");
            }
            for f in &summary.failures {
                eprintln!("{f}");
            }
            if summary.failures.is_empty() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

/// `K/N` with `K < N`.
fn parse_shard(text: &str) -> Result<(u64, u64), String> {
    let (k, n) = text
        .split_once('/')
        .ok_or_else(|| format!("expected K/N (such as 0/4), got '{text}'"))?;
    let k: u64 = k
        .trim()
        .parse()
        .map_err(|_| format!("K in '{text}' is not a number"))?;
    let n: u64 = n
        .trim()
        .parse()
        .map_err(|_| format!("N in '{text}' is not a number"))?;
    if n == 0 || k >= n {
        return Err(format!("need 0 <= K < N, got '{text}'"));
    }
    Ok((k, n))
}

/// What a run did.
struct Summary {
    variants: u64,
    bytes: u64,
    seconds: f64,
    /// Time spent compiling with MuJoCo, summed over threads (with `--validate`).
    compile: Option<Duration>,
    failures: Vec<String>,
    output: String,
    range: (u64, u64),
}

impl Summary {
    fn rate(&self) -> f64 {
        self.variants as f64 / self.seconds.max(1e-9)
    }

    fn text(&self) -> String {
        let mut s = format!(
            "generated {} variants (indices {}..{}) in {:.2} s: {:.0} variants/s, {:.1} MB of XML -> {}",
            self.variants,
            self.range.0,
            self.range.1,
            self.seconds,
            self.rate(),
            self.bytes as f64 / 1e6,
            self.output
        );
        if let Some(c) = self.compile {
            s.push_str(&format!(
                "; MuJoCo compile {:.2} ms per variant (summed over threads)",
                c.as_secs_f64() * 1e3 / self.variants.max(1) as f64
            ));
        }
        s.push_str(&format!("; {} failed", self.failures.len()));
        s
    }

    fn json(&self) -> String {
        serde_json::json!({
            "variants": self.variants,
            "start": self.range.0,
            "end": self.range.1,
            "seconds": self.seconds,
            "variants_per_second": self.rate(),
            "xml_bytes": self.bytes,
            "compile_ms_per_variant": self.compile.map(|c| c.as_secs_f64() * 1e3 / self.variants.max(1) as f64),
            "failures": self.failures,
            "output": self.output,
        })
        .to_string()
    }
}

fn generate(args: &Args, (k, n): (u64, u64)) -> Result<Summary, String> {
    let started = Instant::now();
    let mut scene = match &args.scene {
        Some(path) => Scene::load(path),
        None => Scene::demo(),
    }
    .map_err(|e| e.to_string())?;
    if let Some(seed) = args.seed {
        scene = scene.with_seed(seed);
    }
    let store = AssetStore::new();
    scene.relocate_assets(&store).map_err(|e| e.to_string())?;
    let lo = args.start + args.count * k / n;
    let hi = args.start + args.count * (k + 1) / n;
    // A scene that cannot make even its first variant (say, a region too small for its
    // objects) is refused before anything is written.
    if lo < hi {
        scene.variant(lo).map_err(|e| e.to_string())?;
    }
    let mut sink = open_sink(
        &args.output,
        &store,
        args.validate,
        (k, n),
        args.shard.is_some(),
    )?;
    let check_dir: Option<PathBuf> = match &sink {
        Sink::Dir { out, .. } => Some(out.path().to_path_buf()),
        Sink::Tar { check_dir, .. } => check_dir.as_ref().map(|d| d.path().to_path_buf()),
    };
    let progress = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(hi - lo);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} variants {per_sec} eta {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    let mut summary = Summary {
        variants: 0,
        bytes: 0,
        seconds: 0.0,
        compile: args.validate.then_some(Duration::ZERO),
        failures: Vec::new(),
        output: args.output.display().to_string(),
        range: (lo, hi),
    };
    // One text buffer per variant of a chunk, reused chunk after chunk: a variant is
    // written into memory the last chunk left, not into fresh pages. Everything but the
    // ordered writes happens on the workers (a tar stream's members are framed there), so
    // the writing thread does one write per variant.
    let is_tar = matches!(sink, Sink::Tar { .. });
    let mut slots: Vec<Slot> = (0..CHUNK).map(|_| Slot::default()).collect();
    let mut at = lo;
    while at < hi {
        let end = (at + CHUNK).min(hi);
        let made: Vec<Result<(String, Duration, u64), String>> = slots[..(end - at) as usize]
            .par_iter_mut()
            .enumerate()
            .map(|(k, slot)| {
                let i = at + k as u64;
                let file = format!("{i:09}.xml");
                let make = |buf: &mut String| -> Result<Params, String> {
                    if args.pretty {
                        let v = scene.variant(i).map_err(|e| e.to_string())?;
                        buf.push_str(&v.document.to_pretty_string());
                        Ok(v.params)
                    } else {
                        scene.variant_xml_append(i, buf).map_err(|e| e.to_string())
                    }
                };
                // For a tar stream the XML is written straight into its member.
                let (params, xml) = if is_tar {
                    slot.framed.clear();
                    let (params, range) = frame_text_member(&mut slot.framed, &file, |buf| {
                        let start = buf.len();
                        make(buf).map(|p| (p, start..buf.len()))
                    })
                    .map_err(|e| e.to_string())??;
                    (params, &slot.framed[range])
                } else {
                    slot.framed.clear();
                    (make(&mut slot.framed)?, slot.framed.as_str())
                };
                let took = match (&check_dir, args.validate) {
                    (Some(dir), true) => check(i, &params, xml, dir)?,
                    _ => Duration::ZERO,
                };
                let json = params.to_json(i, Some(&file));
                if let Sink::Dir { out, .. } = &sink {
                    out.write(&file, xml.as_bytes())
                        .map_err(|e| e.to_string())?;
                }
                let bytes = xml.len() as u64;
                if is_tar {
                    frame_text_member(&mut slot.framed, &format!("{i:09}.json"), |m| {
                        m.push_str(&json);
                        Ok::<(), String>(())
                    })
                    .map_err(|e| e.to_string())??;
                }
                Ok((json, took, bytes))
            })
            .collect();
        for (r, slot) in made.into_iter().zip(&slots) {
            match r {
                Ok((json, took, bytes)) => {
                    summary.variants += 1;
                    summary.bytes += bytes;
                    if let Some(c) = &mut summary.compile {
                        *c += took;
                    }
                    write_variant(&mut sink, &json, slot.framed.as_bytes())?;
                }
                Err(e) => summary.failures.push(e),
            }
        }
        if let Some(bar) = &progress {
            bar.inc(end - at);
        }
        at = end;
    }
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    close_sink(sink)?;
    summary.seconds = started.elapsed().as_secs_f64();
    Ok(summary)
}

#[cfg(mjcf_mujoco)]
fn check(i: u64, params: &Params, xml: &str, dir: &Path) -> Result<Duration, String> {
    let t = Instant::now();
    mjcf_forge::scene::check_variant(i, params, xml, dir)?;
    Ok(t.elapsed())
}

#[cfg(not(mjcf_mujoco))]
fn check(_: u64, _: &Params, _: &str, _: &Path) -> Result<Duration, String> {
    Err(super::NO_MUJOCO.to_owned())
}

fn open_sink(
    output: &Path,
    store: &AssetStore,
    validate: bool,
    (k, n): (u64, u64),
    sharded: bool,
) -> Result<Sink, String> {
    let is_tar = output == Path::new("-") || output.extension().is_some_and(|e| e == "tar");
    if !is_tar {
        let out = OutputDir::create(output).map_err(|e| e.to_string())?;
        store.write_to_dir(&out).map_err(|e| e.to_string())?;
        let name = if sharded {
            format!("manifest-{k}-of-{n}.jsonl")
        } else {
            "manifest.jsonl".to_string()
        };
        let manifest = out.create_file(&name).map_err(|e| e.to_string())?;
        return Ok(Sink::Dir {
            out,
            manifest: BufWriter::with_capacity(1 << 16, manifest),
        });
    }
    let check_dir = if validate {
        let dir =
            tempfile::tempdir().map_err(|e| format!("cannot make a folder for --validate: {e}"))?;
        let out = OutputDir::create(dir.path()).map_err(|e| e.to_string())?;
        store.write_to_dir(&out).map_err(|e| e.to_string())?;
        out.finish().map_err(|e| e.to_string())?;
        Some(dir)
    } else {
        None
    };
    // Shards writing tar files each write their own, named as WebDataset shards are.
    let path = if output == Path::new("-") {
        PathBuf::from("/dev/stdout")
    } else if sharded {
        let stem = output.file_stem().unwrap_or_default().to_string_lossy();
        output.with_file_name(format!("{stem}-{k:06}.tar"))
    } else {
        output.to_path_buf()
    };
    let file = AtomicFile::create(&path).map_err(|e| e.to_string())?;
    let label = if output == Path::new("-") {
        PathBuf::from("standard output")
    } else {
        path
    };
    let mut tar = TarWriter::new(BufWriter::with_capacity(1 << 20, file), label);
    store.write_to_tar(&mut tar).map_err(|e| e.to_string())?;
    Ok(Sink::Tar { tar, check_dir })
}

/// Writes a made variant in order: its manifest line to a folder (whose XML file a worker
/// wrote), or its framed tar members to the stream.
fn write_variant(sink: &mut Sink, json: &str, framed: &[u8]) -> Result<(), String> {
    match sink {
        Sink::Dir { manifest, .. } => manifest
            .write_all(json.as_bytes())
            .and_then(|()| manifest.write_all(b"\n"))
            .map_err(|e| format!("cannot write the manifest: {e}")),
        Sink::Tar { tar, .. } => tar.append_framed(framed).map_err(|e| e.to_string()),
    }
}

/// Puts the outputs in place: the manifest (or the tar file) appears whole, only now.
fn close_sink(sink: Sink) -> Result<(), String> {
    let commit = |w: BufWriter<AtomicFile>| -> Result<(), String> {
        let file = w
            .into_inner()
            .map_err(|e| format!("cannot write the output: {}", e.error()))?;
        file.commit().map_err(|e| e.to_string())
    };
    match sink {
        Sink::Dir { out, manifest } => {
            commit(manifest)?;
            out.finish().map_err(|e| e.to_string())
        }
        Sink::Tar { tar, .. } => commit(tar.finish().map_err(|e| e.to_string())?),
    }
}
