//! `WorldRows`: the split tier's per-world rows ([`mjcf_forge::split::WorldRows`], the rule
//! the C face's `ModelCache::worlds` keeps too) over one of the user's `MjModel`s patched
//! in place world after world: its arrays read in place (`arrays.rs`'s `Memory`), its
//! statistics read each world, the kept rows handed back as NumPy arrays with a leading
//! world axis. `ModelCache.batch` and `WorldBatch` keep their worlds through it.

use std::sync::Mutex;

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use super::arrays::Memory;
use crate::cache::statistics_of;
use crate::upcalls;
use mjcf_forge::split::{self, STATISTIC_NAMES, Statistics};

/// The rows, and the patched model's arrays they read.
struct Inner {
    rows: split::WorldRows,
    views: Vec<Memory>,
}

/// Per-world rows of ``model``'s arrays ``fields`` (``mjcf_forge::split::WorldRows``; by
/// default every array but those of ``STATIC_PREFIXES``):
/// ``base``'s bytes are world 0's; :meth:`push` reads the next world from ``model`` (the
/// model patched in place for it); an array gets a row per world once a world differs from
/// world 0 in it, or from the start when it is among ``always``; the statistics of every
/// world are kept. :meth:`arrays` gives the kept rows as ``(nworld, ...)`` arrays and
/// ``stat.<name>``.
///
/// >>> import mujoco
/// >>> from mjcf_forge._mjcf_forge import WorldRows
/// >>> model = mujoco.MjModel.from_xml_string(
/// ...     '<mujoco><worldbody><geom size=".1"/><geom size=".2"/></worldbody></mujoco>')
/// >>> rows = WorldRows(model, model, ["qpos0"], ["geom_rgba", "qpos0"])
/// >>> rows.push(None)
/// >>> model.geom_rgba[1] = [1, 0, 0, 1]
/// >>> rows.push(None)
/// >>> sorted(rows.arrays()), rows.arrays()["geom_rgba"].shape
/// (['geom_rgba', 'qpos0', 'stat.center', 'stat.extent', 'stat.meaninertia', 'stat.meanmass', 'stat.meansize'], (2, 2, 4))
#[pyclass(name = "WorldRows", module = "mjcf_forge._mjcf_forge", frozen)]
pub(crate) struct PyWorldRows {
    inner: Mutex<Inner>,
    model: Py<PyAny>,
}

impl PyWorldRows {
    fn inner(&self) -> PyResult<std::sync::MutexGuard<'_, Inner>> {
        self.inner
            .try_lock()
            .map_err(|_| PyRuntimeError::new_err("these WorldRows are in use by another call"))
    }
}

/// The arrays' bytes among `compare` (`None`: all), the arrays kept always included.
fn read<'v>(
    rows: &split::WorldRows,
    views: &'v [Memory],
    compare: Option<&[String]>,
) -> Vec<Option<&'v [u8]>> {
    rows.names()
        .zip(views)
        .enumerate()
        .map(|(k, (name, view))| {
            let wanted = compare.is_none_or(|c| c.iter().any(|n| n == name));
            (wanted || rows.always(k)).then(|| view.bytes())
        })
        .collect()
}

/// Statistics as `stat.<name>` arrays: one value per world, `center` three.
fn statistics<'py>(
    py: Python<'py>,
    out: &Bound<'py, PyDict>,
    stats: &[Statistics],
) -> PyResult<()> {
    let numpy = upcalls::python_module(py, "numpy")?;
    for (k, name) in STATISTIC_NAMES.iter().enumerate() {
        let values: Vec<Vec<f64>> = stats
            .iter()
            .map(|s| if k == 4 { s[4..].to_vec() } else { vec![s[k]] })
            .collect();
        let array = numpy.call_method1("array", (values,))?;
        let array = if k == 4 {
            array
        } else {
            array.call_method1("reshape", (-1,))?
        };
        out.set_item(format!("stat.{name}"), array)?;
    }
    Ok(())
}

/// The arrays of ``model`` a patch may change: its NumPy arrays but those of
/// ``STATIC_PREFIXES`` (what the C face reads from MuJoCo's table likewise), in ``dir``'s
/// order.
///
/// >>> import mujoco
/// >>> from mjcf_forge._mjcf_forge import patchable_arrays
/// >>> names = patchable_arrays(mujoco.MjModel.from_xml_string("<mujoco/>"))
/// >>> "body_mass" in names, "mesh_vert" in names
/// (True, False)
#[pyfunction]
pub(crate) fn patchable_arrays(model: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    let mut out = Vec::new();
    for name in model.dir()? {
        let name: String = name.extract()?;
        if name.starts_with('_') || split::STATIC_PREFIXES.iter().any(|p| name.starts_with(p)) {
            continue;
        }
        let Ok(value) = model.getattr(name.as_str()) else {
            continue;
        };
        if value.hasattr("__array_interface__")? && !value.is_callable() {
            out.push(name);
        }
    }
    Ok(out)
}

