//! `generate [SCENE] -n N -o OUT`: seeded variants of a scene, in parallel, streamed to a
//! folder (one XML per variant, `manifest*.jsonl`, `assets/`), a tar file or standard
//! output (`-`: a WebDataset-style tar stream: `assets/...` first, then
//! `NNNNNNNNN.xml` and `NNNNNNNNN.json` per variant).
//!
//! Variants are made in parallel into a ring of reused slots and written in index order
//! (`mjcf_forge::output::for_each_ordered`), so memory stays bounded and the output is
//! the same bytes for any thread count. With `--shard K/N` this process makes only its
//! share of the indices; N processes given the same folder together write what one
//! process writes (each its own manifest).
//!
//! An output folder is one run's output, never mixed with another's: without `--shard` it
//! is written beside its destination and put in place whole at the end (refused when the
//! destination holds something, replaced whole with `--replace`); the shards of one run
//! share it, and refuse it when it holds a file that is not that run's.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use mjcf_forge::output::AtomicFile;
use mjcf_forge::scene::{Params, Scene};
use mjcf_forge::{AssetStore, OutputDir, TarWriter, frame_text_member};

use super::progress::{Progress, Show};
use super::{QUIET_END, USAGE, quiet_if_stdout_closed, refuse_validate_without_mujoco};

/// Variants made but not yet written, at most: enough that no worker waits while another
/// one writes, few enough that their texts (~90 KB each for a robot scene as tar
/// members) are reused memory rather than fresh pages (a batch of 512 at a time spent a
/// fifth of the time in page faults).
const RING: usize = 128;

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
    /// Threads, writing included (all cores without it).
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
    /// Replace an output folder that is not empty, whole (atomically where the filesystem
    /// allows); without it such a folder is refused. Not with `--shard` (the shards of a
    /// run share their folder: empty it before starting them).
    #[arg(long)]
    replace: bool,
    /// No progress and no summary on standard error (problems are still reported;
    /// `--json` still prints its summary).
    #[arg(short, long)]
    quiet: bool,
}

/// A ring slot's reused buffers: the variant's XML, or for a tar stream its two members
/// (XML and JSON) framed; and its manifest line. What a worker makes stays in the slot
/// for whichever worker writes it: a buffer allocated on one thread and freed on another
/// takes the allocator's lock of the first (with glibc's malloc, two workers waited on it
/// thousands of times per second).
#[derive(Default)]
struct Slot {
    framed: Vec<u8>,
    json: String,
}

/// Where the variants go.
struct Outputs {
    /// The output folder, which workers write the variants' XML files into.
    files: Option<OutputDir>,
    /// The ordered writes (made by one worker at a time).
    writer: Writer,
    /// Assets written out for `--validate` of a tar stream (which is not on disk).
    check_dir: Option<tempfile::TempDir>,
}

