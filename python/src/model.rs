//! `Model`: one instance of a model in a scene (robosuite's `MujocoXMLModel`).

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Arc, RwLock};

use mjcf_forge::{Document, MujocoModel, UrdfOptions, XmlModel, XmlModelOptions};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::sync::RwLockExt;
use pyo3::types::{PyDict, PyList, PyString};

use crate::document::{DocCell, PyDocument, retarget, urdf};
use crate::errors::{Failure, read, run, write};

/// One instance of an MJCF model, with every name prefixed and its parts sorted by role:
/// robosuite's ``MujocoXMLModel`` vocabulary over a :class:`Document`.
///
/// ``Model(source, idn)`` takes a :class:`Document` (copied: later changes to it do not
/// reach the model) or a path (MJCF, or URDF read as :meth:`Document.load` reads it; for
/// :meth:`Document.from_urdf`'s options pass its document), and prefixes every name with
/// ``f"{idn}_"`` (or exactly ``prefix=`` when given). As robosuite does, unnamed geoms of
/// group 0 and 1 are named ``g{n}_col`` / ``g{n}_vis`` and collision geoms (group 0) are
/// drawn in ``contact_geom_rgba`` (``None`` leaves their colours). The model must have
/// exactly one top-level body.
///
/// Lists (``bodies``, ``joints``, ...) hold prefixed names; ``bottom_offset``,
/// ``top_offset`` and ``base_offset`` are numpy arrays, computed from the geometry
/// (primitives exactly, meshes from their vertices) unless set.
///
/// Example::
///
///     robot = Model("panda/robot.xml", "robot0")
///     gripper = Model("panda_gripper.xml", "gripper0")
///     robot.merge(gripper, body="robot0_right_hand")
///     robot.joints          # ['robot0_joint1', ...]
///     robot.bottom_offset   # array([0., 0., -0.15...])
#[pyclass(name = "Model", module = "mjcf_forge", frozen)]
pub(crate) struct PyModel {
    model: Arc<RwLock<XmlModel>>,
    /// The model's document as a `Document` shares it: one cell, so that its elements keep
    /// one proxy each however often `document` is asked for.
    cell: Arc<DocCell>,
}

