//! URDF in Python: `Document.from_urdf`'s keyword options as the library's [`UrdfOptions`],
//! the importer chosen from the user's `mujoco`, and which files and texts are URDF at all.
//!
//! The library reads a URDF file as the MuJoCo it was built against (4.0.0 without the
//! `mujoco` feature, which this module is built without), but the model a user compiles
//! is their own `mujoco`'s: 3.x and 4.x read a `continuous` joint's `<limit>` differently.
//! So every load here that meets URDF asks `mjcf_forge._upcalls.mujoco_version` which
//! importer to read as. Only URDF asks: the root element is looked at first (past the XML
//! prolog, a few bytes of the file), so that loading MJCF never imports `mujoco`.

use std::io::Read;
use std::path::{Path, PathBuf};

use mjcf_forge::{UrdfActuators, UrdfImporter, UrdfOptions};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::errors::Failure;

/// How far into a file the root element is looked for: a prolog (declaration, comments,
/// doctype) longer than this is read by the library with the defaults.
const PROLOG_LIMIT: usize = 1 << 20;

/// The root element of XML text, as far as the text given shows it.
#[derive(Debug, PartialEq)]
enum Root<'a> {
    /// Its name, and the offset of its `<`.
    Found(&'a [u8], usize),
    /// The prolog goes on past the text given.
    Unfinished,
    /// Not XML the scan understands (the library says what is wrong with it).
    Unknown,
}

/// The root element of `text`: past a UTF-8 byte order mark, white space, the XML
/// declaration, processing instructions, comments and a doctype (with its internal
/// subset).
fn root_element(text: &[u8]) -> Root<'_> {
    let find = |from: usize, what: &[u8]| {
        text.get(from..)
            .and_then(|rest| rest.windows(what.len()).position(|w| w == what))
            .map(|i| from + i)
    };
    let mut i = if text.starts_with(b"\xEF\xBB\xBF") {
        3
    } else {
        0
    };
    loop {
        while text.get(i).is_some_and(u8::is_ascii_whitespace) {
            i += 1;
        }
        let rest = &text[i.min(text.len())..];
        if rest.len() < 4 {
            return if b"<!--".starts_with(rest)
                || b"<?".starts_with(rest)
                || rest.first() == Some(&b'<')
            {
                Root::Unfinished
            } else {
                Root::Unknown
            };
        }
        if rest[0] != b'<' {
            return Root::Unknown;
        }
        if rest.starts_with(b"<?") {
            match find(i + 2, b"?>") {
                Some(end) => i = end + 2,
                None => return Root::Unfinished,
            }
        } else if rest.starts_with(b"<!--") {
            match find(i + 4, b"-->") {
                Some(end) => i = end + 3,
                None => return Root::Unfinished,
            }
        } else if rest.starts_with(b"<!") {
            // A doctype: its internal subset in brackets may hold '>' of its own.
            let mut depth = 0usize;
            let end = rest.iter().enumerate().skip(2).find_map(|(k, &b)| {
                match b {
                    b'[' => depth += 1,
                    b']' => depth = depth.saturating_sub(1),
                    b'>' if depth == 0 => return Some(k),
                    _ => {}
                }
                None
            });
            match end {
                Some(k) => i += k + 1,
                None => return Root::Unfinished,
            }
        } else {
            let name = &rest[1..];
            return match name
                .iter()
                .position(|&b| b.is_ascii_whitespace() || b == b'/' || b == b'>')
            {
                Some(n) => Root::Found(&name[..n], i),
                None => Root::Unfinished,
            };
        }
    }
}

/// The 1-based line and byte column of `offset` in `text`, as the library counts them.
fn line_col(text: &[u8], offset: usize) -> (usize, usize) {
    let before = &text[..offset];
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    let start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |k| k + 1);
    (line, offset - start + 1)
}

/// The root element of a file: its name and line:col. `None` when the file cannot be read,
/// is no regular file (opening a FIFO would wait for a writer) or the scan cannot tell;
/// the load that follows says what is wrong.
fn file_root(path: &Path) -> Option<(String, usize, usize)> {
    if !std::fs::metadata(path).ok()?.is_file() {
        return None;
    }
    let mut file = std::fs::File::open(path).ok()?;
    let mut text = Vec::new();
    let mut chunk = [0u8; 8192];
    loop {
        let n = file.read(&mut chunk).ok()?;
        text.extend_from_slice(&chunk[..n]);
        match root_element(&text) {
            Root::Found(name, at) => {
                let (line, col) = line_col(&text, at);
                return Some((String::from_utf8_lossy(name).into_owned(), line, col));
            }
            Root::Unfinished if n > 0 && text.len() < PROLOG_LIMIT => continue,
            _ => return None,
        }
    }
}

/// Whether the library reads `path` as URDF: a `.xacro` file (expanded first), or a file
/// whose root element is `<robot>`.
pub(crate) fn is_urdf_file(path: &Path) -> bool {
    is_xacro(path) || file_root(path).is_some_and(|(name, _, _)| name == "robot")
}

