//! The `mjcf-forge` command line.
//!
//! Every subcommand reports problems on standard error as `file:line:col: message`, one
//! problem per line, and exits non-zero; it never writes a partial output file (outputs go
//! through [`mjcf_forge::write_atomic`], and only after everything that can fail has run).
//! Exit codes: 0 success, 1 a model failed (loading, compiling, writing), 2 bad usage.
#![cfg_attr(not(feature = "mujoco"), forbid(unsafe_code))]
#![cfg_attr(feature = "mujoco", deny(unsafe_code))]

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use mjcf_forge::{Document, MergeOptions, XmlModel, XmlModelOptions};
use rayon::prelude::*;

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
        /// Compile each output with MuJoCo first; write nothing for a model that fails
        /// (needs the `mujoco` feature).
        #[arg(long)]
        validate: bool,
    },
    /// Load a model and give every name in it a prefix (identifiers and every reference).
    Prefix {
        /// Input MJCF file.
        input: PathBuf,
        /// The prefix.
        #[arg(long)]
        prefix: String,
        /// Output file; standard output without it.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Write compact XML instead of indented XML.
        #[arg(long)]
        compact: bool,
        /// Compile the output with MuJoCo first (needs the `mujoco` feature).
        #[arg(long)]
        validate: bool,
    },
    /// Merge parts into a base model: `--part FILE[:PREFIX[:BODY]]` gives the part the name
    /// prefix PREFIX and puts it into the base's body BODY (the world body without it).
    Merge {
        /// The base model.
        base: PathBuf,
        /// A part: FILE, FILE:PREFIX or FILE:PREFIX:BODY (in order of merging).
        #[arg(long = "part", required = true)]
        parts: Vec<String>,
        /// Fuse each part key PREFIX+NAME into the base key NAME (one "home" pose for the scene).
        #[arg(long)]
        fuse_keys: bool,
        /// Output file; standard output without it.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Write compact XML instead of indented XML.
        #[arg(long)]
        compact: bool,
        /// Compile the output with MuJoCo first (needs the `mujoco` feature).
        #[arg(long)]
        validate: bool,
    },
    /// The model tier's view of a model: its lists (bodies, joints, actuators, sites,
    /// sensors, contact and visual geoms) and offsets.
    Info {
        /// Input MJCF file (exactly one top-level body).
        input: PathBuf,
        /// Naming prefix of the instance (none by default).
        #[arg(long, default_value = "")]
        prefix: String,
        /// Print one JSON object (the only output form for now).
        #[arg(long)]
        json: bool,
    },
    /// Load a model as `inline` does, compile it with MuJoCo and print its sizes
    /// (needs the `mujoco` feature).
    Compile {
        /// Input MJCF file.
        input: PathBuf,
        /// Print the sizes as one JSON object.
        #[arg(long)]
        json: bool,
    },
}

/// Exit code for a command line that cannot be carried out as asked.
const USAGE: u8 = 2;