#[pymethods]
impl PyWorldRows {
    #[new]
    #[pyo3(signature = (base, model, always, fields=None))]
    fn new(
        base: &Bound<'_, PyAny>,
        model: &Bound<'_, PyAny>,
        always: Vec<String>,
        fields: Option<Vec<String>>,
    ) -> PyResult<Self> {
        let fields = match fields {
            Some(fields) => fields,
            None => patchable_arrays(model)?,
        };
        let mut first = Vec::with_capacity(fields.len());
        let mut views = Vec::with_capacity(fields.len());
        for name in fields {
            let view = Memory::of(&model.getattr(name.as_str())?, &name)?
                .ok_or_else(|| PyValueError::new_err(format!("{name}: not an array")))?;
            let at_base = Memory::of(&base.getattr(name.as_str())?, &name)?
                .ok_or_else(|| PyValueError::new_err(format!("{name}: not an array")))?;
            if at_base.shape != view.shape || at_base.typestr != view.typestr {
                return Err(PyValueError::new_err(format!(
                    "{name}: the base and the model differ in shape"
                )));
            }
            let kept = always.contains(&name);
            first.push((name, at_base.bytes().to_vec(), kept));
            views.push(view);
        }
        Ok(PyWorldRows {
            inner: Mutex::new(Inner {
                rows: split::WorldRows::new(first),
                views,
            }),
            model: model.clone().unbind(),
        })
    }

    /// The next world, as the model holds it now: its arrays among ``compare`` (``None``:
    /// all; the others taken as world 0's, the arrays kept always read) and its statistics.
    #[pyo3(signature = (compare=None))]
    fn push(&self, py: Python<'_>, compare: Option<Vec<String>>) -> PyResult<()> {
        let stat = statistics_of(self.model.bind(py));
        let mut inner = self.inner()?;
        let Inner { rows, views } = &mut *inner;
        let read = read(rows, views, compare.as_deref());
        rows.push(|k| read.get(k).copied().flatten(), stat);
        Ok(())
    }

    /// The arrays among ``compare`` (``None``: all) not kept per world in which the model
    /// now differs from world 0.
    #[pyo3(signature = (compare=None))]
    fn differing(&self, compare: Option<Vec<String>>) -> PyResult<Vec<String>> {
        let inner = self.inner()?;
        let read = read(&inner.rows, &inner.views, compare.as_deref());
        let names = inner.rows.differing(|k| read.get(k).copied().flatten());
        Ok(names.into_iter().map(str::to_string).collect())
    }

    /// The model's values now of every array kept per world, and its statistics: one
    /// world's row of :meth:`arrays` (copies).
    fn row<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let inner = self.inner()?;
        let out = PyDict::new(py);
        let model = self.model.bind(py);
        for (name, _) in inner.rows.kept() {
            out.set_item(name, model.getattr(name)?.call_method0("copy")?)?;
        }
        statistics(py, &out, &[statistics_of(model)])?;
        for name in STATISTIC_NAMES {
            let key = format!("stat.{name}");
            let value = out.get_item(&key)?.map(|v| v.get_item(0)).transpose()?;
            if let Some(value) = value {
                out.set_item(key, value)?;
            }
        }
        Ok(out)
    }

    /// Every array kept per world, ``(nworld, ...)`` in the model's own element type, and
    /// ``stat.<name>`` (``(nworld,)``, ``center`` ``(nworld, 3)``).
    fn arrays<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let inner = self.inner()?;
        let numpy = upcalls::python_module(py, "numpy")?;
        let out = PyDict::new(py);
        let n = inner.rows.worlds();
        let names: Vec<&str> = inner.rows.names().collect();
        for (name, bytes) in inner.rows.kept() {
            let k = names.iter().position(|m| *m == name).unwrap_or(0);
            let view = &inner.views[k];
            let mut shape = vec![n];
            shape.extend(&view.shape);
            let array = numpy
                .call_method1(
                    "frombuffer",
                    (PyBytes::new(py, bytes), view.typestr.as_str()),
                )?
                .call_method1("reshape", (shape,))?
                .call_method0("copy")?;
            out.set_item(name, array)?;
        }
        statistics(py, &out, inner.rows.statistics())?;
        Ok(out)
    }

    /// How many worlds were pushed.
    #[getter]
    fn worlds(&self) -> PyResult<usize> {
        Ok(self.inner()?.rows.worlds())
    }
}
