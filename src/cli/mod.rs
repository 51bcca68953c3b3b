//! The subcommands, one file each (`Args` for clap and `run`), and what they share: how a
//! finished document is written, how problems are reported, and `--validate`.
//!
//! A face, on top of every tier: it uses the library's public API only (`mjcf_forge::...`).
//!
//! Nothing here is library API: `mod cli` is private to the binary, and its problems are the
//! lines it prints on standard error, so the helpers below pass them as `String` and are
//! `pub(crate)`. The library's own errors reach them typed and become text only here.

pub mod compile;
pub mod export;
pub mod generate;
pub mod info;
pub mod inline;
pub mod merge;
pub mod prefix;
pub mod preview;
pub mod progress;
pub mod store;

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use mjcf_forge::Document;

/// Exit code for a command line that cannot be carried out as asked.
pub const USAGE: u8 = 2;

/// What `compile` and `--validate` say in a build without MuJoCo.
pub const NO_MUJOCO: &str = "built without the `mujoco` feature; rebuild with --features mujoco";

/// How a command that writes a model writes it: the `--compact` and `--validate` flags
/// every such command takes.
#[derive(Clone, Copy, clap::Args)]
pub struct WriteOptions {
    /// Write compact XML instead of indented XML.
    #[arg(long)]
    pub compact: bool,
    /// Compile with MuJoCo first; write nothing for a model that fails (needs the
    /// `mujoco` feature).
    #[arg(long)]
    pub validate: bool,
}

/// The text of a finished document, validated first when asked: what every command that
/// writes a model writes, once everything that can fail has run.
pub(crate) fn render(doc: &Document, options: WriteOptions) -> Result<String, String> {
    if options.validate {
        validate(doc)?;
    }
    Ok(if options.compact {
        doc.to_xml_string()
    } else {
        doc.to_pretty_string()
    })
}

/// Writes a finished document (validated first when asked) to a file or standard output.
/// The output is written only when everything before it succeeded, and atomically, so a
/// failure leaves the old file intact (see [`mjcf_forge::write_atomic`] for symlinks and
/// special files).
pub(crate) fn emit(
    doc: &Document,
    output: Option<&Path>,
    options: WriteOptions,
) -> Result<(), String> {
    let text = render(doc, options)?;
    match output {
        Some(path) => mjcf_forge::write_atomic(path, text.as_bytes()).map_err(|e| e.to_string()),
        None => write_stdout(text.as_bytes()),
    }
}

/// `print!` would panic on a closed pipe; a failed write is an ordinary error here, and
/// a reader that went away ([`QUIET_END`]) is no error at all.
pub(crate) fn write_stdout(bytes: &[u8]) -> Result<(), String> {
    let mut out = std::io::stdout().lock();
    out.write_all(bytes)
        .and_then(|()| out.flush())
        .map_err(|e| quiet_if_stdout_closed(format!("cannot write to standard output: {e}")))
}

/// What a run that stopped because standard output's reader went away (`| head`) reports
/// instead of an error: nothing. It ends with exit 0, as `head`'s writer does in a shell
/// pipeline where SIGPIPE ends it; unlike SIGPIPE, the run still cleans up (temporary
/// files are removed, no output file is left half written). Never printed.
pub const QUIET_END: &str = "\0standard output closed";

/// `problem` when standard output is still open, else [`QUIET_END`]: for an error met
/// while writing to standard output, whose words (a `Broken pipe` inside a library
/// error) are not worth telling a reader that has gone.
pub fn quiet_if_stdout_closed(problem: String) -> String {
    if stdout_closed() {
        QUIET_END.to_owned()
    } else {
        problem
    }
}

/// Whether standard output is a pipe or socket whose reading end is closed: polled, so
/// the answer is the kernel's (a write there fails with EPIPE), not read off an error's
/// text.
pub fn stdout_closed() -> bool {
    use rustix::event::{PollFd, PollFlags, poll};
    let stdout = std::io::stdout();
    let mut fds = [PollFd::new(&stdout, PollFlags::OUT)];
    let zero = rustix::event::Timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    poll(&mut fds, Some(&zero)).is_ok()
        && fds[0].revents().intersects(PollFlags::ERR | PollFlags::HUP)
}

