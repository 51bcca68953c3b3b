//! Errors: one type, positioned at `file:line:col`, with the include chain that led there.
//!
//! Below every tier (each reports through it), so it uses nothing of the crate.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where something is in the sources: a file, a 1-based line and column, and the chain of
/// `<include>` elements through which that file was reached (outermost first); or, for a
/// description that has no text of its own (a scene given as a Python `dict`), the key path
/// of the value (`objects[0].placement.x`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The file, as it was named to us (absolute for included files).
    pub file: Arc<Path>,
    /// 1-based line.
    pub line: u32,
    /// 1-based column, counted in bytes.
    pub col: u32,
    /// The `<include>` elements that led to `file`, outermost first.
    pub included_from: Vec<(Arc<Path>, u32, u32)>,
    /// The key path of the value in a structured description (`objects[0].placement.x`;
    /// empty for the whole description), shown instead of the line and column, which are
    /// then those of the text the description was read as and serve only for ordering.
    /// (An `Arc<String>`, one pointer wide: an `Error` stays small enough to return.)
    pub key: Option<Arc<String>>,
}

impl Location {
    /// A location with no include chain.
    pub fn new(file: Arc<Path>, line: u32, col: u32) -> Location {
        Location {
            file,
            line,
            col,
            included_from: Vec::new(),
            key: None,
        }
    }
}

impl fmt::Display for Location {
    /// `file:line:col`, or `file: key.path` for a location given by its key path.
    ///
    /// ```
    /// use std::{path::Path, sync::Arc};
    /// let mut at = mjcf_forge::Location::new(Arc::from(Path::new("<scene dict>")), 9, 3);
    /// assert_eq!(at.to_string(), "<scene dict>:9:3");
    /// at.key = Some(Arc::new("objects[0].placement.x".to_string()));
    /// assert_eq!(at.to_string(), "<scene dict>: objects[0].placement.x");
    /// ```
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.key.as_deref().map(String::as_str) {
            Some("") => write!(f, "{}", self.file.display()),
            Some(key) => write!(f, "{}: {key}", self.file.display()),
            None => write!(f, "{}:{}:{}", self.file.display(), self.line, self.col),
        }
    }
}

