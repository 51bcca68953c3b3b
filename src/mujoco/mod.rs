//! Compile MJCF with MuJoCo's own C library (cargo feature `mujoco`).
//!
//! [`compile_file`] and [`compile_str`] run MuJoCo's XML loader (`mj_loadXML`: parse,
//! then compile) and return a [`CompiledModel`], a safe owning handle to the resulting
//! `mjModel`, or a [`CompileError`] carrying MuJoCo's own message and, when MuJoCo names
//! one, the line of the offending element.
//!
//! One binding for any MuJoCo from 3.17.0 on: `build.rs` compiles our small C shim
//! (`src/mujoco_shim.c`) against the headers of the MuJoCo it links, so no Rust copy of
//! `mjModel`'s layout exists; fields are read by name through MuJoCo's X-macro tables. The
//! calls into C go through the small private module `sys` below. This module calls
//! `mj_loadXML` itself, with a 4 KiB error buffer: MuJoCo's messages name the offending
//! element's line at their end, which a short buffer would cut off.
//!
//! # Thread safety
//!
//! The loader is called without any lock of ours: `mj_loadXML` is safe to call from several
//! threads at once in MuJoCo 3.x. Its only process-wide state is the "last loaded spec"
//! kept for `mj_saveLastXML`, which MuJoCo guards with its own mutex; the compiler reports
//! engine errors through thread-local handlers (`_mjPRIVATE__set_tls_error_fn`) and a
//! thread-local jump buffer; the XML reader switches the number locale per thread
//! (`uselocale`); each call here gets its own VFS. (Source: MuJoCo's `xml_api.cc`,
//! `xml_global.cc`, `xml.cc` and `user_model.cc`; the wheel's own `thread_safety_test.py`
//! creates models from several threads.) `tests/mujoco_compile.rs` checks it with 8
//! threads compiling different models, with and without mesh files, 50 times each. What
//! stays global in MuJoCo is what this module never touches: the user error/warning
//! callbacks (`mju_user_error`, `mju_user_warning`) and `mj_saveLastXML`.
//!
//! # Example
//!
//! ```
//! use std::path::Path;
//! use mjcf_forge::mujoco::{compile_str, ObjType};
//!
//! let xml = r#"<mujoco><worldbody>
//!   <body name="ball"><freejoint/><geom name="g" size="0.1"/></body>
//! </worldbody></mujoco>"#;
//! let model = compile_str(xml, Path::new(".")).expect("valid model");
//! assert_eq!(model.sizes().nbody, 2);
//! assert_eq!(model.names(ObjType::Body), ["world", "ball"]);
//! ```

// The FFI calls into MuJoCo are confined to this module; the crate root denies unsafe code
// elsewhere (it must use `deny`, not `forbid`, in builds with this feature).
#![allow(unsafe_code)]

use std::ffi::{CStr, CString, c_char, c_int};
use std::fmt;
use std::path::Path;
use std::ptr::NonNull;
use std::sync::OnceLock;

use sys::{model_array, model_size};

mod cache;
pub use cache::ModelCache;

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
        let element_line = parse_line(&message);
        Self {
            message,
            element_line,
        }
    }

    /// An error that did not come from MuJoCo (bad path, version mismatch): no line.
    fn local(message: String) -> Self {
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

/// The line number in a MuJoCo error message: MuJoCo's `", line N"` (it ends the
/// `Element ...` line of its messages), else tinyxml2's `"Line number=N"`.
fn parse_line(message: &str) -> Option<u32> {
    let element_line = message
        .lines()
        .rev()
        .filter(|line| line.trim_start().starts_with("Element"))
        .find_map(|line| number_after(line, ", line "));
    element_line
        .or_else(|| number_after(message, ", line "))
        .or_else(|| number_after(message, "Line number="))
}

/// The decimal number right after the last `marker` in `text` that has one.
fn number_after(text: &str, marker: &str) -> Option<u32> {
    text.rmatch_indices(marker).find_map(|(at, _)| {
        let rest = &text[at + marker.len()..];
        let end = rest
            .find(|c: char| !c.is_ascii_digit())
            .unwrap_or(rest.len());
        rest[..end].parse().ok()
    })
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

/// Writes an explicit `<inertial>` (mass, pos, quat, diaginertia, at full precision, as
/// MuJoCo compiles `doc` alone) into every body that infers its inertia from its geoms, so
/// that the document compiles to the same masses and inertias whatever the compiler's
/// `inertiagrouprange`: what lets [`Document::merge`](crate::Document::merge) take a part
/// whose range differs from the base's. Returns how many bodies got one.
///
/// Refuses documents whose compiled bodies are not their `<body>` elements one to one
/// (`<replicate>`, `<attach>`, `<composite>`, `<flexcomp>`, `fusestatic`), and documents
/// with `inertiafromgeom="true"` (which ignores `<inertial>`).
///
/// ```
/// use mjcf_forge::Document;
/// use mjcf_forge::mujoco::write_inertials;
///
/// let mut doc = Document::from_str(r#"<mujoco><compiler inertiagrouprange="1 5"/><worldbody>
///   <body name="b"><freejoint/><geom size="0.1" group="1"/><geom size="0.5" group="0"/></body>
///   </worldbody></mujoco>"#, ".")?;
/// assert_eq!(write_inertials(&mut doc)?, 1);
/// assert!(doc.to_xml_string().contains("<inertial "));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_inertials(doc: &mut crate::Document) -> Result<usize, CompileError> {
    write_inertials_of(doc, false)
}

/// Like [`write_inertials`], but for every body whose compiled mass or inertia is not zero or
/// that has geoms or an `<inertial>` of its own (which is replaced): afterwards the compiler's
/// mass settings (`settotalmass`, `boundmass`, `boundinertia`, `balanceinertia`,
/// `inertiafromgeom="false"`) have nothing left to change when left at MuJoCo's defaults, so
/// a part authored with them merges exactly into a base without them.
///
/// ```
/// use mjcf_forge::Document;
/// use mjcf_forge::mujoco::write_all_inertials;
///
/// let mut doc = Document::from_str(r#"<mujoco><compiler settotalmass="3"/><worldbody>
///   <body name="b"><freejoint/><geom size="0.1"/></body></worldbody></mujoco>"#, ".")?;
/// assert_eq!(write_all_inertials(&mut doc)?, 1);
/// assert!(doc.to_xml_string().contains(r#"mass="3.0""#));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_all_inertials(doc: &mut crate::Document) -> Result<usize, CompileError> {
    write_inertials_of(doc, true)
}

