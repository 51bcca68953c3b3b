//! `Variant`: one variant of a scene, and what a worker makes for it.

use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use mjcf_forge::Document;
use mjcf_forge::scene::{Scene, VariantPatch};
use pyo3::exceptions::PyImportError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};

use crate::document::PyDocument;
use crate::document::patch::{PatchTuple, patch_entry, patch_list};
use crate::errors::{Failure, catch, run};
use crate::upcalls;

/// What a worker makes for one index: the variant's text forms, so that the Python side
/// only wraps them. The XML comes from the library's fastest path (`variant_xml`: the
/// template's text with the variant's values spliced in, where the scene allows); the
/// document is only built if Python asks for it.
pub(super) struct Made {
    index: u64,
    xml: String,
    params_json: String,
    objects: usize,
}

pub(super) fn make(scene: &Scene, index: u64) -> Result<Made, Failure> {
    catch(|| {
        let (xml, params) = scene.variant_xml(index)?;
        Ok(Made {
            index,
            params_json: params.to_json(index, None),
            objects: params.objects.len(),
            xml,
        })
    })
}

/// The numbers of a variant's parameters (made from the manifest's JSON, where values are
/// the XML's text): poses as lists of floats, a randomized value as a float or a list of
/// them unless its attribute holds a name or a file, or it is not all numbers (a keyword).
fn numeric_params(params: &Bound<'_, PyAny>) -> PyResult<()> {
    let py = params.py();
    for object in params.get_item("objects")?.try_iter()? {
        let object = object?;
        for key in ["pos", "quat"] {
            let text: String = object.get_item(key)?.extract()?;
            if let Some(numbers) = numbers(&text) {
                object.set_item(key, PyList::new(py, numbers)?)?;
            }
        }
    }
    for value in params.get_item("randomized")?.try_iter()? {
        let value = value?;
        let kind: String = value.get_item("kind")?.extract()?;
        let attribute: String = value.get_item("attribute")?.extract()?;
        let names_something = mjcf_forge::vocab::element(&kind)
            .and_then(|e| e.attr(&attribute))
            .is_some_and(|a| !matches!(a.kind, mjcf_forge::vocab::AttrKind::Plain));
        if names_something {
            continue;
        }
        let text: String = value.get_item("value")?.extract()?;
        match numbers(&text).as_deref() {
            Some([one]) => value.set_item("value", *one)?,
            Some(many) => value.set_item("value", PyList::new(py, many)?)?,
            None => {}
        }
    }
    Ok(())
}

/// The numbers of an attribute value's text, when it is one or more decimal numbers (not
/// words such as `inf` that Rust's parser also reads, which may be names).
fn numbers(text: &str) -> Option<Vec<f64>> {
    let numbers: Vec<f64> = text
        .split_ascii_whitespace()
        .map(|t| {
            t.bytes()
                .all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E'))
                .then(|| t.parse::<f64>().ok())
                .flatten()
        })
        .collect::<Option<_>>()?;
    (!numbers.is_empty()).then_some(numbers)
}

/// One variant of a :class:`Scene`: its ``index``, its MJCF text ``xml`` (assets
/// referenced by absolute path), and ``params``, everything that was drawn for it.
/// Picklable (as its index, XML and parameters). Its :attr:`document` is built only
/// when asked for.
#[pyclass(name = "Variant", module = "mjcf_forge", frozen)]
pub(crate) struct PyVariant {
    index: u64,
    xml: String,
    params_json: String,
    objects: usize,
    /// Where the document comes from when asked for.
    origin: Origin,
    /// The document, built on first use: most callers only want the XML.
    document: OnceLock<Document>,
    /// The `str` made once on first access (the XML of a scene is tens of kilobytes).
    xml_str: OnceLock<Py<pyo3::types::PyString>>,
    /// Structure key and patch, drawn again on first use (or shipped by pickling).
    patch: OnceLock<VariantPatch>,
    /// The patch as the Python tuple made once on first access (a model cache reads it per
    /// patch; a tuple, so that no caller can change what the next one reads).
    patch_list: OnceLock<Py<PyTuple>>,
}