/// What `compile` and `--validate` say in a build without MuJoCo.
const NO_MUJOCO: &str = "built without the `mujoco` feature; rebuild with --features mujoco";

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Inline {
            inputs,
            output,
            out_dir,
            compact,
            validate,
        } => {
            // Without MuJoCo, fail before loading anything rather than once per model.
            if let Some(code) = refuse_validate_without_mujoco(validate) {
                return code;
            }
            let options = InlineOptions { compact, validate };
            match out_dir {
                Some(dir) => inline_to_dir(&inputs, &dir, options),
                None => inline_one_input(&inputs, output.as_deref(), options),
            }
        }
        Command::Prefix {
            input,
            prefix,
            output,
            compact,
            validate,
        } => {
            if let Some(code) = refuse_validate_without_mujoco(validate) {
                return code;
            }
            let result = Document::load(&input)
                .map_err(|e| e.to_string())
                .and_then(|mut doc| {
                    doc.apply_prefix(&prefix).map_err(|e| e.to_string())?;
                    emit(&doc, output.as_deref(), InlineOptions { compact, validate })
                });
            finish(&[result])
        }
        Command::Merge {
            base,
            parts,
            fuse_keys,
            output,
            compact,
            validate,
        } => {
            if let Some(code) = refuse_validate_without_mujoco(validate) {
                return code;
            }
            let specs: Vec<PartSpec> = match parts.iter().map(|p| PartSpec::parse(p)).collect() {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("mjcf-forge: {e}");
                    return ExitCode::from(USAGE);
                }
            };
            finish(&[merge(
                &base,
                &specs,
                fuse_keys,
                output.as_deref(),
                InlineOptions { compact, validate },
            )])
        }
        Command::Info {
            input,
            prefix,
            json,
        } => {
            if !json {
                eprintln!("mjcf-forge: info prints JSON only: add --json");
                return ExitCode::from(USAGE);
            }
            let result = Document::load(&input)
                .map_err(|e| e.to_string())
                .and_then(|doc| {
                    let options = XmlModelOptions {
                        contact_geom_rgba: None,
                        ..XmlModelOptions::default()
                    };
                    let model =
                        XmlModel::with_prefix(doc, &prefix, options).map_err(|e| e.to_string())?;
                    println!("{}", model.info_json());
                    Ok(())
                });
            finish(&[result])
        }
        Command::Compile { input, json } => compile(&input, json),
    }
}

/// One `--part FILE[:PREFIX[:BODY]]` of `merge`.
struct PartSpec {
    file: PathBuf,
    prefix: String,
    body: Option<String>,
}

impl PartSpec {
    fn parse(spec: &str) -> Result<PartSpec, String> {
        let mut it = spec.splitn(3, ':');
        let file = it
            .next()
            .filter(|f| !f.is_empty())
            .ok_or_else(|| format!("--part '{spec}': no file"))?;
        let prefix = it.next().unwrap_or_default().to_string();
        let body = it.next().filter(|b| !b.is_empty()).map(str::to_string);
        Ok(PartSpec {
            file: PathBuf::from(file),
            prefix,
            body,
        })
    }
}

/// `merge`: loads the base and every part, prefixes and merges each in order, then writes.
fn merge(
    base: &Path,
    parts: &[PartSpec],
    fuse_keys: bool,
    output: Option<&Path>,
    options: InlineOptions,
) -> Result<(), String> {
    let mut scene = Document::load(base).map_err(|e| e.to_string())?;
    // Parts load in parallel; they merge in the order given.
    let loaded: Vec<Result<Document, String>> = parts
        .par_iter()
        .map(|p| {
            let mut doc = Document::load(&p.file).map_err(|e| e.to_string())?;
            doc.apply_prefix(&p.prefix).map_err(|e| e.to_string())?;
            Ok(doc)
        })
        .collect();
    for (spec, doc) in parts.iter().zip(loaded) {
        let doc = doc?;
        let merge_options = MergeOptions {
            fuse_keys,
            part_prefix: spec.prefix.clone(),
        };
        let report = scene
            .merge(&doc, spec.body.as_deref(), &merge_options)
            .map_err(|e| e.to_string())?;
        for w in report.warnings {
            eprintln!("warning: {w}");
        }
    }
    emit(&scene, output, options)
}

/// Writes a finished document (validated first when asked) to a file or standard output.
fn emit(doc: &Document, output: Option<&Path>, options: InlineOptions) -> Result<(), String> {
    if options.validate {
        validate(doc)?;
    }
    let text = if options.compact {
        doc.to_xml_string()
    } else {
        doc.to_pretty_string()
    };
    match output {
        Some(path) => mjcf_forge::write_atomic(path, text.as_bytes()).map_err(|e| e.to_string()),
        None => {
            let mut out = std::io::stdout().lock();
            out.write_all(text.as_bytes())
                .and_then(|()| out.flush())
                .map_err(|e| format!("cannot write to standard output: {e}"))
        }
    }
}