/// `qpos0` of the free joint `joint` of `doc` (7 numbers) as MuJoCo compiles `doc` alone:
/// for a free body MuJoCo aligns with its inertial frame, the only exact source. Joints
/// are matched to `doc`'s joint elements in document order, which must be one to one.
pub(crate) fn free_joint_qpos0(
    doc: &crate::Document,
    joint: crate::document::tree::Node,
) -> Result<[f64; 7], CompileError> {
    let joints: Vec<crate::document::tree::Node> = doc
        .find_section(crate::Section::Worldbody)
        .map(|w| {
            doc.descendants(w)
                .filter(|&n| matches!(doc.tag(n), "joint" | "freejoint"))
                .collect()
        })
        .unwrap_or_default();
    let model = compile_str(&doc.to_xml_string(), doc.model_dir())?;
    let types = model.jnt_type();
    if types.len() != joints.len() {
        return Err(CompileError::local(format!(
            "MuJoCo compiled {} joints from {} joint elements",
            types.len(),
            joints.len()
        )));
    }
    let k = joints
        .iter()
        .position(|&n| n == joint)
        .ok_or_else(|| CompileError::local("not a joint of the model's bodies".to_string()))?;
    if types[k] != 0 {
        return Err(CompileError::local("not a free joint".to_string()));
    }
    // qpos widths by joint type: free 7, ball 4, slide and hinge 1.
    let at: usize = types[..k]
        .iter()
        .map(|&t| match t {
            0 => 7,
            1 => 4,
            _ => 1,
        })
        .sum();
    let mut q = [0.0; 7];
    q.copy_from_slice(&model.qpos0()[at..at + 7]);
    Ok(q)
}

/// For a document with `compiler inertiafromgeom="true"`: every body's compiled inertia
/// written out as by [`write_all_inertials`] (compiled under "true", whatever the body's
/// `<inertial>` says), then the setting made `"auto"`, under which every written `<inertial>`
/// counts: the same masses and inertias, and no mass setting left with anything to change.
pub(crate) fn write_all_inertials_from_geoms(
    doc: &mut crate::Document,
) -> Result<usize, CompileError> {
    let n = write_inertials_checked(doc, true, false)?;
    let compilers: Vec<crate::document::tree::Node> = doc
        .elements(doc.root())
        .filter(|&c| doc.tag(c) == "compiler" && doc.attr(c, "inertiafromgeom").is_some())
        .collect();
    for c in compilers {
        doc.set_attr(c, "inertiafromgeom", "auto");
    }
    Ok(n)
}

fn write_inertials_of(doc: &mut crate::Document, all: bool) -> Result<usize, CompileError> {
    write_inertials_checked(doc, all, true)
}