/// The ordered part of the output, written by whichever worker finds the next variant
/// made while the others make the next ones: a folder's manifest, or the tar stream (the
/// assets first).
enum Writer {
    Manifest(BufWriter<AtomicFile>),
    Tar {
        tar: TarWriter<BufWriter<AtomicFile>>,
        /// The assets are not in the stream yet (written before the first variant).
        assets_pending: bool,
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
    if args.replace && args.shard.is_some() && !is_tar_output(&args.output) {
        eprintln!(
            "mjcf-forge: --replace cannot be used with --shard: the shards of a run share \
             their folder (remove or empty it before starting them)"
        );
        return ExitCode::from(USAGE);
    }
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
            if args.json {
                let json = summary.json();
                if args.output == Path::new("-") {
                    eprintln!("{json}");
                } else if super::write_stdout(format!("{json}\n").as_bytes()).is_err() {
                    // Only a closed standard output ends here: the run itself succeeded.
                    return ExitCode::SUCCESS;
                }
            } else if !args.quiet {
                eprintln!("{}", summary.text());
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
        Err(e) if e == QUIET_END => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

/// Whether `-o` names a tar stream (a `.tar` file, or `-`) rather than a folder.
fn is_tar_output(output: &Path) -> bool {
    output == Path::new("-") || output.extension().is_some_and(|e| e == "tar")
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
    /// Time spent validating with MuJoCo (compiling or patching, and the contact check),
    /// summed over threads (with `--validate`).
    compile: Option<Duration>,
    /// Models MuJoCo compiled for `--validate`.
    compiled: u64,
    /// Variants whose model for `--validate` was patched from one already compiled.
    patched: u64,
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
                "; validated by MuJoCo in {:.2} ms per variant (summed over threads; {} {} \
                 compiled, {} patched from a compiled one)",
                c.as_secs_f64() * 1e3 / self.variants.max(1) as f64,
                self.compiled,
                if self.compiled == 1 {
                    "model"
                } else {
                    "models"
                },
                self.patched
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
            "models_compiled": self.compile.map(|_| self.compiled),
            "models_patched": self.compile.map(|_| self.patched),
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
    // What MuJoCo's URDF importer warns about in the scene's models, once per run.
    if k == 0 {
        for w in scene.warnings() {
            eprintln!("{}: warning: {}", w.location, w.message);
        }
    }
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
    let outputs = open_sink(args, &store, (k, n))?;
    let check_dir: Option<PathBuf> = match (&outputs.files, &outputs.check_dir) {
        (Some(out), _) => Some(out.path().to_path_buf()),
        (None, dir) => dir.as_ref().map(|d| d.path().to_path_buf()),
    };
    let files = outputs.files.as_ref();
    let validators = match (&check_dir, args.validate) {
        (Some(dir), true) => Some(Validators::new(&scene, dir)),
        _ => None,
    };
    let progress = Progress::default();
    let show = if args.quiet {
        Show::Nothing
    } else {
        Show::Auto
    };
    let mut summary = Summary {
        variants: 0,
        bytes: 0,
        seconds: 0.0,
        compile: args.validate.then_some(Duration::ZERO),
        compiled: 0,
        patched: 0,
        failures: Vec::new(),
        output: args.output.display().to_string(),
        range: (lo, hi),
    };
    // One text buffer per ring slot, reused: a variant is written into memory an earlier
    // variant left, not into fresh pages. A tar stream's members are framed as they are
    // made, so the ordered part is one write per variant, after the assets.
    let is_tar = matches!(outputs.writer, Writer::Tar { .. });
    let mut writer = outputs.writer;
    let to_stdout = args.output == Path::new("-");
    let stream_error = |e: String| {
        if to_stdout {
            quiet_if_stdout_closed(e)
        } else {
            e
        }
    };
    progress.run(hi - lo, args.validate, show, || {
        mjcf_forge::output::for_each_ordered(
            lo..hi,
            RING,
            |i, slot: &mut Slot| {
                make_one(
                    args,
                    &scene,
                    i,
                    slot,
                    is_tar,
                    files,
                    validators.as_ref(),
                    &progress,
                )
            },
            |_, slot, made| {
                match made {
                    Ok((took, bytes)) => {
                        writer
                            .write(&store, &slot.json, &slot.framed)
                            .map_err(stream_error)?;
                        Progress::bump(&progress.written);
                        summary.variants += 1;
                        summary.bytes += bytes;
                        if let Some(c) = &mut summary.compile {
                            *c += took;
                        }
                    }
                    Err(e) => {
                        Progress::bump(&progress.failed);
                        summary.failures.push(e);
                    }
                }
                Ok::<(), String>(())
            },
        )
    })?;
    (summary.compiled, summary.patched) = validators.as_ref().map_or((0, 0), Validators::counts);
    close_sink(writer, &store, outputs.files).map_err(stream_error)?;
    summary.seconds = started.elapsed().as_secs_f64();
    Ok(summary)
}

/// Makes variant `i` into `slot` (for a tar stream, its members framed; its manifest
/// line), writes its XML file into `files` when the output is a folder, checks it with
/// `--validate`: the time its check took and its XML's size.
#[allow(clippy::too_many_arguments)]
fn make_one(
    args: &Args,
    scene: &Scene,
    i: u64,
    slot: &mut Slot,
    is_tar: bool,
    files: Option<&OutputDir>,
    validators: Option<&Validators<'_>>,
    progress: &Progress,
) -> Result<(Duration, u64), String> {
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
    // The slot's buffer as text again: empty, so nothing is validated, and its capacity
    // is kept.
    slot.framed.clear();
    let mut text = String::from_utf8(std::mem::take(&mut slot.framed)).unwrap_or_default();
    // For a tar stream the XML is written straight into its member.
    let (params, xml, header) = if is_tar {
        let ((params, range), header) = frame_text_member(&mut text, &file, |buf| {
            let start = buf.len();
            make(buf).map(|p| (p, start..buf.len()))
        })
        .map_err(|e| e.to_string())??;
        (params, range, Some(header))
    } else {
        let params = make(&mut text)?;
        let all = 0..text.len();
        (params, all, None)
    };
    Progress::bump(&progress.made);
    let took = match validators {
        Some(v) => {
            let took = v.check(i, &params)?;
            Progress::bump(&progress.validated);
            took
        }
        None => Duration::ZERO,
    };
    slot.json.clear();
    params.write_json(i, Some(&file), &mut slot.json);
    if let Some(out) = files {
        out.write(&file, text[xml.clone()].as_bytes())
            .map_err(|e| e.to_string())?;
    }
    let bytes = xml.len() as u64;
    let json_header = if is_tar {
        let ((), h) = frame_text_member(&mut text, &format!("{i:09}.json"), |m| {
            m.push_str(&slot.json);
            Ok::<(), String>(())
        })
        .map_err(|e| e.to_string())??;
        Some(h)
    } else {
        None
    };
    slot.framed = text.into_bytes();
    for h in header.iter().chain(&json_header) {
        h.write_into(&mut slot.framed).map_err(|e| e.to_string())?;
    }
    Ok((took, bytes))
}

/// `--validate`: per worker thread a model cache (each structure compiled once per thread,
/// its other variants patched: the same models, see `mjcf_forge::compiled::ModelCache`),
/// then the interpenetration check on the variant's model.
#[cfg(mjcf_mujoco)]
struct Validators<'s>(Vec<std::sync::Mutex<mjcf_forge::compiled::ModelCache<'s>>>);

/// Without MuJoCo `--validate` is refused before anything runs.
#[cfg(not(mjcf_mujoco))]
struct Validators<'s>(std::marker::PhantomData<&'s Scene>);

/// Models and scratch data each thread's cache may hold for `--validate`.
#[cfg(mjcf_mujoco)]
const VALIDATE_CACHE_BYTES: usize = 512 << 20;

impl<'s> Validators<'s> {
    #[cfg(mjcf_mujoco)]
    fn new(scene: &'s Scene, dir: &Path) -> Self {
        let threads = rayon::current_num_threads().max(1);
        Validators(
            (0..threads)
                .map(|_| {
                    let cache =
                        mjcf_forge::compiled::ModelCache::new(scene, 8, Some(VALIDATE_CACHE_BYTES))
                            .compiling_in(dir);
                    std::sync::Mutex::new(cache)
                })
                .collect(),
        )
    }