impl PyModel {
    /// The model, read with the GIL held (waiting without it, see `document::cell`).
    fn lock(&self, py: Python<'_>) -> std::sync::RwLockReadGuard<'_, XmlModel> {
        self.model
            .read_py_attached(py)
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// The model, changed with the GIL held.
    fn lock_mut(&self, py: Python<'_>) -> std::sync::RwLockWriteGuard<'_, XmlModel> {
        self.model
            .write_py_attached(py)
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    fn with(model: XmlModel) -> PyModel {
        let model = Arc::new(RwLock::new(model));
        PyModel {
            cell: DocCell::of_model(model.clone()),
            model,
        }
    }
}

/// The geometry-derived numbers, raising instead of returning NaN.
fn offsets(model: &XmlModel) -> Result<mjcf_forge::Offsets, Failure> {
    model.try_offsets().map_err(Failure::from)
}

/// An instance id as robosuite's models take it: a ``str``, or an integer (anything with
/// ``__index__``, numpy's included, ``bool`` not), written in decimal. Anything else would
/// make a prefix of its ``str()`` (``"<object object at 0x...>_"``): a ``TypeError``.
fn instance_id(idn: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(s) = idn.cast::<PyString>() {
        return Ok(s.to_cow()?.into_owned());
    }
    if !idn.is_instance_of::<pyo3::types::PyBool>()
        && let Ok(i) = crate::upcalls::python(idn.py(), "operator", "index")?.call1((idn,))
    {
        return Ok(i.str()?.to_cow()?.into_owned());
    }
    Err(PyTypeError::new_err(format!(
        "Model(source, idn): idn is an int or a str (the instance id), not {}",
        idn.get_type().name()?
    )))
}

fn numpy_array<'py>(py: Python<'py>, values: &[f64]) -> PyResult<Bound<'py, PyAny>> {
    crate::upcalls::python(py, "numpy", "array")?.call1((values.to_vec(),))
}

#[pymethods]
impl PyModel {
    #[new]
    #[pyo3(text_signature = "(source, idn=None, *, prefix=None, name=None, \
        contact_geom_rgba=(0.0, 0.5, 0.0, 1.0), name_unnamed_geoms=True, \
        exclude_from_prefixing=())")]
    #[pyo3(signature = (
        source,
        idn = None,
        *,
        prefix = None,
        name = None,
        contact_geom_rgba = Some([0.0, 0.5, 0.0, 1.0]),
        name_unnamed_geoms = true,
        exclude_from_prefixing = Vec::new(),
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        source: &Bound<'_, PyAny>,
        idn: Option<&Bound<'_, PyAny>>,
        prefix: Option<String>,
        name: Option<String>,
        contact_geom_rgba: Option<[f64; 4]>,
        name_unnamed_geoms: bool,
        exclude_from_prefixing: Vec<String>,
    ) -> PyResult<PyModel> {
        let prefix = match (idn, prefix) {
            (Some(idn), None) => format!("{}_", instance_id(idn)?),
            (None, Some(prefix)) => prefix,
            _ => {
                return Err(PyTypeError::new_err(
                    "Model(source, idn) or Model(source, prefix=...): give exactly one",
                ));
            }
        };
        crate::document::check_xml_text("prefix", &prefix)?;
        enum Source {
            // Boxed: the document is large and the enum lives only for this call.
            Doc(Box<Document>),
            Path(PathBuf),
            Urdf(PathBuf, UrdfOptions),
        }
        let source = if let Ok(doc) = source.cast::<PyDocument>() {
            Source::Doc(Box::new(doc.get().snapshot(source.py())))
        } else {
            let path = source.extract::<PathBuf>().map_err(|_| {
                PyTypeError::new_err("Model(source, ...): source is a Document or a path")
            })?;
            // URDF as the installed mujoco imports it (Document.load's rule).
            if py.detach(|| urdf::is_urdf_file(&path)) {
                Source::Urdf(path, urdf::plain_options(py)?)
            } else {
                Source::Path(path)
            }
        };
        let options = XmlModelOptions {
            name,
            contact_geom_rgba,
            name_unnamed_geoms,
            exclude_from_prefixing,
        };
        // A URDF file's load warnings, raised as Document.load raises them (a Document
        // given raised its own when it was loaded).
        let read_urdf = matches!(source, Source::Urdf(..));
        let model = run(py, move || {
            let doc = match source {
                Source::Doc(doc) => *doc,
                Source::Path(path) => Document::load(&path)?,
                Source::Urdf(path, options) => Document::load_urdf(&path, &options)?,
            };
            Ok(XmlModel::with_prefix(doc, &prefix, options)?)
        })?;
        if read_urdf {
            crate::errors::raise_warnings(py, model.document().warnings())?;
        }
        Ok(PyModel::with(model))
    }

    /// The model's name: ``name=`` if given, else the ``model`` attribute, else the root
    /// body's name.
    #[getter]
    fn name(&self, py: Python<'_>) -> String {
        self.lock(py).name().to_owned()
    }

    /// The prefix every name of this instance carries (``"robot0_"``).
    #[getter]
    fn naming_prefix(&self, py: Python<'_>) -> String {
        self.lock(py).naming_prefix().to_owned()
    }

    /// The one top-level body (prefixed name). One the file leaves unnamed (robosuite's
    /// objects wrap theirs in one) is named ``root`` (or the first of ``root1``,
    /// ``root2``... no body uses) before prefixing, as the same object is named in a
    /// scene's variants: ``Model(can_xml, "object1").root_body == "object1_root"``.
    #[getter]
    fn root_body(&self, py: Python<'_>) -> String {
        self.lock(py).root_body().to_owned()
    }

    /// Every named body, the root first.
    #[getter]
    fn bodies(&self, py: Python<'_>) -> Vec<String> {
        self.lock(py).bodies().to_vec()
    }

    /// Every named joint (free joints included).
    #[getter]
    fn joints(&self, py: Python<'_>) -> Vec<String> {
        self.lock(py).joints().to_vec()
    }

