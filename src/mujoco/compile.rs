//! Compiling with MuJoCo's XML loader: [`compile_file`], [`compile_str`] and why they fail
//! ([`CompileError`]).
//!
//! Both run MuJoCo's loader as `mj_loadXML` runs it, without keeping the parsed model as
//! the process's last loaded XML (`sys::load_xml`), with a 4 KiB error buffer: MuJoCo's
//! messages name the offending element's line at their end, which a short buffer would cut
//! off.

use std::ffi::{CStr, CString, c_char, c_int};
use std::fmt;
use std::path::Path;
use std::ptr::NonNull;
use std::sync::OnceLock;

use super::model::CompiledModel;
use super::sys;
use crate::document::Document;
use crate::error::Error;

/// Bytes for MuJoCo's error (or warning) text; longer text is cut at this length.
const ERROR_BUF_LEN: usize = 4096;

/// Name under which [`compile_str`] puts its string into the VFS, inside the caller's `dir`
/// (MuJoCo resolves relative file references against the directory of this name).
const STRING_MODEL_NAME: &str = "__mjcf_forge_string_model__.xml";

/// Why MuJoCo could not compile a model.
///
/// `message` is MuJoCo's own error text (as `mj_loadXML` writes it, trailing newlines
/// removed); `element_line` is the 1-based line of the offending element when MuJoCo names
/// one (`"Element 'geom', line 12"`, `"Element name 'a', id 0, line 9"`, or tinyxml2's
/// `"Line number=3"` for malformed XML). `Display` prints the message alone.
///
/// ```
/// use std::path::Path;
/// use mjcf_forge::mujoco::compile_str;
///
/// let xml = "<mujoco>\n<worldbody>\n<geom size=\"x\"/>\n</worldbody>\n</mujoco>";
/// let err = compile_str(xml, Path::new(".")).unwrap_err();
/// assert_eq!(err.element_line, Some(3));
/// assert!(err.to_string().contains("bad format in attribute 'size'"));
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompileError {
    /// MuJoCo's error text.
    pub message: String,
    /// The line MuJoCo's message names, if any.
    pub element_line: Option<u32>,
}

impl CompileError {
    /// An error from MuJoCo's text: parses the line number out of it.
    ///
    /// ```
    /// use mjcf_forge::mujoco::CompileError;
    ///
    /// let err = CompileError::from_message("XML Error: bad format\nElement 'geom', line 12\n");
    /// assert_eq!(err.element_line, Some(12));
    /// assert_eq!(err.message, "XML Error: bad format\nElement 'geom', line 12");
    /// ```
    pub fn from_message(message: impl Into<String>) -> Self {
        let mut message = message.into();
        message.truncate(message.trim_end().len());
        let element_line = crate::document::locate::error_line(&message);
        Self {
            message,
            element_line,
        }
    }

    /// An error that did not come from MuJoCo (bad path, version mismatch): no line.
    pub(super) fn local(message: String) -> Self {
        Self {
            message,
            element_line: None,
        }
    }
}

impl fmt::Display for CompileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for CompileError {}

/// A local error (no line) from a message: what the document tier's checks report when it
/// writes compiled inertials back ([`Document::write_compiled_inertials`](crate::Document::write_compiled_inertials)).
impl From<String> for CompileError {
    fn from(message: String) -> Self {
        Self::local(message)
    }
}

/// A local error (no line) in the words of the crate's error (the document tier's checks
/// when it writes compiled inertials back).
impl From<crate::Error> for CompileError {
    fn from(e: crate::Error) -> Self {
        Self::local(e.to_string())
    }
}

/// Compiles the MJCF (or URDF) file at `path`; its relative file references (includes,
/// meshes, textures) resolve against the file's directory, as in MuJoCo.
///
/// Never panics on bad input: unreadable files, malformed XML, schema violations, missing
/// assets and compiler errors all come back as [`CompileError`].
///
/// ```no_run
/// use std::path::Path;
/// use mjcf_forge::mujoco::compile_file;
///
/// match compile_file(Path::new("robot.xml")) {
///     Ok(model) => println!("{}", model.sizes().to_json()),
///     Err(err) => eprintln!("line {:?}: {err}", err.element_line),
/// }
/// ```
pub fn compile_file(path: &Path) -> Result<CompiledModel, CompileError> {
    check_version()?;
    let c_path = path_to_cstring(path)?;
    load_xml(&c_path, None)
}

/// Compiles the MJCF document `xml`, resolving its relative file references (includes,
/// meshes, textures, `meshdir`, ...) against `dir`, as if it were a file in `dir`.
///
/// The string goes into a MuJoCo virtual file system (VFS) private to this call, under a
/// name in `dir`: nothing is written to disk, `dir` may be read-only, and concurrent calls
/// do not interfere. Assets are read from the real file system.
///
/// ```no_run
/// use std::path::Path;
/// use mjcf_forge::mujoco::{compile_str, ObjType};
///
/// let xml = r#"<mujoco>
///   <asset><mesh name="part" file="meshes/part.obj"/></asset>
///   <worldbody><geom type="mesh" mesh="part"/></worldbody>
/// </mujoco>"#;
/// // reads ./models/meshes/part.obj
/// let model = compile_str(xml, Path::new("models")).unwrap();
/// assert_eq!(model.names(ObjType::Mesh), ["part"]);
/// ```
pub fn compile_str(xml: &str, dir: &Path) -> Result<CompiledModel, CompileError> {
    check_version()?;
    let name = path_to_cstring(&dir.join(STRING_MODEL_NAME))?;
    let len = c_int::try_from(xml.len()).map_err(|_| {
        CompileError::local(format!(
            "MJCF string too long for MuJoCo ({} bytes)",
            xml.len()
        ))
    })?;
    let mut vfs = sys::Vfs::new()
        .ok_or_else(|| CompileError::local("could not make a MuJoCo VFS".to_owned()))?;
    let added = vfs.add_buffer(&name, xml.as_bytes(), len);
    if added != 0 {
        return Err(CompileError::local(format!(
            "could not add the MJCF string to MuJoCo's VFS (code {added})"
        )));
    }
    load_xml(&name, Some(&vfs))
}