    #[cfg(not(mjcf_mujoco))]
    fn new(_: &'s Scene, _: &Path) -> Self {
        Validators(std::marker::PhantomData)
    }

    #[cfg(mjcf_mujoco)]
    fn check(&self, i: u64, params: &Params) -> Result<Duration, String> {
        let t = Instant::now();
        let k = rayon::current_thread_index().unwrap_or(0) % self.0.len();
        // A thread's own cache: the lock is never contended (poisoned only by a panic
        // elsewhere, after which the cache is still whole).
        let mut cache = self.0[k].lock().unwrap_or_else(|p| p.into_inner());
        let model = cache.model(i).map_err(|e| e.to_string())?;
        mjcf_forge::scene::check_model(i, params, model).map_err(|e| e.to_string())?;
        Ok(t.elapsed())
    }

    #[cfg(not(mjcf_mujoco))]
    fn check(&self, _: u64, _: &Params) -> Result<Duration, String> {
        Err(super::NO_MUJOCO.to_owned())
    }

    /// Models compiled, and models patched from a compiled one, over all threads.
    #[cfg(mjcf_mujoco)]
    fn counts(&self) -> (u64, u64) {
        self.0.iter().fold((0, 0), |(c, p), m| {
            let cache = m.lock().unwrap_or_else(|p| p.into_inner());
            (c + cache.compiles(), p + cache.patches())
        })
    }