    /// Every named actuator.
    #[getter]
    fn actuators(&self, py: Python<'_>) -> Vec<String> {
        self.lock(py).actuators().to_vec()
    }

    /// Every named site of the kinematic tree.
    #[getter]
    fn sites(&self, py: Python<'_>) -> Vec<String> {
        self.lock(py).sites().to_vec()
    }

    /// Every named sensor.
    #[getter]
    fn sensors(&self, py: Python<'_>) -> Vec<String> {
        self.lock(py).sensors().to_vec()
    }

    /// Collision geoms: group 0 (MuJoCo's default group).
    #[getter]
    fn contact_geoms(&self, py: Python<'_>) -> Vec<String> {
        self.lock(py).contact_geoms().to_vec()
    }

    /// Visual geoms: group 1.
    #[getter]
    fn visual_geoms(&self, py: Python<'_>) -> Vec<String> {
        self.lock(py).visual_geoms().to_vec()
    }

    /// Geoms that matter to a task, by role (set with :meth:`set_important`).
    #[getter]
    fn important_geoms(&self, py: Python<'_>) -> BTreeMap<String, Vec<String>> {
        self.lock(py).important_geoms().clone()
    }

    /// Sites that matter to a task, by role.
    #[getter]
    fn important_sites(&self, py: Python<'_>) -> BTreeMap<String, String> {
        self.lock(py).important_sites().clone()
    }

    /// Sensors that matter to a task, by role.
    #[getter]
    fn important_sensors(&self, py: Python<'_>) -> BTreeMap<String, String> {
        self.lock(py).important_sensors().clone()
    }

    /// Sets the important geoms, sites and sensors by role, with raw (unprefixed) names,
    /// as robosuite's ``_important_geoms`` and friends; the properties return them prefixed.
    #[pyo3(signature = (*, geoms = None, sites = None, sensors = None))]
    fn set_important(
        &self,
        py: Python<'_>,
        geoms: Option<BTreeMap<String, Vec<String>>>,
        sites: Option<BTreeMap<String, String>>,
        sensors: Option<BTreeMap<String, String>>,
    ) {
        let mut model = self.lock_mut(py);
        if let Some(g) = geoms {
            model.set_important_geoms(g);
        }
        if let Some(s) = sites {
            model.set_important_sites(s);
        }
        if let Some(s) = sensors {
            model.set_important_sensors(s);
        }
    }