/// How a variant's document is made on demand.
pub(super) enum Origin {
    /// Made again by the scene (the same document the XML was written from).
    Scene(Arc<Scene>),
    /// Read back from the XML (an unpickled variant); the folder relative paths use.
    Text(PathBuf),
}

impl PyVariant {
    pub(super) fn new(made: Made, origin: Origin) -> PyVariant {
        PyVariant {
            index: made.index,
            xml: made.xml,
            params_json: made.params_json,
            objects: made.objects,
            origin,
            document: OnceLock::new(),
            xml_str: OnceLock::new(),
            patch: OnceLock::new(),
            patch_list: OnceLock::new(),
        }
    }

    /// The structure key and patch, made on first call (GIL released by the caller).
    fn drawn_patch(&self) -> Result<&VariantPatch, Failure> {
        if let Some(p) = self.patch.get() {
            return Ok(p);
        }
        let p = match &self.origin {
            Origin::Scene(scene) => catch(|| Ok(scene.patch(self.index)?))?,
            Origin::Text(_) => {
                return Err(Failure::from(
                    "this variant was unpickled without its patch".to_string(),
                ));
            }
        };
        Ok(self.patch.get_or_init(|| p))
    }

    /// The structure key and patch (made on first call with the GIL released).
    pub(crate) fn drawn(&self, py: Python<'_>) -> PyResult<&VariantPatch> {
        if let Some(p) = self.patch.get() {
            return Ok(p);
        }
        run(py, || self.drawn_patch().map(drop))?;
        self.drawn_patch().map_err(PyErr::from)
    }

    /// The variant as compact MJCF text.
    pub(crate) fn text(&self) -> &str {
        &self.xml
    }

    /// The document, built on first call (GIL released by the caller).
    fn doc(&self) -> Result<&Document, Failure> {
        if let Some(doc) = self.document.get() {
            return Ok(doc);
        }
        let doc = match &self.origin {
            Origin::Scene(scene) => scene.variant(self.index)?.document,
            Origin::Text(dir) => Document::from_str(&self.xml, dir)?,
        };
        // Another thread may have built it meanwhile: either copy is the same document.
        Ok(self.document.get_or_init(|| doc))
    }

    /// The folder the variant's relative paths (if any) are resolved from.
    fn model_dir(&self) -> PathBuf {
        match &self.origin {
            Origin::Scene(scene) => scene.template().model_dir().to_path_buf(),
            Origin::Text(dir) => dir.clone(),
        }
    }
}

#[pymethods]
impl PyVariant {
    /// The variant's index.
    #[getter]
    pub(crate) fn index(&self) -> u64 {
        self.index
    }

    /// The variant as compact MJCF text.
    #[getter]
    fn xml(&self, py: Python<'_>) -> Py<pyo3::types::PyString> {
        self.xml_str
            .get_or_init(|| pyo3::types::PyString::new(py, &self.xml).unbind())
            .clone_ref(py)
    }