/// Prints the problems of all runs; success only when there were none. A run that ended
/// because standard output was closed ([`QUIET_END`]) prints nothing and is a success
/// unless another run failed.
pub(crate) fn finish(results: &[Result<(), String>]) -> ExitCode {
    let mut failed = false;
    for problem in results.iter().filter_map(|r| r.as_ref().err()) {
        if problem == QUIET_END {
            continue;
        }
        eprintln!("{problem}");
        failed = true;
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// `Err` when the output folder `dir` already holds something: outputs are never mixed
/// with a previous run's, so a folder that is not empty is replaced whole with
/// `--replace` or refused (checked before any work, so nothing runs in vain).
pub(crate) fn refuse_non_empty(dir: &Path, replace: bool) -> Result<(), String> {
    if replace {
        return Ok(());
    }
    let first = match std::fs::read_dir(dir) {
        Ok(mut entries) => entries.next(),
        Err(_) => None,
    };
    match first {
        Some(entry) => Err(format!(
            "{}: the output folder is not empty (it holds '{}'); add --replace to replace it \
             whole, or choose another folder",
            dir.display(),
            entry.map_or_else(
                |e| e.to_string(),
                |e| e.file_name().to_string_lossy().into_owned()
            )
        )),
        None => Ok(()),
    }
}

/// The output folder a run writes: staged beside `dir` and put in place whole at
/// [`mjcf_forge::OutputDir::finish`] (replacing a folder there with `replace`).
pub(crate) fn open_output_dir(dir: &Path, replace: bool) -> Result<mjcf_forge::OutputDir, String> {
    refuse_non_empty(dir, replace)?;
    if replace {
        mjcf_forge::OutputDir::replace(dir)
    } else {
        mjcf_forge::OutputDir::create_new(dir)
    }
    .map_err(|e| e.to_string())
}

/// With `--validate` in a build without MuJoCo: the usage error, said once before any model
/// is loaded (rather than once per model).
pub fn refuse_validate_without_mujoco(validate: bool) -> Option<ExitCode> {
    if !validate {
        return None;
    }
    let Err(e) = require_mujoco() else {
        return None;
    };
    eprintln!("mjcf-forge: --validate: {e}");
    Some(ExitCode::from(USAGE))
}

/// `Ok` when this binary can compile with MuJoCo, else the reason it cannot.
fn require_mujoco() -> Result<(), String> {
    if cfg!(mjcf_mujoco) {
        Ok(())
    } else {
        Err(NO_MUJOCO.to_owned())
    }
}

/// Compiles `doc` with MuJoCo and forgets the model: the check behind `--validate`, for
/// every subcommand that writes a model. The error is ready to print: MuJoCo's message,
/// prefixed with the position of the element it names (see
/// [`compile::compile_document`]).
pub(crate) fn validate(doc: &Document) -> Result<(), String> {
    #[cfg(mjcf_mujoco)]
    {
        compile::compile_document(doc).map(drop)
    }
    #[cfg(not(mjcf_mujoco))]
    {
        let _ = doc;
        Err(NO_MUJOCO.to_owned())
    }
}

/// Bounds on the input, for every subcommand that loads models (see
/// `mjcf_forge::Limits`, whose defaults are far above any real model's needs).
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct LimitArgs {
    /// Deepest element nesting accepted, includes expanded [default: 1000].
    #[arg(long, value_name = "LEVELS")]
    max_depth: Option<u32>,
    /// Longest chain of files including each other [default: 100].
    #[arg(long, value_name = "FILES")]
    max_include_depth: Option<u32>,
    /// Largest file read (models, includes, meshes, skins) [default: 1073741824].
    #[arg(long, value_name = "BYTES")]
    max_file_size: Option<u64>,
    /// Most attributes on one element [default: 1000].
    #[arg(long, value_name = "N")]
    max_attributes: Option<u32>,
    /// Longest element or attribute name, in bytes [default: 1000].
    #[arg(long, value_name = "BYTES")]
    max_name_len: Option<u32>,
}

/// How a URDF input is read (see `mjcf_forge::UrdfOptions`), for every subcommand that
/// loads models; an MJCF input ignores them.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct UrdfArgs {
    /// URDF: keep each <visual> as a geom of group 1 (no mass, no contacts), its material
    /// as a MuJoCo material (MuJoCo's importer drops them).
    #[arg(long)]
    urdf_visuals: bool,
    /// URDF: keep every link a body (MuJoCo's importer fuses static links into their
    /// parents).
    #[arg(long)]
    urdf_keep_static: bool,
    /// URDF: keep this link a body even when static links are fused (repeatable).
    #[arg(long, value_name = "LINK")]
    urdf_keep_link: Vec<String>,
    /// URDF: the folder of a package named by `package://NAME/...` (repeatable); else
    /// ROS_PACKAGE_PATH, AMENT_PREFIX_PATH and the folders above the file are searched.
    #[arg(long, value_name = "NAME=DIR")]
    urdf_package: Vec<String>,
    /// URDF: an actuator for each hinge and slide joint: `position:KP[:KV]`,
    /// `velocity:KV` or `motor`.
    #[arg(long, value_name = "KIND")]
    urdf_actuators: Option<String>,
    /// URDF: read as this MuJoCo version's importer [default: the linked MuJoCo's, else
    /// 4.0.0].
    #[arg(long, value_name = "VERSION")]
    urdf_mujoco: Option<String>,
}

impl UrdfArgs {
    /// The options these flags ask for, or what is wrong with them.
    pub(crate) fn options(&self) -> Result<mjcf_forge::UrdfOptions, String> {
        let mut o = mjcf_forge::UrdfOptions {
            visuals: self.urdf_visuals,
            fuse_static: !self.urdf_keep_static,
            keep_links: self.urdf_keep_link.clone(),
            ..Default::default()
        };
        for p in &self.urdf_package {
            let (name, dir) = p
                .split_once('=')
                .ok_or_else(|| format!("--urdf-package {p}: expected NAME=DIR"))?;
            o.packages.push((name.to_string(), PathBuf::from(dir)));
        }
        if let Some(v) = &self.urdf_mujoco {
            o.importer = mjcf_forge::UrdfImporter::of_version(v);
        }
        if let Some(kind) = &self.urdf_actuators {
            let bad = || {
                format!("--urdf-actuators {kind}: expected position:KP[:KV], velocity:KV or motor")
            };
            let mut parts = kind.split(':');
            let gain = |parts: &mut std::str::Split<'_, char>| -> Result<Option<f64>, String> {
                parts
                    .next()
                    .map(|g| g.parse::<f64>().map_err(|_| bad()))
                    .transpose()
            };
            o.actuators = Some(match parts.next() {
                Some("position") => {
                    let kp = gain(&mut parts)?.ok_or_else(bad)?;
                    let kv = gain(&mut parts)?.unwrap_or(0.0);
                    mjcf_forge::UrdfActuators::Position { kp, kv }
                }
                Some("velocity") => mjcf_forge::UrdfActuators::Velocity {
                    kv: gain(&mut parts)?.ok_or_else(bad)?,
                },
                Some("motor") => mjcf_forge::UrdfActuators::Motor,
                _ => return Err(bad()),
            });
            if parts.next().is_some() {
                return Err(bad());
            }
        }
        Ok(o)
    }
}