/// Whether the library reads `xml` as URDF: its root element is `<robot>`.
pub(crate) fn is_urdf_text(xml: &str) -> bool {
    matches!(root_element(xml.as_bytes()), Root::Found(b"robot", _))
}

fn is_xacro(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "xacro")
}

/// The refusal of `from_urdf` for a file that is MJCF (or anything but URDF).
pub(crate) fn check_urdf_file(path: &Path) -> Result<(), Failure> {
    if is_xacro(path) {
        return Ok(());
    }
    match file_root(path) {
        Some((name, line, col)) if name != "robot" => Err(not_urdf(
            &path.display().to_string(),
            line,
            col,
            &name,
            "Document.load",
        )),
        _ => Ok(()),
    }
}

/// The refusal of `from_urdf_string` for text that is not URDF.
pub(crate) fn check_urdf_text(xml: &str) -> Result<(), Failure> {
    match root_element(xml.as_bytes()) {
        Root::Found(name, at) if name != b"robot" => {
            let (line, col) = line_col(xml.as_bytes(), at);
            let name = String::from_utf8_lossy(name);
            Err(not_urdf(
                "<string>",
                line,
                col,
                &name,
                "Document.from_string",
            ))
        }
        _ => Ok(()),
    }
}

fn not_urdf(file: &str, line: usize, col: usize, root: &str, instead: &str) -> Failure {
    Failure::new(vec![format!(
        "{file}:{line}:{col}: not URDF: the root element is <{root}>, not <robot> ({instead} reads any model)"
    )])
}

/// The importer of the user's `mujoco` (`mjcf_forge._upcalls.mujoco_version`), or the
/// library's default when `mujoco` cannot be imported.
pub(crate) fn installed_importer(py: Python<'_>) -> PyResult<UrdfImporter> {
    let version: Option<String> = crate::upcalls::get(py, "mujoco_version")?
        .call0()?
        .extract()?;
    Ok(version.map_or_else(UrdfImporter::default, |v| UrdfImporter::of_version(&v)))
}

/// The options a plain load (`Document.load`, `Document.from_string`, `Model(path)`,
/// `LoadCache.load`) reads URDF with: the defaults, as the user's `mujoco` imports.
pub(crate) fn plain_options(py: Python<'_>) -> PyResult<UrdfOptions> {
    Ok(UrdfOptions {
        importer: installed_importer(py)?,
        ..UrdfOptions::default()
    })
}

/// `Document.from_urdf`'s keyword arguments, as Python gave them.
pub(crate) struct UrdfArgs<'a, 'py> {
    pub(crate) caller: &'static str,
    pub(crate) visuals: bool,
    pub(crate) fuse_static: bool,
    pub(crate) keep_links: Option<&'a Bound<'py, PyAny>>,
    pub(crate) packages: Option<&'a Bound<'py, PyAny>>,
    pub(crate) resolve_packages: bool,
    pub(crate) actuators: Option<&'a Bound<'py, PyAny>>,
    pub(crate) importer: Option<&'a Bound<'py, PyAny>>,
}

impl UrdfArgs<'_, '_> {
    /// The library's options, every argument checked.
    pub(crate) fn options(&self, py: Python<'_>) -> PyResult<UrdfOptions> {
        let caller = self.caller;
        let keep_links = match self.keep_links {
            None => Vec::new(),
            Some(links) => {
                if links.is_instance_of::<PyString>() {
                    return Err(PyTypeError::new_err(format!(
                        "{caller}(keep_links=...): a collection of link names, not a str"
                    )));
                }
                links
                    .try_iter()
                    .map_err(|_| {
                        PyTypeError::new_err(format!(
                            "{caller}(keep_links=...): a collection of link names"
                        ))
                    })?
                    .map(|n| {
                        n?.extract::<String>().map_err(|_| {
                            PyTypeError::new_err(format!(
                                "{caller}(keep_links=...): every link name is a str"
                            ))
                        })
                    })
                    .collect::<PyResult<_>>()?
            }
        };
        let packages = match self.packages {
            None => Vec::new(),
            Some(map) => {
                let items = map.call_method0("items").map_err(|_| {
                    PyTypeError::new_err(format!(
                        "{caller}(packages=...): a mapping of package names to folders"
                    ))
                })?;
                items
                    .try_iter()?
                    .map(|item| {
                        let (name, dir): (Bound<'_, PyAny>, Bound<'_, PyAny>) = item?.extract()?;
                        let name = name.extract::<String>().map_err(|_| {
                            PyTypeError::new_err(format!(
                                "{caller}(packages=...): package names are str"
                            ))
                        })?;
                        let dir = dir.extract::<PathBuf>().map_err(|_| {
                            PyTypeError::new_err(format!(
                                "{caller}(packages=...): package {name:?}'s folder is a str or path-like"
                            ))
                        })?;
                        Ok((name, dir))
                    })
                    .collect::<PyResult<_>>()?
            }
        };
        let actuators = self.actuators.map(|a| actuators(caller, a)).transpose()?;
        let importer = match self.importer {
            None => installed_importer(py)?,
            Some(v) => importer(caller, v)?,
        };
        Ok(UrdfOptions {
            visuals: self.visuals,
            fuse_static: self.fuse_static,
            keep_links,
            resolve_packages: self.resolve_packages,
            packages,
            actuators,
            importer,
        })
    }
}

