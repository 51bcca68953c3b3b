//! `Document`, `Element` and `Attrib`: the document tier, with elements that behave as
//! `xml.etree.ElementTree` elements over the arena (see STYLE.md, "ElementTree over a
//! native tree").
//!
//! - `cell.rs`: the shared, lockable document and the registry of one proxy per node;
//! - `element.rs`: `Element`, the proxy; `children.rs`, `path.rs`, `attrib.rs` its child
//!   edits, ElementPath and live attribute mapping;
//! - `load_cache.rs`: `LoadCache`, loaded files served again while unchanged;
//! - `values.rs`: attribute values from Python, and the checks of what XML can carry.
//!
//! A `Document` is one cell: Python threads may share it, readers run at once, and an
//! `Element` keeps its document alive by holding the cell. Locks are only held by Rust
//! code that never waits for the GIL while holding one.

mod attrib;
mod cell;
mod children;
mod element;
mod etree_text;
mod inertia;
mod load_cache;
pub(crate) mod patch;
mod path;
mod sort;
pub(crate) mod urdf;
mod values;

use std::path::PathBuf;
use std::sync::Arc;

use ahash::AHashSet;
use mjcf_forge::split::{SplitOptions, split_document_with};
use mjcf_forge::{Document, MergePart, Node, Section};
use pyo3::exceptions::{PyFutureWarning, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};

use crate::errors::{Failure, run};
pub(crate) use patch::PyDocumentSplit;
use patch::patch_list;

pub(crate) use attrib::PyAttrib;
pub(crate) use cell::{DocCell, retarget};
pub(crate) use element::PyElement;
pub(crate) use inertia::python_inertia;
pub(crate) use load_cache::PyLoadCache;
pub(crate) use values::check_xml_text;

/// The document's split as Python's `DocumentCache` takes it: sizes of primitive geoms
/// patched through their body models, which it compiles.
fn split(doc: &Document) -> mjcf_forge::split::DocumentPatch {
    split_document_with(doc, SplitOptions { body_models: true })
}

/// A shared, lockable document.
pub(crate) type SharedDoc = Arc<DocCell>;

/// An MJCF model as MuJoCo reads it: ``<include>`` expanded, default classes inlined
/// into explicit attributes, asset file paths absolute.
///
/// Load one with :meth:`Document.load` or :meth:`Document.from_string` (a URDF robot too,
/// as the installed ``mujoco`` imports it; :meth:`Document.from_urdf` with options); edit
/// it in place (:meth:`prefix`, :meth:`merge`, element attributes); write it with
/// :meth:`to_xml` or :meth:`write`. Safe to share between threads; loading, writing,
/// prefixing, merging and validating release the GIL.
///
/// Example::
///
///     doc = Document.load("panda.xml")
///     doc.prefix("robot0_")
///     hand = doc.find_named("body", "robot0_right_hand")
///     hand.attrib["pos"] = "0 0 0.1"
///     joints = doc.findall(".//joint")
///     doc.write("out.xml")
#[pyclass(name = "Document", module = "mjcf_forge", frozen)]
pub(crate) struct PyDocument {
    pub(crate) doc: SharedDoc,
}

impl PyDocument {
    pub(crate) fn new(doc: Document) -> PyDocument {
        PyDocument {
            doc: DocCell::new(doc),
        }
    }

    /// A copy of the Rust document (for parts that are merged or wrapped by a model).
    pub(crate) fn snapshot(&self, py: Python<'_>) -> Document {
        self.doc.read(py).clone()
    }
}

/// What a merge did besides merging.
#[pyclass(name = "MergeReport", module = "mjcf_forge", frozen, get_all)]
pub(crate) struct PyMergeReport {
    /// One line per part setting the base overrode or adjusted (``option``, ``size``,
    /// ``visual``, ``statistic`` conflicts), each with its position in the part.
    warnings: Vec<String>,
    /// How many of the part's assets were already in the base (same tag, name and
    /// content) and are shared rather than copied.
    shared_assets: usize,
}

#[pymethods]
impl PyMergeReport {
    fn __repr__(&self) -> String {
        format!(
            "MergeReport(warnings={:?}, shared_assets={})",
            self.warnings, self.shared_assets
        )
    }
}