/// What a subcommand loads models with: its limits, and how URDF is read.
pub struct Loader {
    limits: mjcf_forge::Limits,
    urdf: Result<mjcf_forge::UrdfOptions, String>,
}

impl Loader {
    /// The loader of a subcommand's flags (a bad URDF flag is reported on first load).
    pub fn new(limits: &LimitArgs, urdf: &UrdfArgs) -> Loader {
        Loader {
            limits: limits.limits(),
            urdf: urdf.options(),
        }
    }

    /// A model read as `Document::load` reads it, within the limits; its problems (or a
    /// bad URDF flag) as text.
    pub(crate) fn load(&self, path: &Path) -> Result<mjcf_forge::Document, String> {
        let urdf = self.urdf.as_ref().map_err(Clone::clone)?;
        let doc = mjcf_forge::Document::load_urdf_with(path, &self.limits, urdf)
            .map_err(|e| e.to_string())?;
        // What MuJoCo's URDF importer warns about, on standard error as it prints them.
        for w in doc.warnings() {
            eprintln!("{}: warning: {}", w.location, w.message);
        }
        Ok(doc)
    }
}

impl LimitArgs {
    /// The limits: the defaults, with what was given on the command line.
    pub fn limits(&self) -> mjcf_forge::Limits {
        let d = mjcf_forge::Limits::default();
        mjcf_forge::Limits {
            max_depth: self.max_depth.unwrap_or(d.max_depth),
            max_include_depth: self.max_include_depth.unwrap_or(d.max_include_depth),
            max_file_size: self.max_file_size.unwrap_or(d.max_file_size),
            max_attributes: self.max_attributes.unwrap_or(d.max_attributes),
            max_name_len: self.max_name_len.unwrap_or(d.max_name_len),
        }
    }
}