/// `importer=`: a MuJoCo version (`"3.17.0"`, `"4.0.0"`, `mujoco.__version__`).
fn importer(caller: &str, value: &Bound<'_, PyAny>) -> PyResult<UrdfImporter> {
    let text: String = value.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "{caller}(importer=...): a MuJoCo version such as \"3.17.0\" or \"4.0.0\""
        ))
    })?;
    let major = text.trim().split('.').next().unwrap_or("");
    match major.parse::<u32>() {
        Ok(m) if m >= 3 => Ok(UrdfImporter::of_version(text.trim())),
        _ => Err(PyValueError::new_err(format!(
            "{caller}(importer={text:?}): a MuJoCo version from 3.0 on, such as \"3.17.0\" or \"4.0.0\" \
             (URDF is read as MuJoCo 3.x or 4.x reads it)"
        ))),
    }
}

/// `actuators=`: `{"type": "position", "kp": ..., "kv": ...}`, `{"type": "velocity",
/// "kv": ...}` or `{"type": "motor"}`.
fn actuators(caller: &str, value: &Bound<'_, PyAny>) -> PyResult<UrdfActuators> {
    let usage = "{\"type\": \"position\", \"kp\": KP, \"kv\": KV}, {\"type\": \"velocity\", \"kv\": KV} or {\"type\": \"motor\"}";
    let dict = value
        .cast::<PyDict>()
        .map_err(|_| PyTypeError::new_err(format!("{caller}(actuators=...): a dict, {usage}")))?;
    let bad = |what: String| PyValueError::new_err(format!("{caller}(actuators=...): {what}"));
    let kind: String = match dict.get_item("type")? {
        Some(t) => t
            .extract()
            .map_err(|_| bad(format!("\"type\" is a str: {usage}")))?,
        None => return Err(bad(format!("no \"type\": {usage}"))),
    };
    let allowed: &[&str] = match kind.as_str() {
        "position" => &["type", "kp", "kv"],
        "velocity" => &["type", "kv"],
        "motor" => &["type"],
        other => {
            return Err(bad(format!(
                "unknown type {other:?}: position, velocity or motor"
            )));
        }
    };
    for key in dict.keys() {
        let key: String = key.str()?.to_cow()?.into_owned();
        if !allowed.contains(&key.as_str()) {
            let takes = match &allowed[1..] {
                [] => "no gains".to_string(),
                keys => keys
                    .iter()
                    .map(|k| format!("{k:?}"))
                    .collect::<Vec<_>>()
                    .join(" and "),
            };
            return Err(bad(format!("{kind} actuators take {takes}, not {key:?}")));
        }
    }
    let gain = |key: &str, required: bool| -> PyResult<f64> {
        let Some(v) = dict.get_item(key)? else {
            return if required {
                Err(bad(format!("{kind} actuators need {key:?}")))
            } else {
                Ok(0.0)
            };
        };
        let x: f64 = v
            .extract()
            .map_err(|_| bad(format!("{key:?} is a number")))?;
        if !x.is_finite() || x < 0.0 {
            return Err(bad(format!(
                "{key:?} is a finite number of at least 0, not {x}"
            )));
        }
        Ok(x)
    };
    Ok(match kind.as_str() {
        "position" => UrdfActuators::Position {
            kp: gain("kp", true)?,
            kv: gain("kv", false)?,
        },
        "velocity" => UrdfActuators::Velocity {
            kv: gain("kv", true)?,
        },
        _ => UrdfActuators::Motor,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_root_is_found_past_the_prolog() {
        let text = b"\xEF\xBB\xBF<?xml version=\"1.0\"?>\n<!-- a > b -->\n<!DOCTYPE r [<!ENTITY e \">\">]>\n  <robot name='r'>";
        assert_eq!(root_element(text), Root::Found(b"robot", 73));
        assert_eq!(line_col(text, 73), (4, 3));
        assert_eq!(root_element(b"<mujoco/>"), Root::Found(b"mujoco", 0));
        assert_eq!(root_element(b"<robot>"), Root::Found(b"robot", 0));
        assert_eq!(root_element(b"<!-- unfinished"), Root::Unfinished);
        assert_eq!(root_element(b"<rob"), Root::Unfinished);
        assert_eq!(root_element(b"<!-"), Root::Unfinished);
        assert_eq!(root_element(b"robot"), Root::Unknown);
        assert_eq!(root_element(b""), Root::Unfinished);
    }
}