    /// What was drawn, as a new ``dict``: ``index``, ``objects`` (for each placed object
    /// its ``group``, ``slot``, ``model``, ``prefix``, root ``body``, and ``pos`` and
    /// ``quat`` as lists of 3 and 4 floats, the values written in the XML) and
    /// ``randomized`` (each randomized attribute with its element's ``kind``, ``name``,
    /// ``part``, ``attribute`` and ``value``: a ``float`` for one number, a list of floats
    /// for several, a ``str`` for a name or keyword such as a material). The numbers are
    /// those of the XML text, read back exactly.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let params = upcalls::python(py, "json", "loads")?.call1((self.params_json.as_str(),))?;
        numeric_params(&params)?;
        Ok(params)
    }

    /// ``params`` as the JSON text it comes from: the manifest line of ``mjcf-forge
    /// generate`` without the file name, whose values are the XML's text (``"0.1 0 0.8"``).
    #[getter]
    fn params_json(&self) -> &str {
        &self.params_json
    }

    /// The variant's structure: equal for two variants of a scene exactly when their
    /// compiled models differ only in the values of :attr:`patch` (and what MuJoCo's
    /// ``mj_setConst`` derives from them). 32 hex digits.
    #[getter]
    fn structure_key(&self, py: Python<'_>) -> PyResult<String> {
        run(py, || Ok(self.drawn_patch()?.structure_key.clone()))
    }

    /// The values that turn a compiled model of this variant's structure into its own:
    /// a tuple of ``(object, name, field, value)``, meaning
    /// ``model.<object>(name).<field> = value`` with MuJoCo's named accessors (``name``
    /// is an ``int``, the element's id, for an unnamed element of the scene's template)
    /// (``("geom", "object0_g0_vis", "rgba", (r, g, b, a))``,
    /// ``("joint", "object0_joint0", "qpos0", (x, y, z, qw, qx, qy, qz))``). ``value`` is
    /// a tuple of floats (a ``float`` field's already rounded as MuJoCo rounds it), or
    /// for ``matid`` the material's name. See :class:`ModelCache`.
    #[getter]
    fn patch<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        if let Some(t) = self.patch_list.get() {
            return Ok(t.bind(py).clone());
        }
        let p = run(py, || Ok(self.drawn_patch()?.clone()))?;
        let t = PyTuple::new(py, patch_list(py, &p.entries)?)?;
        Ok(self.patch_list.get_or_init(|| t.unbind()).bind(py).clone())
    }

    /// A copy of the variant's :class:`Document` (to edit before writing or compiling).
    #[getter]
    fn document(&self, py: Python<'_>) -> PyResult<PyDocument> {
        run(py, || Ok(self.doc()?.clone())).map(PyDocument::new)
    }

    /// Writes the indented XML to ``path`` atomically.
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        run(py, || Ok(self.doc()?.write_file(&path)?))
    }

    /// Compiles the variant with MuJoCo (``mujoco.MjModel.from_xml_string``); needs the
    /// ``mujoco`` package. Asset files are found by their absolute paths.
    fn compile<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mujoco = upcalls::python_module(py, "mujoco").map_err(|e| {
            PyImportError::new_err(format!(
                "Variant.compile() needs the mujoco package (pip install mujoco): {e}"
            ))
        })?;
        mujoco
            .getattr("MjModel")?
            .getattr("from_xml_string")?
            .call1((self.xml(py),))
    }

    fn __repr__(&self) -> String {
        format!(
            "<mjcf_forge.Variant index={} objects={} xml_bytes={}>",
            self.index,
            self.objects,
            self.xml.len()
        )
    }

    /// Pickling (Ray, multiprocessing) ships the index, the XML, the parameters and the
    /// patch; the copy reads its document back from the XML (paths in it are absolute).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let restore = py.get_type::<PyVariant>().getattr("_restore")?;
        let patch = run(py, || Ok(self.drawn_patch()?.clone()))?;
        let args = (
            self.index,
            self.xml(py),
            self.params_json.as_str(),
            self.objects,
            self.model_dir(),
            (patch.structure_key.clone(), patch_list(py, &patch.entries)?),
        )
            .into_pyobject(py)?;
        PyTuple::new(py, [restore, args.into_any()])
    }

    /// The inverse of ``__reduce__`` (not part of the API).
    #[staticmethod]
    fn _restore(
        py: Python<'_>,
        index: u64,
        xml: String,
        params_json: String,
        objects: usize,
        model_dir: PathBuf,
        patched: (String, Vec<PatchTuple<'_>>),
    ) -> PyResult<PyVariant> {
        let (structure_key, patch) = patched;
        let made = Made {
            index,
            xml,
            params_json,
            objects,
        };
        let variant = PyVariant::new(made, Origin::Text(model_dir));
        let entries = patch
            .into_iter()
            .map(|(object, name, field, value)| patch_entry(object, &name, field, &value))
            .collect::<PyResult<Vec<_>>>()?;
        let _ = variant.patch.set(VariantPatch {
            index,
            structure_key,
            entries,
        });
        // Read the document now: a pickled variant that does not read back is an error
        // at unpickling, not later.
        run(py, || variant.doc().map(|_| ()))?;
        Ok(variant)
    }
}