/// `from_geoms_refused`: refuse inertiafromgeom="true", under which the written inertials
/// would be ignored (callers that then make the setting "auto" pass false).
fn write_inertials_checked(
    doc: &mut crate::Document,
    all: bool,
    from_geoms_refused: bool,
) -> Result<usize, CompileError> {
    let refused = ["replicate", "attach", "composite", "flexcomp"];
    if let Some(n) = doc
        .descendants(doc.root())
        .find(|&n| refused.contains(&doc.tag(n)))
    {
        return Err(CompileError::local(format!(
            "{}: <{}> makes bodies when MuJoCo compiles; explicit inertials are written for \
             plain <body> elements only",
            doc.location(n),
            doc.tag(n)
        )));
    }
    for c in doc
        .elements(doc.root())
        .filter(|&c| doc.tag(c) == "compiler")
    {
        let setting = |k: &str, bad: &str| doc.attr(c, k).is_some_and(|v| v.trim() == bad);
        if (from_geoms_refused && setting("inertiafromgeom", "true"))
            || setting("fusestatic", "true")
        {
            return Err(CompileError::local(format!(
                "{}: compiler inertiafromgeom=\"true\" or fusestatic=\"true\": explicit \
                 inertials would not carry the compiled inertia",
                doc.location(c)
            )));
        }
    }
    let inferring = doc.bodies_inferring_inertia();
    if inferring.is_empty() && !all {
        return Ok(0);
    }
    let model = compile_str(&doc.to_xml_string(), doc.model_dir())?;
    // MuJoCo numbers bodies depth first in document order, the world body first.
    let bodies: Vec<crate::document::tree::Node> = doc
        .descendants(doc.root())
        .filter(|&n| doc.tag(n) == "body")
        .collect();
    let names = model.names(ObjType::Body);
    if names.len() != bodies.len() + 1 {
        return Err(CompileError::local(format!(
            "MuJoCo compiled {} bodies from {} <body> elements",
            names.len() - 1,
            bodies.len()
        )));
    }
    for (i, &b) in bodies.iter().enumerate() {
        if doc.attr(b, "name").is_some_and(|n| n != names[i + 1]) {
            return Err(CompileError::local(format!(
                "{}: body {:?} compiled as {:?}: bodies do not match one to one",
                doc.location(b),
                doc.attr(b, "name").unwrap_or(""),
                names[i + 1]
            )));
        }
    }
    let (mass, ipos, iquat, inertia) = (
        model.body_mass(),
        model.body_ipos(),
        model.body_iquat(),
        model.body_inertia(),
    );
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:?}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let own_inertial =
        |doc: &crate::Document, b| doc.elements(b).find(|&c| doc.tag(c) == "inertial");
    let targets: Vec<crate::document::tree::Node> = if all {
        bodies
            .iter()
            .enumerate()
            .filter(|&(i, &b)| {
                let id = i + 1;
                let nonzero =
                    mass[id] != 0.0 || inertia[3 * id..3 * id + 3].iter().any(|&x| x != 0.0);
                nonzero || inferring.contains(&b) || own_inertial(doc, b).is_some()
            })
            .map(|(_, &b)| b)
            .collect()
    } else {
        inferring
    };
    for &b in &targets {
        if let Some(old) = own_inertial(doc, b) {
            doc.remove(old);
        }
        let id = 1 + bodies
            .iter()
            .position(|&n| n == b)
            .expect("a body of the document");
        let attrs = [
            ("pos", list(&ipos[3 * id..3 * id + 3])),
            ("quat", list(&iquat[4 * id..4 * id + 4])),
            ("mass", list(&mass[id..id + 1])),
            ("diaginertia", list(&inertia[3 * id..3 * id + 3])),
        ];
        let attrs: Vec<(&str, &str)> = attrs.iter().map(|(k, v)| (*k, v.as_str())).collect();
        doc.append_element(b, "inertial", &attrs);
    }
    Ok(targets.len())
}

/// Runs `mj_loadXML` and wraps the result.
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
            Ok(CompiledModel {
                ptr,
                warnings,
                serial: cache::next_serial(),
            })
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

/// A model compiled by MuJoCo: owns the `mjModel`, which is freed (`mj_deleteModel`) on
/// drop. All access is read-only.
///
/// `CompiledModel` is `Send`: the `mjModel` is one heap allocation owned by this handle
/// alone (no other pointer to it escapes, and MuJoCo keeps none), and MuJoCo ties no thread
/// to a model, so using and freeing it on another thread is fine. It is also `Sync`: every
/// method takes `&self` and only reads the model (`mj_id2name` included), there is no
/// interior mutability, and concurrent reads of memory nobody writes are not a data race.
///
/// ```no_run
/// use std::path::Path;
/// use mjcf_forge::mujoco::{compile_file, ObjType};
///
/// let model = compile_file(Path::new("arm.xml")).unwrap();
/// let sizes = model.sizes();
/// for (name, pos) in model.names(ObjType::Body).iter().zip(model.body_pos().chunks(3)) {
///     println!("{name}: {pos:?}");
/// }
/// let handle = std::thread::spawn(move || model.sizes()); // Send
/// assert_eq!(handle.join().unwrap(), sizes);
/// ```
pub struct CompiledModel {
    ptr: NonNull<sys::Model>,
    warnings: Option<String>,
    /// Unique per model made (compiled or cloned): the model cache's plans are per model.
    serial: u64,
}

/// A deep copy (`mj_copyModel`): a model of the same structure, patched on its own.
impl Clone for CompiledModel {
    fn clone(&self) -> Self {
        // SAFETY: `self` is live; mj_copyModel allocates a new model or returns null.
        let copy = unsafe { cache::mjf_patch_copy_model(self.raw()) };
        let ptr = NonNull::new(copy).expect("MuJoCo could not allocate a copy of the model");
        CompiledModel {
            ptr,
            warnings: self.warnings.clone(),
            serial: cache::next_serial(),
        }
    }
}

// SAFETY: see the type's documentation: exclusive ownership of a heap allocation without
// thread affinity.
unsafe impl Send for CompiledModel {}
// SAFETY: see the type's documentation: only reads through `&self`.
unsafe impl Sync for CompiledModel {}