/// What went wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// A file could not be read.
    Io {
        /// The path we tried.
        path: PathBuf,
        /// The operating system's words.
        reason: String,
    },
    /// The XML itself is malformed.
    Syntax(String),
    /// The document is not MJCF (wrong root element and the like).
    NotMjcf(String),
    /// `<include>` without a `file` attribute.
    IncludeWithoutFile,
    /// A nested `<include>` whose file is neither beside the main file nor beside the file
    /// that includes it (the two places MuJoCo looks, in that order).
    IncludeNotFound {
        /// The path beside the main file, as the user would name it.
        beside_main: PathBuf,
        /// The path beside the including file.
        beside_includer: PathBuf,
        /// The operating system's words about the second one.
        reason: String,
    },
    /// An included file is part of its own include chain.
    IncludeCycle {
        /// The chain of files, outermost first, ending with the repeated one.
        chain: Vec<PathBuf>,
    },
    /// The same file is included twice (MuJoCo refuses that too).
    IncludedTwice(PathBuf),
    /// An included file inserts no element.
    EmptyInclude(PathBuf),
    /// `class` or `childclass` names no default class.
    UnknownClass(String),
    /// Two default classes share a name.
    RepeatedClass(String),
    /// A top-level `<default>` with a class other than `main`.
    RenamedMainClass(String),
    /// A default class would change the compiled model in a way MJCF cannot write
    /// without classes.
    Inexpressible(String),
    /// Any other problem with the model, in words.
    Invalid(String),
    /// Writing an output file failed.
    Write {
        /// The output path.
        path: PathBuf,
        /// The operating system's words.
        reason: String,
    },
    /// MuJoCo refused to compile a scene's variant (`ModelCache`).
    Compile {
        /// The variant's index.
        variant: u64,
        /// MuJoCo's words.
        message: String,
    },
    /// A model handed to `ModelCache::apply` is not of the variant's structure.
    OtherStructure {
        /// The variant's index.
        variant: u64,
        /// The variant's structure key.
        key: String,
        /// The model's structure key, where the cache patched it before.
        found: Option<String>,
    },
    /// A call that needs a superset cache (`ModelCache::with_superset`) on a plain one.
    NeedsSuperset,
    /// A batch of worlds with no variant.
    NoWorlds,
    /// An element's geometry cannot be read the way MuJoCo's compiler reads it (the
    /// geometry functions, `XmlModel::try_offsets`): a malformed number or orientation, an
    /// `eulerseq` or `angle` MuJoCo refuses, a mesh file that cannot be read, a subtree
    /// with no measurable geom, a model with no root body to measure. In words that name
    /// the element and end with its `file:line:col` (which is why the error's `location`
    /// stays empty).
    ///
    /// ```
    /// use mjcf_forge::geometry::{element_pose, Angles};
    /// let doc = mjcf_forge::Document::from_str(
    ///     "<mujoco><worldbody><geom name='g' size='1' pos='0 x 0'/></worldbody></mujoco>", ".")?;
    /// let geom = doc.descendants(doc.root()).find(|&n| doc.tag(n) == "geom").unwrap();
    /// let e = element_pose(&doc, geom, &Angles::default()).unwrap_err();
    /// assert!(matches!(e.kind, mjcf_forge::ErrorKind::Geometry(_)));
    /// assert_eq!(e.to_string(), "<geom name=\"g\">: attribute 'pos': 'x' is not a number at <string>:1:20");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    Geometry(String),
    /// MuJoCo refused to compile the text of a scene's variant that
    /// `scene::check_variant` was given.
    CheckCompile {
        /// The variant's index.
        variant: u64,
        /// MuJoCo's words.
        message: String,
    },
    /// Two geoms of a variant interpenetrate at its initial pose, one of them of a placed
    /// object (`scene::check_model`, `scene::check_variant`), deeper than
    /// `scene::PENETRATION_TOLERANCE`. Boxed: an `Error` stays small enough to return.
    ///
    /// ```
    /// use mjcf_forge::{Error, ErrorKind, Interpenetration};
    /// let e = Error {
    ///     location: None,
    ///     kind: ErrorKind::Interpenetration(Box::new(Interpenetration {
    ///         variant: 4,
    ///         geoms: ["g".into(), "#7".into()],
    ///         bodies: ["0_box".into(), "table".into()],
    ///         depth_mm: "1.250".into(),
    ///     })),
    /// };
    /// assert_eq!(
    ///     e.to_string(),
    ///     "variant 4: geom g of '0_box' interpenetrates geom #7 of 'table' by 1.250 mm at the initial pose"
    /// );
    /// ```
    Interpenetration(Box<Interpenetration>),
    /// A camera name that the model does not have (`preview::Camera::named`).
    UnknownCamera {
        /// The name asked for.
        name: String,
        /// The model's named cameras, in their order (empty when it has none).
        cameras: Vec<String>,
    },
    /// A geom set that is not one of `default`, `visual`, `collision`, `all`
    /// (`sheet::Geoms` from text).
    UnknownGeoms(String),
    /// A part compiled alone for its masses and inertias was refused (an
    /// `InertiaCompiler`'s words: MuJoCo's, or the caller's compiler's).
    InertiaCompile(String),
    /// A patch cannot be made or written over a compiled model (the split tier's
    /// functions: `split::PatchPlan`, `split::land`, the body-model copies, geom masses
    /// and tree derivations): the model's arrays are not of the plan's structure, or the
    /// face's model (`split::PatchModel` and the other traits the faces implement) refused
    /// a call. In the plan's or the face's words. The faces' caches take it for "not this
    /// structure" and compile the variant instead where they can.
    ///
    /// ```
    /// let e = mjcf_forge::split::body_mass(&[]).unwrap_err();
    /// assert_eq!(e.kind, mjcf_forge::ErrorKind::Patch("no geom counts for its inertia".into()));
    /// ```
    Patch(String),
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::Io { path, reason } => {
                write!(f, "cannot read '{}': {reason}", path.display())
            }
            ErrorKind::Syntax(msg) => write!(f, "malformed XML: {msg}"),
            ErrorKind::NotMjcf(msg) => write!(f, "not an MJCF model: {msg}"),
            ErrorKind::IncludeWithoutFile => write!(f, "<include> needs a 'file' attribute"),
            ErrorKind::IncludeNotFound {
                beside_main,
                beside_includer,
                reason,
            } => write!(
                f,
                "cannot read '{}' (beside the main file) nor '{}' (beside the including file): {reason}",
                beside_main.display(),
                beside_includer.display()
            ),
            ErrorKind::IncludeCycle { chain } => {
                let names: Vec<String> = chain.iter().map(|p| p.display().to_string()).collect();
                write!(f, "include cycle: {}", names.join(" -> "))
            }
            ErrorKind::IncludedTwice(p) => {
                write!(
                    f,
                    "file '{}' is already included (MuJoCo allows each file once)",
                    p.display()
                )
            }
            ErrorKind::EmptyInclude(p) => {
                write!(f, "included file '{}' inserts no element", p.display())
            }
            ErrorKind::UnknownClass(c) => write!(f, "unknown default class '{c}'"),
            ErrorKind::RepeatedClass(c) => write!(f, "repeated default class name '{c}'"),
            ErrorKind::RenamedMainClass(c) => {
                write!(
                    f,
                    "top-level default class 'main' cannot be renamed (found '{c}')"
                )
            }
            ErrorKind::Inexpressible(msg) => write!(f, "cannot inline defaults exactly: {msg}"),
            ErrorKind::Invalid(msg) => f.write_str(msg),
            ErrorKind::Write { path, reason } => {
                write!(f, "cannot write '{}': {reason}", path.display())
            }
            ErrorKind::Compile { variant, message } => {
                write!(f, "variant {variant}: MuJoCo: {message}")
            }
            ErrorKind::OtherStructure {
                variant,
                key,
                found: Some(found),
            } => write!(
                f,
                "the model has structure {found}, variant {variant} has {key}: a patch cannot \
                 change a structure (ModelCache::model compiles it)"
            ),
            ErrorKind::OtherStructure {
                variant,
                key,
                found: None,
            } => write!(
                f,
                "the model does not have the structure of variant {variant} (key {key}): its \
                 sizes or names differ"
            ),
            ErrorKind::NeedsSuperset => {
                f.write_str("per-world arrays need ModelCache::with_superset")
            }
            ErrorKind::NoWorlds => {
                f.write_str("a batch needs at least one world: no variant was given (0 worlds)")
            }
            ErrorKind::Geometry(msg) => f.write_str(msg),
            ErrorKind::CheckCompile { variant, message } => {
                write!(f, "variant {variant}: {message}")
            }
            ErrorKind::Interpenetration(i) => write!(
                f,
                "variant {}: geom {} of '{}' interpenetrates geom {} of '{}' by \
                 {} mm at the initial pose",
                i.variant, i.geoms[0], i.bodies[0], i.geoms[1], i.bodies[1], i.depth_mm
            ),
            ErrorKind::UnknownCamera { name, cameras } => {
                write!(f, "the model has no camera named '{name}' (")?;
                if cameras.is_empty() {
                    f.write_str("it has no named camera)")
                } else {
                    write!(f, "its cameras: {})", cameras.join(", "))
                }
            }
            ErrorKind::Patch(msg) => f.write_str(msg),
            ErrorKind::InertiaCompile(msg) => f.write_str(msg),
            ErrorKind::UnknownGeoms(s) => {
                write!(
                    f,
                    "unknown geom set '{s}' (default, visual, collision, all)"
                )
            }
        }
    }
}