/// Compiles `doc` as MuJoCo reads it (its indented XML, relative references resolved from
/// the model's folder, though loading made them absolute already), with MuJoCo's error,
/// if any, at the element it names in the user's sources ([`Document::mujoco_error`]):
/// `robot.xml:12:7: Error: mesh 'nope' not found in geom 0`, the rest of MuJoCo's message
/// (whose own `line N` counts lines of the XML it was given) and the include chain.
///
/// ```
/// use mjcf_forge::Document;
/// use mjcf_forge::mujoco::compile_document;
///
/// let doc = Document::from_str("<mujoco>\n<worldbody>\n<geom type='mesh' mesh='nope'/>\n</worldbody>\n</mujoco>", ".")?;
/// let err = compile_document(&doc).unwrap_err();
/// assert!(err.to_string().starts_with("<string>:3:1: "), "{err}");
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn compile_document(doc: &Document) -> Result<CompiledModel, Error> {
    let xml = doc.to_pretty_string();
    compile_str(&xml, doc.model_dir()).map_err(|e| doc.mujoco_error(&xml, &e.message))
}

/// Runs MuJoCo's loader (`sys::load_xml`) and wraps the result.
fn load_xml(path: &CStr, vfs: Option<&sys::Vfs>) -> Result<CompiledModel, CompileError> {
    let mut buf = vec![0 as c_char; ERROR_BUF_LEN];
    // SAFETY: `path` is NUL-terminated; `vfs` is None or a live VFS that outlives the call;
    // `buf` holds `ERROR_BUF_LEN` bytes, which is what MuJoCo is told it may write.
    let model = unsafe { sys::load_xml(path, vfs, buf.as_mut_ptr(), ERROR_BUF_LEN as c_int) };
    // MuJoCo NUL-terminates within `error_sz`; the last byte stays 0 in any case.
    buf[ERROR_BUF_LEN - 1] = 0;
    // SAFETY: `buf` is NUL-terminated (see above).
    let text = unsafe { CStr::from_ptr(buf.as_ptr()) }
        .to_string_lossy()
        .into_owned();
    match NonNull::new(model) {
        Some(ptr) => {
            let text = text.trim_end();
            let warnings = (!text.is_empty()).then(|| text.to_owned());
            Ok(CompiledModel::from_raw(ptr, warnings))
        }
        None if text.trim().is_empty() => Err(CompileError::local(
            "MuJoCo could not compile the model and gave no reason".to_owned(),
        )),
        None => Err(CompileError::from_message(text)),
    }
}

/// Refuses to call into a MuJoCo other than the one whose headers the shim was compiled
/// with (a library swapped after the build): the layouts the shim reads would be wrong.
fn check_version() -> Result<(), CompileError> {
    static LINKED: OnceLock<c_int> = OnceLock::new();
    let linked = *LINKED.get_or_init(sys::linked_version);
    let header = sys::header_version();
    if linked == header {
        Ok(())
    } else {
        Err(CompileError::local(format!(
            "linked MuJoCo library has version code {linked}, expected {header} (the headers \
             this build was made with): run scripts/setup.sh, or rebuild against the MuJoCo \
             you link"
        )))
    }
}

fn path_to_cstring(path: &Path) -> Result<CString, CompileError> {
    #[cfg(unix)]
    let bytes = {
        use std::os::unix::ffi::OsStrExt;
        path.as_os_str().as_bytes().to_vec()
    };
    #[cfg(not(unix))]
    let bytes = match path.to_str() {
        Some(s) => s.as_bytes().to_vec(),
        None => {
            return Err(CompileError::local(format!(
                "path is not valid Unicode: {}",
                path.display()
            )));
        }
    };
    CString::new(bytes)
        .map_err(|_| CompileError::local(format!("path contains a NUL byte: {}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_from_element_messages() {
        let cases = [
            (
                "XML Error: Schema violation: unrecognized attribute: 'sizee'\nElement 'geom', line 5\n",
                Some(5),
            ),
            (
                "Error: unknown transmission target 'nope' for actuator id = 0\nElement name '', id 0, line 9",
                Some(9),
            ),
            (
                "XML parse error 14:\nError=XML_ERROR_MISMATCHED_ELEMENT ErrorID=14 (0xe) Line number=3: XMLElement name=geom\n",
                Some(3),
            ),
            ("Error: Error opening file 'does_not_exist.obj'", None),
            ("XML Error: Unrecognized XML model type: 'foo'", None),
            (
                "Error: file 'baseline.xml' missing\nElement 'geom', line x",
                None,
            ),
        ];
        for (message, line) in cases {
            let err = CompileError::from_message(message);
            assert_eq!(err.element_line, line, "{message:?}");
            assert_eq!(err.to_string(), message.trim_end());
        }
    }
}