// ------------------------------------------------------------------------------ inline

#[derive(Clone, Copy)]
struct InlineOptions {
    compact: bool,
    validate: bool,
}

/// Where one inlined model goes.
#[derive(Clone, Copy)]
enum Sink<'a> {
    Stdout,
    File(&'a Path),
}

fn inline_one_input(inputs: &[PathBuf], output: Option<&Path>, options: InlineOptions) -> ExitCode {
    if inputs.len() > 1 {
        eprintln!("mjcf-forge: several inputs need --out-dir DIR");
        return ExitCode::from(USAGE);
    }
    let sink = output.map_or(Sink::Stdout, Sink::File);
    finish(&[inline_model(&inputs[0], sink, options)])
}

/// `inline --out-dir`: plans every output before writing any, so that a clash between two
/// inputs is reported without touching the folder; then runs the models in parallel and
/// reports their problems in input order (never in thread order).
fn inline_to_dir(inputs: &[PathBuf], dir: &Path, options: InlineOptions) -> ExitCode {
    let jobs = match plan_outputs(inputs, dir) {
        Ok(jobs) => jobs,
        Err(problems) => {
            for p in problems {
                eprintln!("{p}");
            }
            return ExitCode::from(USAGE);
        }
    };
    if let Err(e) = std::fs::create_dir_all(dir) {
        eprintln!("{}: cannot create folder: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    let results: Vec<Result<(), String>> = jobs
        .par_iter()
        .map(|job| inline_model(job.input, Sink::File(&job.output), options))
        .collect();
    finish(&results)
}

/// One input of `inline --out-dir` and the file it becomes.
struct Job<'a> {
    input: &'a Path,
    output: PathBuf,
}

/// The output of each distinct input, in input order. An input named twice (by any path
/// spelling) is done once; two different inputs that would write the same output are an
/// error, as is an input without a file name.
fn plan_outputs<'a>(inputs: &'a [PathBuf], dir: &Path) -> Result<Vec<Job<'a>>, Vec<String>> {
    let mut jobs: Vec<Job<'a>> = Vec::new();
    let mut identities: Vec<PathBuf> = Vec::new();
    let mut problems = Vec::new();
    for input in inputs {
        let Some(name) = input.file_name() else {
            problems.push(format!("{}: not a file name", input.display()));
            continue;
        };
        // A missing file keeps its spelling as identity; loading it reports the problem.
        let identity = std::fs::canonicalize(input).unwrap_or_else(|_| input.clone());
        let output = dir.join(name);
        match jobs.iter().position(|j| j.output == output) {
            Some(i) if identities[i] == identity => {}
            Some(i) => problems.push(format!(
                "{}: output '{}' is already taken by '{}'",
                input.display(),
                output.display(),
                jobs[i].input.display()
            )),
            None => {
                jobs.push(Job { input, output });
                identities.push(identity);
            }
        }
    }
    if problems.is_empty() {
        Ok(jobs)
    } else {
        Err(problems)
    }
}

/// Loads, optionally validates, and writes one model. The output is written only when
/// everything before it succeeded, and atomically, so a failure leaves the old file intact.
fn inline_model(input: &Path, sink: Sink<'_>, options: InlineOptions) -> Result<(), String> {
    let doc = Document::load(input).map_err(|e| e.to_string())?;
    if options.validate {
        validate(&doc)?;
    }
    let text = if options.compact {
        doc.to_xml_string()
    } else {
        doc.to_pretty_string()
    };
    match sink {
        Sink::File(path) => {
            mjcf_forge::write_atomic(path, text.as_bytes()).map_err(|e| e.to_string())
        }
        // `print!` would panic on a closed pipe; a failed write is an ordinary error here.
        Sink::Stdout => {
            let mut out = std::io::stdout().lock();
            out.write_all(text.as_bytes())
                .and_then(|()| out.flush())
                .map_err(|e| format!("cannot write to standard output: {e}"))
        }
    }
}