impl Drop for CompiledModel {
    fn drop(&mut self) {
        // SAFETY: `ptr` came from `mj_loadXML`, is owned by `self` alone and freed only here.
        unsafe { sys::delete_model(self.ptr.as_ptr()) }
    }
}

impl fmt::Debug for CompiledModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CompiledModel")
            .field("sizes", &self.sizes())
            .field("warnings", &self.warnings)
            .finish()
    }
}

/// The kinds of named object [`CompiledModel::names`] lists (MuJoCo's `mjtObj`).
///
/// ```
/// use mjcf_forge::mujoco::ObjType;
///
/// assert_eq!(ObjType::Geom.as_str(), "geom");
/// assert_eq!(ObjType::ALL.len(), 14);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ObjType {
    /// `mjOBJ_BODY` (index 0 is `world`).
    Body,
    /// `mjOBJ_JOINT`.
    Joint,
    /// `mjOBJ_GEOM`.
    Geom,
    /// `mjOBJ_SITE`.
    Site,
    /// `mjOBJ_CAMERA`.
    Camera,
    /// `mjOBJ_LIGHT`.
    Light,
    /// `mjOBJ_MESH`.
    Mesh,
    /// `mjOBJ_MATERIAL`.
    Material,
    /// `mjOBJ_TEXTURE`.
    Texture,
    /// `mjOBJ_TENDON`.
    Tendon,
    /// `mjOBJ_ACTUATOR`.
    Actuator,
    /// `mjOBJ_SENSOR`.
    Sensor,
    /// `mjOBJ_EQUALITY`.
    Equality,
    /// `mjOBJ_KEY` (keyframes).
    Key,
}

impl ObjType {
    /// Every variant, in declaration order.
    pub const ALL: [ObjType; 14] = [
        ObjType::Body,
        ObjType::Joint,
        ObjType::Geom,
        ObjType::Site,
        ObjType::Camera,
        ObjType::Light,
        ObjType::Mesh,
        ObjType::Material,
        ObjType::Texture,
        ObjType::Tendon,
        ObjType::Actuator,
        ObjType::Sensor,
        ObjType::Equality,
        ObjType::Key,
    ];

    /// The MJCF element name of this kind (`"body"`, `"joint"`, ..., `"key"`).
    pub fn as_str(self) -> &'static str {
        match self {
            ObjType::Body => "body",
            ObjType::Joint => "joint",
            ObjType::Geom => "geom",
            ObjType::Site => "site",
            ObjType::Camera => "camera",
            ObjType::Light => "light",
            ObjType::Mesh => "mesh",
            ObjType::Material => "material",
            ObjType::Texture => "texture",
            ObjType::Tendon => "tendon",
            ObjType::Actuator => "actuator",
            ObjType::Sensor => "sensor",
            ObjType::Equality => "equality",
            ObjType::Key => "key",
        }
    }
}

impl fmt::Display for ObjType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Defines [`Sizes`] from one list, so the struct, [`Sizes::entries`] and
/// [`Sizes::to_json`] cannot disagree on fields or order.
macro_rules! sizes_struct {
    ($($field:ident: $doc:literal,)*) => {
        /// Sizes of a compiled model (copied from `mjModel`), e.g. `nbody` counts the world
        /// body too. [`Sizes::to_json`] writes them as one JSON object with a fixed key order:
        /// `nbody njnt ngeom nsite nu nsensor nq nv nmesh`, then the rest as declared.
        ///
        /// ```no_run
        /// use std::path::Path;
        /// use mjcf_forge::mujoco::compile_file;
        ///
        /// let sizes = compile_file(Path::new("arm.xml")).unwrap().sizes();
        /// println!("{} bodies, {} dofs", sizes.nbody, sizes.nv);
        /// assert!(sizes.to_json().starts_with("{\"nbody\":"));
        /// ```
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
        pub struct Sizes {
            $(#[doc = $doc] pub $field: usize,)*
        }

        impl Sizes {
            /// Number of fields, i.e. of [`Sizes::entries`].
            pub const LEN: usize = [$(stringify!($field)),*].len();

            /// `(name, value)` of every field, in [`Sizes::to_json`]'s order.
            pub fn entries(&self) -> [(&'static str, usize); Self::LEN] {
                [$((stringify!($field), self.$field)),*]
            }

            fn from_model(m: &sys::Model) -> Self {
                Self { $($field: model_size!(m, $field),)* }
            }
        }
    };
}

sizes_struct! {
    nbody: "Bodies, including the world body.",
    njnt: "Joints.",
    ngeom: "Geoms.",
    nsite: "Sites.",
    nu: "Scalar controls (`dim(ctrl)`).",
    nsensor: "Sensors.",
    nq: "Generalized coordinates (`dim(qpos)`).",
    nv: "Degrees of freedom (`dim(qvel)`).",
    nmesh: "Meshes.",
    na: "Activation states (`dim(act)`).",
    nactuator: "Actuators.",
    ncam: "Cameras.",
    nlight: "Lights.",
    ntex: "Textures.",
    nmat: "Materials.",
    ntendon: "Tendons.",
    nwrap: "Tendon wrap objects.",
    neq: "Equality constraints.",
    nkey: "Keyframes.",
    nmocap: "Mocap bodies.",
    nhfield: "Height fields.",
    nskin: "Skins.",
    nflex: "Flexes.",
    npair: "Predefined geom pairs.",
    nexclude: "Excluded body pairs.",
    nnumeric: "Numeric custom fields.",
    ntext: "Text custom fields.",
    ntuple: "Tuple custom fields.",
    nplugin: "Plugin instances.",
    nsensordata: "Sensor data values (`dim(sensordata)`).",
    nuser_body: "User numbers per body.",
    nuser_jnt: "User numbers per joint.",
    nuser_geom: "User numbers per geom.",
    nuser_site: "User numbers per site.",
    nuser_cam: "User numbers per camera.",
    nuser_tendon: "User numbers per tendon.",
    nuser_actuator: "User numbers per actuator.",
    nuser_sensor: "User numbers per sensor.",
    nnames: "Bytes of the names buffer.",
}

impl Sizes {
    /// One JSON object, keys in [`Sizes::entries`] order, no whitespace:
    /// `{"nbody":2,"njnt":1,...}`.
    ///
    /// ```
    /// use mjcf_forge::mujoco::Sizes;
    ///
    /// let sizes = Sizes { nbody: 2, nq: 7, ..Sizes::default() };
    /// let json = sizes.to_json();
    /// assert!(json.starts_with(r#"{"nbody":2,"njnt":0,"ngeom":0,"nsite":0,"nu":0,"#));
    /// assert!(json.contains(r#""nq":7,"nv":0,"nmesh":0,"na":0"#));
    /// ```
    pub fn to_json(&self) -> String {
        let mut out = String::from("{");
        for (i, (key, value)) in self.entries().iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            out.push_str(&format!("\"{key}\":{value}"));
        }
        out.push('}');
        out
    }
}

/// A contact found by [`CompiledModel::initial_contacts`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The first geom's id.
    pub geom1: usize,
    /// The second geom's id.
    pub geom2: usize,
    /// Signed distance: negative when the geoms interpenetrate.
    pub dist: f64,
}