    /// The root body's position in its parent (numpy array of 3).
    #[getter]
    fn base_offset<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let o = run(py, || offsets(&read(&self.model)))?;
        numpy_array(py, &o.base)
    }

    /// From the root body's origin down to the model's lowest point, in the root's frame
    /// (numpy array of 3). Raises :class:`MjcfError` when a mesh file cannot be read.
    #[getter]
    fn bottom_offset<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let o = run(py, || offsets(&read(&self.model)))?;
        numpy_array(py, &o.bottom)
    }

    /// From the root body's origin up to the model's highest point, in the root's frame
    /// (numpy array of 3).
    #[getter]
    fn top_offset<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let o = run(py, || offsets(&read(&self.model)))?;
        numpy_array(py, &o.top)
    }

    /// The largest horizontal distance of the model's geometry from the root's z axis.
    #[getter]
    fn horizontal_radius(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(run(py, || offsets(&read(&self.model)))?.horizontal_radius)
    }

    /// Overrides any of the geometry-derived offsets (sequences of 3 numbers; a float for
    /// the radius).
    #[pyo3(signature = (*, bottom = None, top = None, base = None, horizontal_radius = None))]
    fn set_offsets(
        &self,
        py: Python<'_>,
        bottom: Option<[f64; 3]>,
        top: Option<[f64; 3]>,
        base: Option<[f64; 3]>,
        horizontal_radius: Option<f64>,
    ) {
        let mut model = self.lock_mut(py);
        if let Some(v) = bottom {
            model.set_bottom_offset(v);
        }
        if let Some(v) = top {
            model.set_top_offset(v);
        }
        if let Some(v) = base {
            model.set_base_offset(v);
        }
        if let Some(v) = horizontal_radius {
            model.set_horizontal_radius(v);
        }
    }

    /// Raw names as they appear in this instance (prefixed unless excluded), like
    /// robosuite's ``correct_naming``: a ``str``, a list of them, or a dict's values.
    fn correct_naming<'py>(
        &self,
        py: Python<'py>,
        names: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let model = self.lock(py);
        if let Ok(s) = names.cast::<PyString>() {
            return Ok(PyString::new(py, &model.correct_naming(&s.to_cow()?)).into_any());
        }
        if let Ok(d) = names.cast::<PyDict>() {
            let out = PyDict::new(py);
            for (k, v) in d.iter() {
                out.set_item(k, model.correct_naming(&v.extract::<String>()?))?;
            }
            return Ok(out.into_any());
        }
        let list: Vec<String> = names.extract()?;
        let fixed: Vec<String> = list.iter().map(|n| model.correct_naming(n)).collect();
        Ok(PyList::new(py, fixed)?.into_any())
    }

    /// Merges ``other`` (a :class:`Model`, or a list of them, merged in order and checked
    /// for name clashes once) into this model: into the world body, or into this model's
    /// body named ``body`` (a full, prefixed name, e.g. ``"robot0_right_hand"``). The lists
    /// and offsets grow by the other's. On error nothing changes.
    #[pyo3(signature = (other, body = None, *, fuse_keys = false))]
    fn merge(
        &self,
        py: Python<'_>,
        other: &Bound<'_, PyAny>,
        body: Option<String>,
        fuse_keys: bool,
    ) -> PyResult<crate::document::PyMergeReport> {
        let others: Vec<Bound<'_, PyModel>> = if let Ok(m) = other.cast::<PyModel>() {
            vec![m.clone()]
        } else {
            let list: Vec<Bound<'_, PyAny>> = other.extract().map_err(|_| {
                PyTypeError::new_err("merge(other, ...): other is a Model or a list of Models")
            })?;
            list.into_iter()
                .map(|m| {
                    m.cast_into::<PyModel>()
                        .map_err(|_| PyTypeError::new_err("merge: every part must be a Model"))
                })
                .collect::<PyResult<_>>()?
        };
        let copies: Vec<XmlModel> = others.iter().map(|m| m.get().lock(py).clone()).collect();
        let (report, maps) = run(py, || {
            let mut model = write(&self.model);
            let mut merged = model.clone();
            let parts: Vec<(&XmlModel, Option<&str>)> =
                copies.iter().map(|m| (m, body.as_deref())).collect();
            let out = merged.merge_all_mapped(&parts, fuse_keys)?;
            *model = merged;
            Ok(out)
        })?;
        // Elements of the parts in hand now stand for their copies in this model.
        for (part, map) in others.iter().zip(&maps) {
            retarget(py, &part.get().cell, &self.cell, map);
        }
        Ok(report.into())
    }

    /// The instance's own document (names prefixed), live: changes made through it (its
    /// elements' attributes, appended or removed elements) are the model's, and what
    /// :meth:`to_xml` writes. The name lists and offsets are read from it on first use.
    #[getter]
    fn document(&self) -> PyDocument {
        PyDocument {
            doc: self.cell.clone(),
        }
    }

    /// The instance as XML text (see :meth:`Document.to_xml`); robosuite calls this
    /// ``get_xml``.
    #[pyo3(signature = (pretty = false))]
    fn to_xml(&self, py: Python<'_>, pretty: bool) -> PyResult<String> {
        run(py, || {
            let model = read(&self.model);
            Ok(if pretty {
                model.document().to_pretty_string()
            } else {
                model.document().to_xml_string()
            })
        })
    }

    /// Everything the model tells, as one JSON text (what ``mjcf-forge info --json``
    /// prints).
    fn info_json(&self, py: Python<'_>) -> PyResult<String> {
        run(py, || Ok(read(&self.model).info_json()))
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let model = self.lock(py);
        format!(
            "<mjcf_forge.Model name={:?} prefix={:?} root_body={:?}>",
            model.name(),
            model.naming_prefix(),
            model.root_body()
        )
    }
}