/// Which two geoms of a variant interpenetrate, and how deep ([`ErrorKind::Interpenetration`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Interpenetration {
    /// The variant's index.
    pub variant: u64,
    /// The two geoms: each its name, or `#id` when it has none.
    pub geoms: [String; 2],
    /// The root bodies of the two geoms, in the same order.
    pub bodies: [String; 2],
    /// How deep, in millimetres with three decimals, as the message prints it (text, so
    /// that the kind stays `Eq`).
    pub depth_mm: String,
}

/// An error with its position: `Display` gives `file:line:col: message`, followed by the
/// include chain when the position is inside an included file.
///
/// ```
/// use mjcf_forge::Document;
/// let err = Document::from_str("<mujoco><worldbody><geom class='x'/></worldbody></mujoco>", ".")
///     .unwrap_err();
/// assert_eq!(err.to_string(), "<string>:1:20: unknown default class 'x'");
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    /// Where; `None` for problems that are not in any file (such as an unreadable top file).
    pub location: Option<Location>,
    /// What.
    pub kind: ErrorKind,
}

impl Error {
    /// An error of `kind` that is in no file: what an [`InertiaCompiler`](crate::InertiaCompiler)
    /// of the caller's returns when its compile fails.
    ///
    /// ```
    /// use mjcf_forge::{Error, ErrorKind};
    /// let e = Error::new(ErrorKind::InertiaCompile("no MuJoCo here".into()));
    /// assert_eq!((e.to_string(), e.location), ("no MuJoCo here".to_string(), None));
    /// ```
    pub fn new(kind: ErrorKind) -> Error {
        Error::bare(kind)
    }