    #[cfg(not(mjcf_mujoco))]
    fn counts(&self) -> (u64, u64) {
        (0, 0)
    }
}

fn open_sink(args: &Args, store: &AssetStore, (k, n): (u64, u64)) -> Result<Outputs, String> {
    let output = args.output.as_path();
    let validate = args.validate;
    let sharded = args.shard.is_some();
    if !is_tar_output(output) {
        let out = if sharded {
            refuse_strays(output, args.start..args.start.saturating_add(args.count), n)?;
            OutputDir::create(output).map_err(|e| e.to_string())?
        } else {
            super::open_output_dir(output, args.replace)?
        };
        store.write_to_dir(&out).map_err(|e| e.to_string())?;
        let name = if sharded {
            format!("manifest-{k}-of-{n}.jsonl")
        } else {
            "manifest.jsonl".to_string()
        };
        let manifest = out.create_file(&name).map_err(|e| e.to_string())?;
        return Ok(Outputs {
            files: Some(out),
            writer: Writer::Manifest(BufWriter::with_capacity(1 << 16, manifest)),
            check_dir: None,
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
    let tar = TarWriter::new(BufWriter::with_capacity(1 << 20, file), label);
    Ok(Outputs {
        files: None,
        writer: Writer::Tar {
            tar,
            assets_pending: true,
        },
        check_dir,
    })
}

/// `--shard K/N` into a folder: the folder the run's shards share may hold what they
/// write (variant files of the run's indices, the `manifest-J-of-N.jsonl` of its shards,
/// `assets/`, and the temporary files of shards writing now), and nothing else: a file of
/// another run is refused, naming it (the shards cannot replace a folder they share).
fn refuse_strays(dir: &Path, indices: std::ops::Range<u64>, n: u64) -> Result<(), String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    let belongs = |name: &str| {
        if name == "assets" || name.starts_with(".mjcf-forge-") {
            return true;
        }
        if let Some(index) = name.strip_suffix(".xml")
            && index.len() == 9
            && let Ok(i) = index.parse::<u64>()
        {
            return indices.contains(&i);
        }
        name.strip_prefix("manifest-")
            .and_then(|m| m.strip_suffix(&format!("-of-{n}.jsonl")))
            .and_then(|j| j.parse::<u64>().ok())
            .is_some_and(|j| j < n)
    };
    let mut strays: Vec<String> = entries
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|name| !belongs(name))
        .collect();
    if strays.is_empty() {
        return Ok(());
    }
    strays.sort();
    let more = match strays.len() {
        1 => String::new(),
        k => format!(" and {} more", k - 1),
    };
    Err(format!(
        "{}: the output folder holds files that are not this run's ('{}'{more}); the shards \
         of a run need a folder that is empty or holds only their own files",
        dir.display(),
        strays[0]
    ))
}

impl Writer {
    /// Writes a made variant in order: its manifest line to a folder (whose XML file a
    /// worker wrote), or its framed tar members to the stream, after the assets.
    fn write(&mut self, store: &AssetStore, json: &str, framed: &[u8]) -> Result<(), String> {
        self.write_assets(store)?;
        match self {
            Writer::Manifest(manifest) => manifest
                .write_all(json.as_bytes())
                .and_then(|()| manifest.write_all(b"\n"))
                .map_err(|e| format!("cannot write the manifest: {e}")),
            Writer::Tar { tar, .. } => tar.append_framed(framed).map_err(|e| e.to_string()),
        }
    }

    /// A tar stream's assets, once, before its first variant.
    fn write_assets(&mut self, store: &AssetStore) -> Result<(), String> {
        if let Writer::Tar {
            tar,
            assets_pending,
        } = self
            && *assets_pending
        {
            *assets_pending = false;
            store.write_to_tar(tar).map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

/// Puts the outputs in place: the manifest (or the tar file) appears whole, only now.
fn close_sink(
    mut writer: Writer,
    store: &AssetStore,
    files: Option<OutputDir>,
) -> Result<(), String> {
    // A stream of no variants still holds the assets.
    writer.write_assets(store)?;
    let commit = |w: BufWriter<AtomicFile>| -> Result<(), String> {
        let file = w
            .into_inner()
            .map_err(|e| format!("cannot write the output: {}", e.error()))?;
        file.commit().map_err(|e| e.to_string())
    };
    match writer {
        Writer::Manifest(manifest) => commit(manifest)?,
        Writer::Tar { tar, .. } => commit(tar.finish().map_err(|e| e.to_string())?)?,
    }
    match files {
        Some(out) => out.finish().map_err(|e| e.to_string()),
        None => Ok(()),
    }
}