/// Defines read-only slice accessors for `mjModel` arrays: `name: type, |m| length`.
macro_rules! model_arrays {
    ($($(#[$doc:meta])* $field:ident: $ty:ty, |$m:ident| $len:expr;)*) => {
        impl CompiledModel {
            $(
                $(#[$doc])*
                pub fn $field(&self) -> &[$ty] {
                    let $m = self.raw();
                    // SAFETY: MuJoCo allocates `$field` with exactly this many elements
                    // (see mjmodel.h) inside the model, which lives as long as `self` and
                    // is never written after compilation.
                    unsafe { slice_or_empty(model_array!($m, $field, $ty), $len) }
                }
            )*
        }
    };
}

model_arrays! {
    /// Body positions relative to the parent body, 3 per body (`nbody x 3`).
    body_pos: f64, |m| model_size!(m, nbody) * 3;
    /// Body orientations relative to the parent body, quaternions `w x y z` (`nbody x 4`).
    body_quat: f64, |m| model_size!(m, nbody) * 4;
    /// Body masses (`nbody`).
    body_mass: f64, |m| model_size!(m, nbody);
    /// Body principal moments of inertia (`nbody x 3`).
    body_inertia: f64, |m| model_size!(m, nbody) * 3;
    /// Positions of the bodies' inertial frames in the body frames (`nbody x 3`).
    body_ipos: f64, |m| model_size!(m, nbody) * 3;
    /// Orientations of the bodies' inertial frames in the body frames (`nbody x 4`).
    body_iquat: f64, |m| model_size!(m, nbody) * 4;
    /// Parent body ids (`nbody`; the world body is its own parent).
    body_parentid: i32, |m| model_size!(m, nbody);
    /// Per body, the id of its top-level ancestor (the body itself at the top).
    body_rootid: i32, |m| model_size!(m, nbody);
    /// Joint types (`mjtJoint`: 0 free, 1 ball, 2 slide, 3 hinge) (`njnt`).
    jnt_type: i32, |m| model_size!(m, njnt);
    /// Joint axes in the body frame (`njnt x 3`).
    jnt_axis: f64, |m| model_size!(m, njnt) * 3;
    /// Joint limits (`njnt x 2`).
    jnt_range: f64, |m| model_size!(m, njnt) * 2;
    /// Geom types (`mjtGeom`) (`ngeom`).
    geom_type: i32, |m| model_size!(m, ngeom);
    /// Ids of the geoms' bodies (`ngeom`).
    geom_bodyid: i32, |m| model_size!(m, ngeom);
    /// Geom size parameters (`ngeom x 3`).
    geom_size: f64, |m| model_size!(m, ngeom) * 3;
    /// Geom positions relative to their body (`ngeom x 3`).
    geom_pos: f64, |m| model_size!(m, ngeom) * 3;
    /// Geom orientations relative to their body, `w x y z` (`ngeom x 4`).
    geom_quat: f64, |m| model_size!(m, ngeom) * 4;
    /// Geom friction: slide, spin, roll (`ngeom x 3`).
    geom_friction: f64, |m| model_size!(m, ngeom) * 3;
    /// Geom colors when no material is set (`ngeom x 4`).
    geom_rgba: f32, |m| model_size!(m, ngeom) * 4;
    /// Site positions relative to their body (`nsite x 3`).
    site_pos: f64, |m| model_size!(m, nsite) * 3;
    /// Actuator gain parameters, `mjNGAIN` (10) per actuator (`nactuator x 10`).
    actuator_gainprm: f64, |m| model_size!(m, nactuator) * sys::ngain();
    /// Actuator bias parameters, `mjNBIAS` (10) per actuator (`nactuator x 10`).
    actuator_biasprm: f64, |m| model_size!(m, nactuator) * sys::nbias();
    /// Default pose (`nq`).
    qpos0: f64, |m| model_size!(m, nq);
    /// Keyframe times (`nkey`).
    key_time: f64, |m| model_size!(m, nkey);
    /// Keyframe positions (`nkey x nq`).
    key_qpos: f64, |m| model_size!(m, nkey) * model_size!(m, nq);
}

/// `len` elements at `ptr`, or an empty slice when `len` is 0 (MuJoCo may leave such
/// arrays null).
///
/// # Safety
/// When `len > 0`, `ptr` must point to `len` initialized elements that stay valid and
/// unwritten for `'a`.
unsafe fn slice_or_empty<'a, T>(ptr: *const T, len: usize) -> &'a [T] {
    if len == 0 || ptr.is_null() {
        &[]
    } else {
        // SAFETY: guaranteed by the caller.
        unsafe { std::slice::from_raw_parts(ptr, len) }
    }
}

impl CompiledModel {
    /// The contacts MuJoCo finds at the model's initial pose (`qpos0`): `mj_forward` on
    /// fresh data, which is freed again. Geoms with a negative `dist` interpenetrate.
    ///
    /// ```
    /// use mjcf_forge::mujoco::compile_str;
    /// let xml = r#"<mujoco><worldbody><geom type="plane" size="1 1 1"/>
    ///   <body pos="0 0 0.05"><freejoint/><geom type="sphere" size="0.1"/></body>
    ///   </worldbody></mujoco>"#;
    /// let model = compile_str(xml, std::path::Path::new(".")).unwrap();
    /// let contacts = model.initial_contacts();
    /// assert_eq!(contacts.len(), 1);
    /// assert!((contacts[0].dist + 0.05).abs() < 1e-9);
    /// ```
    pub fn initial_contacts(&self) -> Vec<Contact> {
        sys::initial_contacts(self.raw())
    }

    fn raw(&self) -> &sys::Model {
        // SAFETY: `ptr` is a live model owned by `self` (see `Drop`).
        unsafe { self.ptr.as_ref() }
    }

    /// The model's sizes (see [`Sizes`]).
    ///
    /// ```
    /// use std::path::Path;
    /// use mjcf_forge::mujoco::compile_str;
    ///
    /// let m = compile_str("<mujoco><worldbody><body><freejoint/><geom size='1'/></body>\
    ///                      </worldbody></mujoco>", Path::new(".")).unwrap();
    /// let s = m.sizes();
    /// assert_eq!((s.nbody, s.njnt, s.nq, s.nv), (2, 1, 7, 6));
    /// ```
    pub fn sizes(&self) -> Sizes {
        Sizes::from_model(self.raw())
    }

    /// The names of all objects of kind `obj`, indexed by MuJoCo id (so `names(Body)[0]`
    /// is `"world"`); unnamed objects give `""`.
    ///
    /// ```
    /// use std::path::Path;
    /// use mjcf_forge::mujoco::{compile_str, ObjType};
    ///
    /// let m = compile_str("<mujoco><worldbody><geom name='floor' type='plane' size='1 1 1'/>\
    ///                      <geom size='1'/></worldbody></mujoco>", Path::new(".")).unwrap();
    /// assert_eq!(m.names(ObjType::Geom), ["floor", ""]);
    /// ```
    pub fn names(&self, obj: ObjType) -> Vec<String> {
        let m = self.raw();
        let count = match obj {
            ObjType::Body => model_size!(m, nbody),
            ObjType::Joint => model_size!(m, njnt),
            ObjType::Geom => model_size!(m, ngeom),
            ObjType::Site => model_size!(m, nsite),
            ObjType::Camera => model_size!(m, ncam),
            ObjType::Light => model_size!(m, nlight),
            ObjType::Mesh => model_size!(m, nmesh),
            ObjType::Material => model_size!(m, nmat),
            ObjType::Texture => model_size!(m, ntex),
            ObjType::Tendon => model_size!(m, ntendon),
            ObjType::Actuator => model_size!(m, nactuator),
            ObjType::Sensor => model_size!(m, nsensor),
            ObjType::Equality => model_size!(m, neq),
            ObjType::Key => model_size!(m, nkey),
        };
        let count = c_int::try_from(count).unwrap_or(0);
        (0..count)
            .map(|id| {
                // SAFETY: the model is live; `id` is in range for `obj`; MuJoCo returns
                // null or a NUL-terminated string inside the model's names buffer.
                let name = unsafe { sys::id2name(m, obj, id) };
                if name.is_null() {
                    String::new()
                } else {
                    // SAFETY: non-null, NUL-terminated, lives as long as the model.
                    unsafe { CStr::from_ptr(name) }
                        .to_string_lossy()
                        .into_owned()
                }
            })
            .collect()
    }

    /// The number of mesh vertices of the compiled model (`nmeshvert`), all meshes together.
    ///
    /// ```
    /// use std::path::Path;
    /// use mjcf_forge::mujoco::compile_str;
    ///
    /// let m = compile_str("<mujoco><worldbody><geom size='1'/></worldbody></mujoco>",
    ///                     Path::new(".")).unwrap();
    /// assert_eq!(m.mesh_vertex_count(), 0);
    /// ```
    pub fn mesh_vertex_count(&self) -> usize {
        model_size!(self.raw(), nmeshvert)
    }

    /// The compiler's warnings, if any (MuJoCo reports them in the error buffer of a
    /// successful `mj_loadXML`), joined by newlines as MuJoCo joins them.
    ///
    /// ```no_run
    /// use std::path::Path;
    /// use mjcf_forge::mujoco::compile_file;
    ///
    /// let model = compile_file(Path::new("arm.xml")).unwrap();
    /// if let Some(w) = model.warnings() {
    ///     eprintln!("MuJoCo warned: {w}");
    /// }
    /// ```
    pub fn warnings(&self) -> Option<&str> {
        self.warnings.as_deref()
    }
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

    #[test]
    fn json_key_order() {
        let json = Sizes::default().to_json();
        let keys: Vec<&str> = json
            .trim_matches(|c| c == '{' || c == '}')
            .split(',')
            .map(|kv| kv.split(':').next().unwrap().trim_matches('"'))
            .collect();
        assert_eq!(
            &keys[..9],
            [
                "nbody", "njnt", "ngeom", "nsite", "nu", "nsensor", "nq", "nv", "nmesh"
            ]
        );
        assert_eq!(keys.len(), Sizes::LEN);
    }
}

/// The calls into C: MuJoCo's own entry points whose signatures are plain C types, and
/// src/mujoco_shim.c for everything that needs a struct layout, a constant or an enum, which
/// build.rs compiles against the linked MuJoCo's headers, so nothing here knows a layout.
mod sys {
    use std::ffi::{CStr, c_char, c_int, c_void};
    use std::ptr::NonNull;

    use super::{Contact, ObjType};

    /// `mjModel`, opaque: only the shim and MuJoCo look inside.
    #[repr(C)]
    pub(super) struct Model {
        _opaque: [u8; 0],
    }

    /// `mjVFS`, opaque.
    #[repr(C)]
    struct RawVfs {
        _opaque: [u8; 0],
    }

    unsafe extern "C" {
        fn mj_version() -> c_int;
        fn mj_loadXML(
            filename: *const c_char,
            vfs: *const RawVfs,
            error: *mut c_char,
            error_sz: c_int,
        ) -> *mut Model;
        fn mj_deleteModel(m: *mut Model);
        fn mj_addBufferVFS(
            vfs: *mut RawVfs,
            name: *const c_char,
            buffer: *const c_void,
            nbuffer: c_int,
        ) -> c_int;
        fn mj_id2name(m: *const Model, kind: c_int, id: c_int) -> *const c_char;
        fn mjf_header_version() -> c_int;
        fn mjf_ngain() -> c_int;
        fn mjf_nbias() -> c_int;
        fn mjf_model_size(m: *const Model, name: *const c_char) -> i64;
        fn mjf_model_array(
            m: *const Model,
            name: *const c_char,
            elem_size: *mut usize,
        ) -> *const c_void;
        fn mjf_vfs_new() -> *mut RawVfs;
        fn mjf_vfs_free(vfs: *mut RawVfs);
        fn mjf_obj_type(kind: *const c_char) -> c_int;
        fn mjf_initial_contacts(
            m: *const Model,
            max: c_int,
            geom1: *mut c_int,
            geom2: *mut c_int,
            dist: *mut f64,
        ) -> c_int;
    }

    /// A size field of `mjModel` as `usize`.
    macro_rules! model_size {
        ($m:expr, $field:ident) => {
            crate::mujoco::sys::size($m, concat!(stringify!($field), "\0"))
        };
    }
    /// An array field of `mjModel` as a pointer to `$ty`.
    macro_rules! model_array {
        ($m:expr, $field:ident, $ty:ty) => {
            crate::mujoco::sys::array::<$ty>($m, concat!(stringify!($field), "\0"))
        };
    }
    pub(super) use {model_array, model_size};

    /// The size field `name` (NUL-terminated). A name this MuJoCo does not have is a bug of
    /// this module (the field lists are fixed): it panics, naming the field.
    pub(super) fn size(m: &Model, name: &'static str) -> usize {
        // SAFETY: `m` is live; `name` is NUL-terminated (the macros add the NUL).
        let v = unsafe { mjf_model_size(m, name.as_ptr().cast()) };
        usize::try_from(v).unwrap_or_else(|_| {
            panic!(
                "this MuJoCo's mjModel has no size field {}",
                name.trim_end_matches('\0')
            )
        })
    }

    /// The array field `name` (NUL-terminated) as `*const T`, checked against the element
    /// size MuJoCo's headers give; panics on a field this MuJoCo does not have.
    pub(super) fn array<T>(m: &Model, name: &'static str) -> *const T {
        let mut elem = 0usize;
        // SAFETY: `m` is live; `name` is NUL-terminated; `elem` is writable.
        let ptr = unsafe { mjf_model_array(m, name.as_ptr().cast(), &mut elem) };
        let field = name.trim_end_matches('\0');
        assert!(elem != 0, "this MuJoCo's mjModel has no array {field}");
        assert_eq!(
            elem,
            std::mem::size_of::<T>(),
            "mjModel.{field}: element size in MuJoCo's headers differs from ours"
        );
        ptr.cast()
    }

    /// `mjNGAIN`, the gain parameters per actuator, as the headers define it.
    pub(super) fn ngain() -> usize {
        // SAFETY: returns a constant of the headers the shim was compiled with.
        usize::try_from(unsafe { mjf_ngain() }).unwrap_or(0)
    }

    /// `mjNBIAS`, the bias parameters per actuator, as the headers define it.
    pub(super) fn nbias() -> usize {
        // SAFETY: returns a constant of the headers the shim was compiled with.
        usize::try_from(unsafe { mjf_nbias() }).unwrap_or(0)
    }

    /// A VFS owned by us, freed with `mj_deleteVFS`.
    pub(super) struct Vfs(NonNull<RawVfs>);

    impl Vfs {
        pub(super) fn new() -> Option<Vfs> {
            // SAFETY: returns null or a VFS initialised by `mj_defaultVFS`.
            NonNull::new(unsafe { mjf_vfs_new() }).map(Vfs)
        }

        /// Adds `bytes` (`len` of them) under `name`; MuJoCo's return code.
        pub(super) fn add_buffer(&mut self, name: &CStr, bytes: &[u8], len: c_int) -> c_int {
            // SAFETY: the VFS is live and ours; `name` is NUL-terminated; MuJoCo copies
            // `len` (= `bytes.len()`) bytes before returning.
            unsafe { mj_addBufferVFS(self.0.as_ptr(), name.as_ptr(), bytes.as_ptr().cast(), len) }
        }
    }

    impl Drop for Vfs {
        fn drop(&mut self) {
            // SAFETY: made by `mjf_vfs_new`, freed once, here.
            unsafe { mjf_vfs_free(self.0.as_ptr()) }
        }
    }

    /// # Safety
    /// As `mj_loadXML`: `err` holds `err_len` writable bytes.
    pub(super) unsafe fn load_xml(
        path: &CStr,
        vfs: Option<&Vfs>,
        err: *mut c_char,
        err_len: c_int,
    ) -> *mut Model {
        let vfs = vfs.map_or(std::ptr::null(), |v| v.0.as_ptr().cast_const());
        // SAFETY: see the caller's contract; `vfs` is null or live.
        unsafe { mj_loadXML(path.as_ptr(), vfs, err, err_len) }
    }

    /// # Safety
    /// `m` came from [`load_xml`] and is not used afterwards.
    pub(super) unsafe fn delete_model(m: *mut Model) {
        // SAFETY: see the contract.
        unsafe { mj_deleteModel(m) }
    }

    pub(super) fn linked_version() -> c_int {
        // SAFETY: `mj_version` only returns a constant.
        unsafe { mj_version() }
    }

    pub(super) fn header_version() -> c_int {
        // SAFETY: returns a constant of the headers the shim was compiled with.
        unsafe { mjf_header_version() }
    }

    /// # Safety
    /// `id` is in range for `obj` in the live model `m`.
    pub(super) unsafe fn id2name(m: &Model, obj: ObjType, id: c_int) -> *const c_char {
        let kind = format!("{}\0", obj.as_str());
        // SAFETY: `kind` is NUL-terminated.
        let code = unsafe { mjf_obj_type(kind.as_ptr().cast()) };
        // SAFETY: see the contract; `code` is MuJoCo's own mjtObj value.
        unsafe { mj_id2name(m, code, id) }
    }

    pub(super) fn initial_contacts(m: &Model) -> Vec<Contact> {
        let mut cap = 64;
        loop {
            let (mut g1, mut g2, mut dist) = (vec![0; cap], vec![0; cap], vec![0.0; cap]);
            // SAFETY: `m` is live; the three buffers hold `cap` elements each.
            let n = unsafe {
                mjf_initial_contacts(
                    m,
                    c_int::try_from(cap).unwrap_or(c_int::MAX),
                    g1.as_mut_ptr(),
                    g2.as_mut_ptr(),
                    dist.as_mut_ptr(),
                )
            };
            let Ok(n) = usize::try_from(n) else {
                return Vec::new();
            };
            if n <= cap {
                return (0..n)
                    .map(|i| Contact {
                        geom1: usize::try_from(g1[i]).unwrap_or(usize::MAX),
                        geom2: usize::try_from(g2[i]).unwrap_or(usize::MAX),
                        dist: dist[i],
                    })
                    .collect();
            }
            cap = n;
        }
    }
}