    pub(crate) fn at(location: Location, kind: ErrorKind) -> Error {
        Error {
            location: Some(location),
            kind,
        }
    }

    pub(crate) fn bare(kind: ErrorKind) -> Error {
        Error {
            location: None,
            kind,
        }
    }
}

/// What a load did that MuJoCo would warn about, at its place: MuJoCo's own URDF importer
/// warns about the same inputs (with the same message), and builds the same model.
///
/// ```
/// use mjcf_forge::{Document, UrdfOptions, UrdfImporter};
/// let urdf = r#"<robot name="r"><link name="a"/>
///   <link name="b"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
///   <joint name="j" type="revolute"><parent link="a"/><child link="b"/><limit lower="1" upper="1"/></joint>
/// </robot>"#;
/// let opts = UrdfOptions { importer: UrdfImporter::MuJoCo4, ..UrdfOptions::default() };
/// let doc = Document::from_urdf_str(urdf, ".", &opts)?;
/// assert_eq!(
///     doc.warnings()[0].to_string(),
///     "<string>:3:70: joint 'j' has equal lower and upper limits, limit ignored"
/// );
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Warning {
    /// Where the input MuJoCo warns about is.
    pub location: Location,
    /// MuJoCo's message.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.location, self.message)
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.location {
            Some(loc) => {
                write!(f, "{loc}: {}", self.kind)?;
                for (file, line, col) in loc.included_from.iter().rev() {
                    write!(f, " (included from {}:{line}:{col})", file.display())?;
                }
                Ok(())
            }
            None => write!(f, "{}", self.kind),
        }
    }
}

impl std::error::Error for Error {}

/// All problems found by one pass, in document order. `Display` writes one per line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Errors(pub Vec<Error>);

impl Errors {
    /// The first problem.
    pub fn first(&self) -> &Error {
        &self.0[0]
    }
}

impl fmt::Display for Errors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Errors {}

impl From<Error> for Errors {
    fn from(e: Error) -> Errors {
        Errors(vec![e])
    }
}