/// Prints the problems of all runs; success only when there were none.
fn finish(results: &[Result<(), String>]) -> ExitCode {
    let mut failed = false;
    for problem in results.iter().filter_map(|r| r.as_ref().err()) {
        eprintln!("{problem}");
        failed = true;
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

// ------------------------------------------------------------------- compile, validate

/// With `--validate` in a build without MuJoCo: the usage error, said once before any model
/// is loaded (rather than once per model).
fn refuse_validate_without_mujoco(validate: bool) -> Option<ExitCode> {
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
    if cfg!(feature = "mujoco") {
        Ok(())
    } else {
        Err(NO_MUJOCO.to_owned())
    }
}

/// Compiles `doc` with MuJoCo and forgets the model: the check behind `--validate`, for
/// every subcommand that writes a model. The error is ready to print: MuJoCo's message,
/// prefixed with the position of the element it names (see [`compile_document`]).
fn validate(doc: &Document) -> Result<(), String> {
    #[cfg(feature = "mujoco")]
    {
        compile_document(doc).map(drop)
    }
    #[cfg(not(feature = "mujoco"))]
    {
        let _ = doc;
        Err(NO_MUJOCO.to_owned())
    }
}

/// `compile IN [--json]`.
#[cfg(feature = "mujoco")]
fn compile(input: &Path, json: bool) -> ExitCode {
    let doc = match Document::load(input) {
        Ok(doc) => doc,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let model = match compile_document(&doc) {
        Ok(model) => model,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    if let Some(w) = model.warnings() {
        eprintln!("{}: MuJoCo warning: {w}", input.display());
    }
    let sizes = model.sizes();
    let text = if json {
        format!("{}\n", sizes.to_json())
    } else {
        let width = sizes
            .entries()
            .iter()
            .map(|(k, _)| k.len())
            .max()
            .unwrap_or(0);
        sizes
            .entries()
            .iter()
            .map(|(key, value)| format!("{key:<width$} {value}\n"))
            .collect()
    };
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("mjcf-forge: cannot write to standard output: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `compile` in a build without MuJoCo: says how to get one.
#[cfg(not(feature = "mujoco"))]
fn compile(_input: &Path, _json: bool) -> ExitCode {
    eprintln!("mjcf-forge: compile: {NO_MUJOCO}");
    ExitCode::from(USAGE)
}

/// Compiles the document's pretty XML with MuJoCo (relative references resolve from the
/// model's folder, though loading made them absolute already).
///
/// MuJoCo names the offending element by its line in the XML it was given; that XML is
/// ours, so the line is mapped back to the element and on to its place in the user's
/// sources: `robot.xml:12:7: Error: mesh 'nope' not found in geom 0` followed by the rest
/// of MuJoCo's message (whose own `line N` counts lines of the generated XML) and by the
/// include chain, as for load errors.
#[cfg(feature = "mujoco")]
fn compile_document(doc: &Document) -> Result<mjcf_forge::mujoco::CompiledModel, String> {
    let xml = doc.to_pretty_string();
    mjcf_forge::mujoco::compile_str(&xml, doc.model_dir()).map_err(|err| {
        let element = err
            .element_line
            .and_then(|line| element_at_line(doc, &xml, line, &err.message));
        match element.and_then(|node| source_location(doc, node)) {
            Some(location) => mjcf_forge::Error {
                location: Some(location),
                kind: mjcf_forge::ErrorKind::Invalid(err.message),
            }
            .to_string(),
            None => format!(
                "{}: {}",
                doc.location(doc.root()).file.display(),
                err.message
            ),
        }
    })
}

// ------------------------------------------------ from a line of our XML to an element

/// Where each element's start tag begins in `xml` as written by [`Document`]'s writers:
/// `(1-based line, byte offset of its '<')`, in document order, i.e. the order of
/// `doc.descendants(doc.root())`.
///
/// Exact for our writers' output, mixed content included (where several elements share a
/// line), because the writers escape `<` in attribute values and text; the only other
/// markup they emit is closing tags and CDATA sections, which are skipped whole. (Counting
/// lines that start with `<` would miscount inside mixed content and CDATA.)
#[cfg(any(feature = "mujoco", test))]
fn element_starts(xml: &str) -> Vec<(u32, usize)> {
    let bytes = xml.as_bytes();
    let mut starts = Vec::new();
    let mut line = 1u32;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'\n' => line += 1,
            b'<' => {
                let rest = &xml[i..];
                let skip_to = |end: &str| rest.find(end).map_or(rest.len(), |at| at + end.len());
                let skipped = if rest.starts_with("<![CDATA[") {
                    skip_to("]]>")
                } else if rest.starts_with("<!--") {
                    skip_to("-->")
                } else if rest.starts_with("<?") {
                    skip_to("?>")
                } else if rest.starts_with("</") || rest.starts_with("<!") {
                    1
                } else {
                    starts.push((line, i));
                    1
                };
                line += rest[..skipped].bytes().filter(|&b| b == b'\n').count() as u32;
                i += skipped;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    starts
}

/// The element that MuJoCo's message points at: one whose start tag is on `line` of `xml`
/// (the document's own rendering). When several share the line (mixed content), the one
/// whose tag or name matches MuJoCo's `Element 'geom'` / `Element name 'g'` wins, else
/// the first; when none starts there, the last one that starts before it.
#[cfg(any(feature = "mujoco", test))]
fn element_at_line(
    doc: &Document,
    xml: &str,
    line: u32,
    message: &str,
) -> Option<mjcf_forge::Node> {
    let starts = element_starts(xml);
    let elements: Vec<mjcf_forge::Node> = doc.descendants(doc.root()).collect();
    if starts.len() != elements.len() {
        // Not this document's rendering: better no position than a wrong one.
        return None;
    }
    let on_line: Vec<mjcf_forge::Node> = starts
        .iter()
        .zip(&elements)
        .filter(|((l, _), _)| *l == line)
        .map(|(_, &node)| node)
        .collect();
    let tag = quoted_after(message, "Element '");
    let name = quoted_after(message, "Element name '");
    let matching = on_line.iter().copied().find(|&node| {
        tag.is_some_and(|t| doc.tag(node) == t)
            || name.is_some_and(|n| doc.attr(node, "name") == Some(n))
    });
    matching.or_else(|| on_line.first().copied()).or_else(|| {
        starts
            .iter()
            .zip(&elements)
            .take_while(|((l, _), _)| *l < line)
            .last()
            .map(|(_, &node)| node)
    })
}

/// The text between `marker` and the next `'`.
#[cfg(any(feature = "mujoco", test))]
fn quoted_after<'a>(text: &'a str, marker: &str) -> Option<&'a str> {
    let rest = &text[text.find(marker)? + marker.len()..];
    rest.find('\'').map(|end| &rest[..end])
}

/// The source position of `node`, or of its nearest ancestor that has one (elements made
/// while loading, such as a section created on demand, have none: line 0).
#[cfg(any(feature = "mujoco", test))]
fn source_location(doc: &Document, node: mjcf_forge::Node) -> Option<mjcf_forge::Location> {
    std::iter::successors(Some(node), |&n| doc.parent(n))
        .map(|n| doc.location(n))
        .find(|location| location.line > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc(xml: &str) -> Document {
        Document::from_str(xml, ".").unwrap()
    }

    #[test]
    fn element_starts_follow_document_order_through_mixed_content_and_cdata() {
        let d = doc("<mujoco><custom><text name='t' data='a&lt;b'/></custom>\
             <worldbody><body><geom size='1'/></body></worldbody></mujoco>");
        let xml = d.to_pretty_string();
        let lines: Vec<u32> = element_starts(&xml).iter().map(|s| s.0).collect();
        assert_eq!(lines, [1, 2, 3, 5, 6, 7], "{xml}");

        // Several elements on one line, and markup-like text inside CDATA.
        let mixed = "<a>x<b/>y<c/><![CDATA[\n<d>\n]]>\n<e/></a>";
        let starts = element_starts(mixed);
        let lines: Vec<u32> = starts.iter().map(|s| s.0).collect();
        assert_eq!(lines, [1, 1, 1, 4]);
        assert!(mixed[starts[3].1..].starts_with("<e/>"));
    }

    #[test]
    fn mujoco_line_maps_to_the_named_element() {
        let src = "<mujoco>\n<worldbody>\n\n\n<body name='b'>\n<geom name='g' size='1'/>\n</body>\n</worldbody>\n</mujoco>";
        let d = doc(src);
        let xml = d.to_pretty_string();
        // Pretty XML: mujoco 1, worldbody 2, body 3, geom 4.
        let geom =
            element_at_line(&d, &xml, 4, "Error: x\nElement name 'g', id 0, line 4").unwrap();
        assert_eq!(d.tag(geom), "geom");
        let loc = source_location(&d, geom).unwrap();
        assert_eq!((loc.line, loc.col), (6, 1));
        // A line past every start falls back to the last element before it.
        let last = element_at_line(&d, &xml, 99, "").unwrap();
        assert_eq!(d.tag(last), "geom");
    }

    #[test]
    fn quoted_names_in_mujoco_messages() {
        let m = "Error: bad\nElement name 'arm', id 3, line 9";
        assert_eq!(quoted_after(m, "Element name '"), Some("arm"));
        assert_eq!(quoted_after(m, "Element '"), None);
        assert_eq!(
            quoted_after("Element 'geom', line 2", "Element '"),
            Some("geom")
        );
    }

    #[test]
    fn plan_outputs_allows_repeats_and_refuses_clashes() {
        let dir = Path::new("out");
        let same = [PathBuf::from("a/x.xml"), PathBuf::from("a/x.xml")];
        assert_eq!(plan_outputs(&same, dir).map(|j| j.len()), Ok(1));
        let clash = [PathBuf::from("a/x.xml"), PathBuf::from("b/x.xml")];
        let problems = plan_outputs(&clash, dir).err().unwrap();
        assert_eq!(problems.len(), 1);
        assert!(
            problems[0].starts_with("b/x.xml: output "),
            "{}",
            problems[0]
        );
    }

    /// The start-tag scan agrees with `descendants` on every wheel model: same count, and
    /// each start tag is that element's tag.
    #[test]
    fn element_starts_match_descendants_on_the_corpus() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let list = std::fs::read_to_string(root.join(".cache/corpus/models.txt"))
            .expect(".cache/corpus/models.txt: run scripts/setup.sh first");
        let mut checked = 0;
        for path in list.lines().filter(|l| !l.trim().is_empty()) {
            let d = Document::load(root.join(path)).unwrap_or_else(|e| panic!("{path}: {e}"));
            for xml in [d.to_pretty_string(), d.to_xml_string()] {
                let starts = element_starts(&xml);
                let elements: Vec<_> = d.descendants(d.root()).collect();
                assert_eq!(starts.len(), elements.len(), "{path}");
                for ((_, at), node) in starts.iter().zip(elements) {
                    let tag = d.tag(node);
                    let after = xml.as_bytes().get(at + 1 + tag.len()).copied();
                    assert!(
                        xml[at + 1..].starts_with(tag) && matches!(after, Some(b' ' | b'/' | b'>')),
                        "{path}: element <{tag}> is not at byte {at}"
                    );
                }
            }
            checked += 1;
        }
        assert!(checked >= 100, "only {checked} corpus models");
    }
}