impl From<mjcf_forge::MergeReport> for PyMergeReport {
    fn from(report: mjcf_forge::MergeReport) -> PyMergeReport {
        PyMergeReport {
            warnings: report.warnings,
            shared_assets: report.shared_assets,
        }
    }
}

#[pymethods]
impl PyDocument {
    /// Loads an MJCF file (``str`` or path-like) as MuJoCo reads it.
    ///
    /// A URDF file (root element ``<robot>``) is read as the installed ``mujoco``'s URDF
    /// importer reads it (3.x or 4.x; 4.0.0's when ``mujoco`` cannot be imported), into the
    /// MJCF model it compiles to: :meth:`from_urdf` with its defaults.
    ///
    /// Raises :class:`MjcfError` with every problem found (``file:line:col: message``).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyDocument> {
        let urdf = if py.detach(|| urdf::is_urdf_file(&path)) {
            Some(urdf::plain_options(py)?)
        } else {
            None
        };
        run(py, move || {
            Ok(match urdf {
                Some(options) => Document::load_urdf(&path, &options)?,
                None => Document::load(&path)?,
            })
        })
        .and_then(|d| loaded(py, d))
    }

    /// Reads MJCF text. ``base_dir`` plays the part of the main file's folder: includes and
    /// asset files are found from there (default: the current folder). Positions in errors
    /// name ``<string>``. URDF text (root element ``<robot>``) is read as :meth:`load`
    /// reads a URDF file.
    #[staticmethod]
    #[pyo3(signature = (xml, base_dir = None))]
    fn from_string(py: Python<'_>, xml: &str, base_dir: Option<PathBuf>) -> PyResult<PyDocument> {
        let urdf = if urdf::is_urdf_text(xml) {
            Some(urdf::plain_options(py)?)
        } else {
            None
        };
        let xml = xml.to_owned();
        let base_dir = base_dir.unwrap_or_else(|| PathBuf::from("."));
        run(py, move || {
            Ok(match urdf {
                Some(options) => Document::from_urdf_str(&xml, &base_dir, &options)?,
                None => Document::from_str(&xml, &base_dir)?,
            })
        })
        .and_then(|d| loaded(py, d))
    }

    /// Loads a URDF robot (``str`` or path-like; a ``.xacro`` file is expanded with the
    /// ``xacro`` command first) as the MJCF model MuJoCo's URDF importer compiles it to,
    /// with options that go beyond the importer. With the defaults the document compiles
    /// to exactly the model ``mujoco.MjModel.from_xml_path(path)`` gives.
    ///
    /// - ``visuals``: keep each ``<visual>`` as a geom of group 1 with no mass and no
    ///   contacts (``contype=conaffinity=0``), its URDF material as a MuJoCo material.
    ///   The importer drops them; the collision model is the same either way. A visual
    ///   whose mesh MuJoCo cannot read (COLLADA ``.dae``) or that is missing is an error.
    /// - ``fuse_static``: fuse links joined by ``fixed`` joints into their parents, as
    ///   the importer does (``fusestatic``); ``False`` keeps every link a body.
    /// - ``keep_links``: names of links kept as bodies even when static links are fused
    ///   (a gripper mount, a camera frame).
    /// - ``packages``: ``{package name: folder}`` for ``package://NAME/...`` mesh paths,
    ///   looked up first; then ``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH``
    ///   (``share/NAME``), then the folders above the URDF (one named ``NAME``, or with a
    ///   ``package.xml`` naming it). ``resolve_packages=False`` leaves such paths as
    ///   MuJoCo reads them (it cannot open them).
    /// - ``actuators``: one actuator per hinge and slide joint, named after it:
    ///   ``{"type": "position", "kp": 100, "kv": 10}`` (control range from the joint's
    ///   ``<limit lower upper>``), ``{"type": "velocity", "kv": 5}`` (``±velocity``) or
    ///   ``{"type": "motor"}`` (``±effort``); position and velocity actuators take the
    ///   force range ``±effort``. The importer writes none.
    /// - ``importer``: the MuJoCo version whose importer to follow where 3.x and 4.x
    ///   differ (a ``continuous`` joint's ``<limit lower upper>`` limits it in 3.x only):
    ///   ``"3.17.0"``, ``"4.0.0"``; by default the installed ``mujoco``'s version, or
    ///   4.0.0 when ``mujoco`` cannot be imported.
    ///
    /// Raises :class:`MjcfError` with every problem found (``file:line:col: message``),
    /// among them a ``package://`` path whose package is found nowhere, and a file that
    /// is not URDF (use :meth:`load`).
    ///
    /// Example::
    ///
    ///     arm = Document.from_urdf(
    ///         "kuka_iiwa/model.urdf",
    ///         visuals=True,
    ///         packages={"iiwa_description": "/opt/ros/share/iiwa_description"},
    ///         actuators={"type": "position", "kp": 100, "kv": 10},
    ///     )
    ///     arm.write("kuka.xml")
    ///     model = mujoco.MjModel.from_xml_string(arm.to_xml())
    #[staticmethod]
    #[pyo3(
        text_signature = "(path, *, visuals=False, fuse_static=True, keep_links=(), \
        packages=None, resolve_packages=True, actuators=None, importer=None)"
    )]
    #[pyo3(signature = (
        path,
        *,
        visuals = false,
        fuse_static = true,
        keep_links = None,
        packages = None,
        resolve_packages = true,
        actuators = None,
        importer = None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn from_urdf(
        py: Python<'_>,
        path: PathBuf,
        visuals: bool,
        fuse_static: bool,
        keep_links: Option<&Bound<'_, PyAny>>,
        packages: Option<&Bound<'_, PyAny>>,
        resolve_packages: bool,
        actuators: Option<&Bound<'_, PyAny>>,
        importer: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyDocument> {
        let options = urdf::UrdfArgs {
            caller: "from_urdf",
            visuals,
            fuse_static,
            keep_links,
            packages,
            resolve_packages,
            actuators,
            importer,
        }
        .options(py)?;
        run(py, move || {
            urdf::check_urdf_file(&path)?;
            Ok(Document::load_urdf(&path, &options)?)
        })
        .and_then(|d| loaded(py, d))
    }

    /// URDF text read as :meth:`from_urdf` reads a file, with the same options;
    /// ``base_dir`` plays the part of the file's folder (relative mesh paths and the
    /// search for packages start there; default: the current folder). Positions in errors
    /// name ``<string>``.
    ///
    /// >>> from mjcf_forge import Document
    /// >>> urdf = '''<robot name="r">
    /// ...   <link name="base"/>
    /// ...   <link name="arm">
    /// ...     <inertial><mass value="1"/>
    /// ...       <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    /// ...     <visual><geometry><sphere radius="0.1"/></geometry></visual>
    /// ...     <collision><geometry><sphere radius="0.1"/></geometry></collision>
    /// ...   </link>
    /// ...   <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    /// ...     <limit lower="-1" upper="1" effort="5"/></joint>
    /// ... </robot>'''
    /// >>> len(Document.from_urdf_string(urdf).findall(".//geom"))  # the importer drops visuals
    /// 1
    /// >>> doc = Document.from_urdf_string(urdf, visuals=True, actuators={"type": "motor"})
    /// >>> [g.get("group") for g in doc.iter("geom")]  # the link's elements in file order
    /// ['1', None]
    /// >>> doc.find("actuator/motor").attrib
    /// {'name': 'j', 'joint': 'j', 'ctrlrange': '-5 5'}
    #[staticmethod]
    #[pyo3(
        text_signature = "(xml, base_dir=None, *, visuals=False, fuse_static=True, \
        keep_links=(), packages=None, resolve_packages=True, actuators=None, importer=None)"
    )]
    #[pyo3(signature = (
        xml,
        base_dir = None,
        *,
        visuals = false,
        fuse_static = true,
        keep_links = None,
        packages = None,
        resolve_packages = true,
        actuators = None,
        importer = None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn from_urdf_string(
        py: Python<'_>,
        xml: &str,
        base_dir: Option<PathBuf>,
        visuals: bool,
        fuse_static: bool,
        keep_links: Option<&Bound<'_, PyAny>>,
        packages: Option<&Bound<'_, PyAny>>,
        resolve_packages: bool,
        actuators: Option<&Bound<'_, PyAny>>,
        importer: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyDocument> {
        let options = urdf::UrdfArgs {
            caller: "from_urdf_string",
            visuals,
            fuse_static,
            keep_links,
            packages,
            resolve_packages,
            actuators,
            importer,
        }
        .options(py)?;
        let xml = xml.to_owned();
        let base_dir = base_dir.unwrap_or_else(|| PathBuf::from("."));
        run(py, move || {
            urdf::check_urdf_text(&xml)?;
            Ok(Document::from_urdf_str(&xml, &base_dir, &options)?)
        })
        .and_then(|d| loaded(py, d))
    }

    /// The document as XML text: compact (no white space between elements) by default,
    /// indented by two spaces a level with ``pretty=True`` (what :meth:`write` writes and
    /// what ``mjcf-forge inline`` prints).
    #[pyo3(signature = (pretty = false))]
    fn to_xml(&self, py: Python<'_>, pretty: bool) -> PyResult<String> {
        run(py, || {
            let doc = self.doc.read_detached();
            Ok(if pretty {
                doc.to_pretty_string()
            } else {
                doc.to_xml_string()
            })
        })
    }

    /// Writes the indented XML to ``path`` atomically: through a temporary file in the
    /// same folder and a rename, so a failure never leaves a partial or clobbered file.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        run(py, || Ok(self.doc.read_detached().write_file(&path)?))
    }

    /// Prefixes every name in place (bodies, joints, geoms, assets, classes, ...) and every
    /// reference to it, following MuJoCo's schema; references to ``world`` stay.
    ///
    /// ``exclude`` keeps names as they are, where declared and wherever referenced (in
    /// every namespace): a collection of names, or a callable ``exclude(name) -> bool``,
    /// asked once for each distinct name the prefix would rename, in sorted order (with no
    /// lock held, so it may read this document).
    #[pyo3(signature = (prefix, *, exclude = None))]
    fn prefix(
        &self,
        py: Python<'_>,
        prefix: &str,
        exclude: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        check_xml_text("prefix", prefix)?;
        let prefix = prefix.to_owned();
        let keep: AHashSet<String> = match exclude {
            None => AHashSet::new(),
            Some(f) if f.is_callable() => {
                // The names the prefix would rename, found on a copy (so that the callable
                // runs with no lock of ours held), then asked about one by one.
                let names = run(py, || {
                    let mut copy = self.doc.read_detached().clone();
                    let seen = std::cell::RefCell::new(AHashSet::new());
                    copy.apply_prefix_except(&prefix, |_, name| {
                        seen.borrow_mut().insert(name.to_owned());
                        false
                    })?;
                    let mut names: Vec<String> = seen.into_inner().into_iter().collect();
                    // Asked in a fixed order: the callable may have side effects.
                    names.sort_unstable();
                    Ok(names)
                })?;
                let mut keep = AHashSet::new();
                for name in names {
                    if f.call1((name.as_str(),))?.is_truthy()? {
                        keep.insert(name);
                    }
                }
                keep
            }
            Some(names) => {
                if names.is_instance_of::<PyString>() {
                    return Err(PyTypeError::new_err(
                        "prefix(..., exclude=...): a collection of names or a callable, not a str",
                    ));
                }
                names
                    .try_iter()?
                    .map(|n| n?.extract::<String>())
                    .collect::<PyResult<_>>()?
            }
        };
        run(py, || {
            Ok(self
                .doc
                .write_detached()
                .apply_prefix_except(&prefix, |_, name| keep.contains(name))?)
        })
    }

    /// Merges ``other`` into this document, in place: its worldbody children into the
    /// world (``body=None``) or into the body named ``body``, every other section carried
    /// over (identical assets shared, compiler settings converted where exact). ``other``
    /// may be a list of documents, merged in order with every name checked once.
    ///
    /// Handles to the parts' elements follow them: afterwards they stand for (read and
    /// change) their copies in this document, as if the elements had moved; the parts
    /// themselves are left as they were.
    ///
    /// ``worldbody=False`` leaves the parts' worldbody children out (every other section is
    /// merged). ``fuse_keys`` makes a part's keyframe ``part_prefix + N`` one with this
    /// document's key ``N`` (``part_prefix``: the prefix the parts' names carry).
    ///
    /// ``compile_inertia``: a callable ``compile_inertia(xml, model_dir)`` returning
    /// ``(body_names, body_mass, body_ipos, body_iquat, body_inertia)`` (the arrays
    /// flattened, by body id, the world body first) as MuJoCo compiles the MJCF text
    /// ``xml`` alone. A part whose compiler settings for masses and inertias
    /// (``inertiagrouprange``, ``settotalmass``, ...) differ from this document's is then
    /// converted exactly: each body's compiled inertia is written out as an explicit
    /// ``<inertial>`` before the merge. Without it such a part is refused. It is called
    /// only for such parts, while this document is locked: it must not use this document.
    ///
    /// Returns a :class:`MergeReport`; raises :class:`MjcfError` (all name clashes at
    /// once, with positions), leaving this document unchanged.
    #[pyo3(signature = (
        other,
        body = None,
        *,
        fuse_keys = false,
        part_prefix = None,
        worldbody = true,
        compile_inertia = None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn merge(
        &self,
        py: Python<'_>,
        other: &Bound<'_, PyAny>,
        body: Option<String>,
        fuse_keys: bool,
        part_prefix: Option<String>,
        worldbody: bool,
        compile_inertia: Option<Py<PyAny>>,
    ) -> PyResult<PyMergeReport> {
        let others: Vec<Bound<'_, PyDocument>> = if let Ok(d) = other.cast::<PyDocument>() {
            vec![d.clone()]
        } else {
            let list: Vec<Bound<'_, PyAny>> = other.extract().map_err(|_| {
                PyTypeError::new_err(
                    "merge(other, ...): other is a Document or a list of Documents",
                )
            })?;
            list.into_iter()
                .map(|d| {
                    d.cast_into::<PyDocument>()
                        .map_err(|_| PyTypeError::new_err("merge: every part must be a Document"))
                })
                .collect::<PyResult<_>>()?
        };
        if let Some(f) = &compile_inertia
            && !f.bind(py).is_callable()
        {
            return Err(PyTypeError::new_err(
                "merge(..., compile_inertia=...): a callable",
            ));
        }
        let prefix = part_prefix.unwrap_or_default();
        let cells: Vec<SharedDoc> = others.iter().map(|d| d.get().doc.clone()).collect();
        let out = run(py, || {
            // Copies of the parts first: one may be this very document (merging a model
            // with itself), and two locks on one RwLock would deadlock. A copy keeps every
            // node's handle, so the maps name the parts' own nodes.
            let parts: Vec<Document> = cells
                .iter()
                .map(|c| {
                    let mut part = c.read_detached().clone();
                    if !worldbody && let Some(world) = part.find_section(Section::Worldbody) {
                        let children: Vec<Node> = part.elements(world).collect();
                        for child in children {
                            part.remove(child);
                        }
                    }
                    part
                })
                .collect();
            let parts: Vec<MergePart<'_>> = parts
                .iter()
                .map(|part| MergePart {
                    doc: part,
                    into: body.as_deref(),
                    prefix: &prefix,
                })
                .collect();
            let mut doc = self.doc.write_detached();
            // Merge into a copy so that a refused merge leaves the document as it was (a
            // copy keeps every node's handle, so elements of this document stay valid).
            let mut merged = doc.clone();
            let out = match &compile_inertia {
                None => merged.merge_all_mapped(&parts, fuse_keys)?,
                Some(f) => {
                    let mut compile = |part: &Document| python_inertia(f, part);
                    merged.merge_all_mapped_with(&parts, fuse_keys, &mut compile)?
                }
            };
            *doc = merged;
            Ok(out)
        });
        let (report, maps) = out?;
        // The parts' elements in hand now stand for their copies, as if moved.
        for (cell, map) in cells.iter().zip(&maps) {
            retarget(py, cell, &self.doc, map);
        }
        Ok(report.into())
    }

    /// Checks names: duplicates within a namespace and references to nothing. Raises
    /// :class:`MjcfError` listing every problem with its position.
    fn validate(&self, py: Python<'_>) -> PyResult<()> {
        run(py, || Ok(self.doc.read_detached().validate()?))
    }

    /// Every file MuJoCo reads when it compiles this document (meshes, textures, height
    /// fields, skins), as absolute paths once loaded, each once, in document order: what
    /// the model store keys a structure by; ``tag``: only those elements of that tag read
    /// (``"mesh"``: what MuJoCo's asset cache keeps of a compile).
    ///
    /// >>> import mjcf_forge
    /// >>> doc = mjcf_forge.Document.from_string(
    /// ...     "<mujoco><asset><mesh file='/m/a.obj'/><texture file='/m/t.png'/></asset></mujoco>")
    /// >>> doc.files()
    /// ['/m/a.obj', '/m/t.png']
    /// >>> doc.files("mesh")  # those of the elements of one tag
    /// ['/m/a.obj']
    #[pyo3(signature = (tag=None))]
    fn files(&self, py: Python<'_>, tag: Option<&str>) -> PyResult<Vec<String>> {
        run(py, || {
            let doc = self.doc.read_detached();
            let files = match tag {
                Some(tag) => doc.files_of(tag),
                None => doc.files(),
            };
            Ok(files
                .iter()
                .map(|p| p.to_string_lossy().into_owned())
                .collect())
        })
    }

    /// The document's structure key (32 hex digits): equal for two documents exactly
    /// when MuJoCo compiles them to models that differ only in the values of
    /// :attr:`patch` (and what ``mj_setConst`` derives from them). Found by reading the
    /// document: every value that cannot be written into a compiled model exactly, and
    /// where the others land. See :class:`DocumentCache`.
    #[getter]
    fn structure_key(&self, py: Python<'_>) -> PyResult<String> {
        run(py, || Ok(split(&self.doc.read_detached()).structure_key))
    }

    /// The values that turn a compiled model of this document's structure into its own,
    /// shaped as :attr:`Variant.patch`: a tuple of ``(object, name, field, value)``,
    /// meaning ``model.<object>(name).<field> = value`` (``name`` is the compiled id, an
    /// ``int``, for an unnamed element; ``object`` may also be ``"actuator"``, and
    /// ``"option"`` with id 0 for ``model.opt.<field>``). A body whose primitive geoms are
    /// sized by the document has ``("body", name, "geoms", mjcf)``: what MuJoCo derives from
    /// the sizes (each geom's size, bounding radius and box, the body's mass, inertia and
    /// bounding volumes) is what it compiles from the model ``mjcf`` of the body's geoms.
    #[getter]
    fn patch<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let split = run(py, || Ok(split(&self.doc.read_detached())))?;
        PyTuple::new(py, patch_list(py, &split.entries)?)
    }

    /// The split as the document cache takes it (a :class:`DocumentSplit`): the structure
    /// key and the patch's values by kind.
    fn _split(&self, py: Python<'_>) -> PyResult<PyDocumentSplit> {
        let split = run(py, || Ok(split(&self.doc.read_detached())))?;
        Ok(PyDocumentSplit::new(
            py,
            split.structure_key,
            split.entries,
            split.fixed_statistics,
        ))
    }

    /// MuJoCo's error ``message`` about ``xml`` (this document as :meth:`to_xml` wrote
    /// it) as ``file:line:col: message`` at the element it names in the sources.
    fn _mujoco_error(&self, py: Python<'_>, xml: &str, message: &str) -> String {
        self.doc.read(py).mujoco_error(xml, message).to_string()
    }

    /// An independent copy (cheap: a few flat buffers).
    fn copy(&self, py: Python<'_>) -> PyResult<PyDocument> {
        run(py, || Ok(self.doc.read_detached().clone())).map(PyDocument::new)
    }

    fn __copy__(&self, py: Python<'_>) -> PyResult<PyDocument> {
        self.copy(py)
    }

    fn __deepcopy__(&self, py: Python<'_>, _memo: &Bound<'_, PyAny>) -> PyResult<PyDocument> {
        self.copy(py)
    }

    /// Pickling (Ray, multiprocessing) goes through the XML text and the model folder: the
    /// text is already inlined with absolute paths, so reading it back gives the same model.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let (xml, dir) = run(py, || {
            let doc = self.doc.read_detached();
            Ok((doc.to_xml_string(), doc.model_dir().to_path_buf()))
        })?;
        let from_string = py.get_type::<PyDocument>().getattr("from_string")?;
        PyTuple::new(
            py,
            [
                from_string,
                PyTuple::new(
                    py,
                    [
                        xml.into_pyobject(py)?.into_any(),
                        dir.into_pyobject(py)?.into_any(),
                    ],
                )?
                .into_any(),
            ],
        )
    }

    /// The ``model`` attribute of ``<mujoco>``, or ``None``.
    #[getter]
    fn model_name(&self, py: Python<'_>) -> Option<String> {
        self.doc.read(py).model_name().map(str::to_owned)
    }

    /// The folder of the main file (includes and relative asset paths were resolved from it).
    #[getter]
    fn model_dir(&self, py: Python<'_>) -> PathBuf {
        self.doc.read(py).model_dir().to_path_buf()
    }

    /// The root ``<mujoco>`` element.
    #[getter]
    fn root<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyElement>> {
        let root = self.doc.read(py).root();
        cell::proxy(py, &self.doc, root)
    }

    /// The root ``<mujoco>`` element (``ElementTree.getroot``).
    fn getroot<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyElement>> {
        self.root(py)
    }

    /// ``mjcf_forge.base``'s element sorting in one native pass (robosuite's
    /// ``sort_elements(root, element_filter=_element_filter)``, naming unnamed geoms of
    /// groups 0 and 1 ``g{n}_col`` / ``g{n}_vis`` first when ``name_geoms``): a dict of
    /// the keys, in the order they first appear, to their elements in document order, and
    /// a dict of the same keys to those elements' names (None for an unnamed one).
    #[pyo3(signature = (name_geoms = true))]
    fn _sort_elements<'py>(
        &self,
        py: Python<'py>,
        name_geoms: bool,
    ) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
        let root = self.doc.read(py).root();
        sort::sorted_dicts(py, &self.doc, root, name_geoms)
    }

    /// Sets ``key`` to ``value`` (as :meth:`Element.set`) on every element of
    /// ``elements`` and removes the attribute ``remove`` from each (if given): what
    /// ``mjcf_forge.base`` does to the collision geoms, under one lock for the elements of
    /// this document.
    #[pyo3(signature = (elements, key, value, remove = None))]
    fn _set_all(
        &self,
        py: Python<'_>,
        elements: Vec<Bound<'_, PyElement>>,
        key: &str,
        value: &Bound<'_, PyAny>,
        remove: Option<&str>,
    ) -> PyResult<()> {
        let (key, text) = values::checked_attr(key, value)?;
        let mut here = Vec::with_capacity(elements.len());
        let mut elsewhere = Vec::new();
        for e in &elements {
            let (cell, node) = e.get().target();
            if Arc::ptr_eq(&cell, &self.doc) {
                here.push(node);
            } else {
                elsewhere.push((cell, node));
            }
        }
        let apply = |doc: &mut Document, node: Node| {
            doc.set_attr(node, &key, &text);
            if let Some(r) = remove {
                doc.remove_attr(node, r);
            }
        };
        {
            let mut doc = self.doc.write(py);
            for node in here {
                apply(&mut doc, node);
            }
        }
        for (cell, node) in elsewhere {
            apply(&mut cell.write(py), node);
        }
        Ok(())
    }

    /// The top-level sections with these tags, each created empty at the end when
    /// missing, in the order given (:meth:`section` of each).
    fn _sections<'py>(
        &self,
        py: Python<'py>,
        tags: Vec<String>,
    ) -> PyResult<Vec<Bound<'py, PyElement>>> {
        let mut sections = Vec::with_capacity(tags.len());
        for tag in &tags {
            sections.push(Section::from_tag(tag).ok_or_else(|| {
                Failure::new(vec![format!(
                    "'{tag}' is not a section of an MJCF model (asset, worldbody, actuator, ...)"
                )])
            })?);
        }
        let nodes: Vec<Node> = {
            let mut doc = self.doc.write(py);
            sections.into_iter().map(|s| doc.section(s)).collect()
        };
        cell::proxies(py, &self.doc, nodes)
    }

    /// The ``<worldbody>`` element (created, empty, when the model has none).
    #[getter]
    fn worldbody<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyElement>> {
        self.section(py, "worldbody")
    }

    /// The top-level section with this tag (``"asset"``, ``"actuator"``, ``"sensor"``, ...),
    /// created empty at the end when the model has none. Repeated sections were already
    /// merged into one at load, as MuJoCo reads them all in order.
    fn section<'py>(&self, py: Python<'py>, tag: &str) -> PyResult<Bound<'py, PyElement>> {
        let section = Section::from_tag(tag).ok_or_else(|| {
            Failure::new(vec![format!(
                "'{tag}' is not a section of an MJCF model (asset, worldbody, actuator, ...)"
            )])
        })?;
        let node = self.doc.write(py).section(section);
        cell::proxy(py, &self.doc, node)
    }

    /// The first element matching the ElementPath ``path`` from the root, as
    /// ``ElementTree.find`` (``"worldbody/body"``, ``".//joint"``, ``".//body[@name='b']"``).
    #[pyo3(signature = (path, namespaces = None))]
    fn find<'py>(
        &self,
        py: Python<'py>,
        path: &str,
        namespaces: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let path = tree_path(py, path)?;
        path::find(&self.root(py)?, &path, namespaces)
    }

    /// Every element matching the ElementPath ``path`` from the root (``ElementTree.findall``).
    #[pyo3(signature = (path, namespaces = None))]
    fn findall<'py>(
        &self,
        py: Python<'py>,
        path: &str,
        namespaces: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let path = tree_path(py, path)?;
        path::findall(&self.root(py)?, &path, namespaces)
    }

    /// An iterator over the elements matching ``path`` from the root (``ElementTree.iterfind``).
    #[pyo3(signature = (path, namespaces = None))]
    fn iterfind<'py>(
        &self,
        py: Python<'py>,
        path: &str,
        namespaces: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let path = tree_path(py, path)?;
        path::iterfind(&self.root(py)?, &path, namespaces)
    }

    /// The text of the first element matching ``path`` from the root (``ElementTree.findtext``).
    #[pyo3(signature = (path, default = None, namespaces = None))]
    fn findtext<'py>(
        &self,
        py: Python<'py>,
        path: &str,
        default: Option<Bound<'py, PyAny>>,
        namespaces: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        let path = tree_path(py, path)?;
        path::findtext(&self.root(py)?, &path, default, namespaces)
    }

    /// An iterator over every element (document order), only those tagged ``tag`` when
    /// given (``ElementTree.iter``).
    #[pyo3(signature = (tag = None))]
    fn iter<'py>(&self, py: Python<'py>, tag: Option<&str>) -> PyResult<Bound<'py, PyAny>> {
        path::iter(self.root(py)?.get(), py, tag)
    }

    /// The first element (document order) whose tag is ``kind`` (``"body"``, ``"geom"``,
    /// ``"joint"``, ``"mesh"``, ...) and, when given, whose ``name`` is ``name``; ``None``
    /// when there is none.
    #[pyo3(signature = (kind, name = None))]
    fn find_named<'py>(
        &self,
        py: Python<'py>,
        kind: &str,
        name: Option<&str>,
    ) -> PyResult<Option<Bound<'py, PyElement>>> {
        let found = {
            let doc = self.doc.read(py);
            path::named(&doc, doc.root(), Some(kind), name).next()
        };
        found.map(|n| cell::proxy(py, &self.doc, n)).transpose()
    }

    /// Every element (document order) whose tag is ``kind`` (any tag when ``None``) and,
    /// when given, whose ``name`` is ``name``.
    #[pyo3(signature = (kind = None, name = None))]
    fn find_all_named<'py>(
        &self,
        py: Python<'py>,
        kind: Option<&str>,
        name: Option<&str>,
    ) -> PyResult<Vec<Bound<'py, PyElement>>> {
        let nodes: Vec<Node> = {
            let doc = self.doc.read(py);
            path::named(&doc, doc.root(), kind, name).collect()
        };
        cell::proxies(py, &self.doc, nodes)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let doc = self.doc.read(py);
        format!(
            "<mjcf_forge.Document model={:?} dir={:?} nodes={}>",
            doc.model_name().unwrap_or(""),
            doc.model_dir().display().to_string(),
            doc.node_count()
        )
    }
}

/// A loaded document, each of its load's warnings (what MuJoCo's URDF importer warns
/// about, at its place) raised as a ``UserWarning`` first.
pub(crate) fn loaded(py: Python<'_>, doc: Document) -> PyResult<PyDocument> {
    crate::errors::raise_warnings(py, doc.warnings())?;
    Ok(PyDocument::new(doc))
}

/// A path of ``ElementTree.find`` and friends, from the tree: an absolute path is taken
/// from the root, with the warning ElementTree gives.
fn tree_path(py: Python<'_>, path: &str) -> PyResult<String> {
    if !path.starts_with('/') {
        return Ok(path.to_owned());
    }
    let message = format!(
        "This search is broken in 1.3 and earlier, and will be fixed in a future version.  \
         If you rely on the current behaviour, change it to {:?}",
        format!(".{path}")
    );
    let message = std::ffi::CString::new(message).unwrap_or_default();
    PyErr::warn(py, &py.get_type::<PyFutureWarning>(), &message, 1)?;
    Ok(format!(".{path}"))
}
