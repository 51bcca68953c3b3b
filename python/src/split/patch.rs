//! `PatchLanding`: where each entry of a patch of one layout lands in a user's `MjModel`
//! ([`mjcf_forge::split::land`], the rule both faces share), found once, and the writer of
//! that layout's numbers and ids into the model in place (`Run::write`). The package's
//! `Plan` (`mjcf_forge/_plan.py`) finds the element ids with the user's `mujoco`, and
//! writes the options (`mjOption` is a struct, no array) and the body models itself.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyString;

use super::arrays::Array;
use mjcf_forge::split::{self, ArrayMut, Carried, Landing, Run};

/// An array a run writes, by its element type.
enum Whole {
    F64(Array<f64>),
    F32(Array<f32>),
    I32(Array<i32>),
}

impl Whole {
    /// `array` of `model` as the type it holds (NumPy's type string).
    fn of(model: &Bound<'_, PyAny>, array: &str) -> PyResult<Whole> {
        let obj = model.getattr(array)?;
        let typestr: String = obj
            .getattr("__array_interface__")?
            .get_item("typestr")?
            .extract()?;
        Ok(match typestr.as_str() {
            "<f4" => Whole::F32(Array::of(&obj, array, true)?),
            "<i4" => Whole::I32(Array::of(&obj, array, true)?),
            _ => Whole::F64(Array::of(&obj, array, true)?),
        })
    }

    /// The array, to write.
    ///
    /// # Safety
    /// As for [`Array::slice_mut`].
    unsafe fn slice_mut(&self) -> ArrayMut<'_> {
        // SAFETY: as the caller promises.
        unsafe {
            match self {
                Whole::F64(a) => ArrayMut::F64(a.slice_mut()),
                Whole::F32(a) => ArrayMut::F32(a.slice_mut()),
                Whole::I32(a) => ArrayMut::I32(a.slice_mut()),
            }
        }
    }
}

/// The user's model as [`split::land`] reads it: integer arrays and lengths.
struct Layout<'a, 'py>(&'a Bound<'py, PyAny>);

impl split::ModelLayout for Layout<'_, '_> {
    fn int(&self, name: &str, i: usize) -> Result<i64, String> {
        self.0
            .getattr(name)
            .and_then(|a| a.get_item(i))
            .and_then(|v| v.extract::<i64>())
            .map_err(|_| format!("{name}[{i}]: no such integer"))
    }
    fn len(&self, name: &str) -> Result<usize, String> {
        self.0
            .getattr(name)
            .and_then(|a| a.getattr("size"))
            .and_then(|v| v.extract::<usize>())
            .map_err(|_| format!("this MuJoCo's MjModel has no array {name}"))
    }
}

/// A run of numbers (from `first` in the values laid end to end, `count` of them) and the
/// array it writes.
struct Target {
    run: Run,
    first: usize,
    count: usize,
    whole: Whole,
}

/// Where each entry of a patch of one layout lands in ``model``, found once
/// (``mjcf_forge::split::land``); :meth:`write` writes a patch of that layout.
///
/// ``PatchLanding(model, patch, ids)``: ``patch`` a sequence of ``(object, name, field,
/// value)``, ``ids`` each entry's element id in ``model`` (``None`` for an option).
/// ``options`` lists the option entries as ``(field, first, n)`` and ``geom_factors`` the
/// ``geom_factors`` entries as ``(body, first, n)``; they and the body-model entries
/// (``MODEL_FIELDS``) are the caller's to write.
///
/// >>> import mujoco, numpy as np
/// >>> from mjcf_forge._mjcf_forge import PatchLanding
/// >>> model = mujoco.MjModel.from_xml_string(
/// ...     '<mujoco><worldbody><body><joint name="j"/><geom size=".1"/></body></worldbody></mujoco>')
/// >>> landing = PatchLanding(model, [("joint", "j", "damping", [0.5])], [0])
/// >>> landing.write(np.array([0.5]), [])
/// >>> float(model.dof_damping[0])
/// 0.5
#[pyclass(name = "PatchLanding", module = "mjcf_forge._mjcf_forge", frozen)]
pub(crate) struct PyPatchLanding {
    numbers: Vec<Target>,
    /// The runs of material ids, in the order their ids are given to `write`.
    ids: Vec<(Run, Whole)>,
    /// The option entries: `(field, first, n)`.
    #[pyo3(get)]
    options: Vec<(String, usize, usize)>,
    /// The `geom_factors` entries: `(body, first, n)`.
    #[pyo3(get)]
    geom_factors: Vec<(usize, usize, usize)>,
}

#[pymethods]
impl PyPatchLanding {
    #[new]
    fn new(
        model: &Bound<'_, PyAny>,
        patch: Vec<Bound<'_, PyAny>>,
        ids: Vec<Option<usize>>,
    ) -> PyResult<Self> {
        if ids.len() != patch.len() {
            return Err(PyValueError::new_err("one id per patch entry"));
        }
        let mut out = PyPatchLanding {
            numbers: Vec::new(),
            ids: Vec::new(),
            options: Vec::new(),
            geom_factors: Vec::new(),
        };
        let layout = Layout(model);
        let mut first = 0;
        for (entry, id) in patch.iter().zip(ids) {
            let (object, _, field, value): (String, Bound<'_, PyAny>, String, Bound<'_, PyAny>) =
                entry.extract()?;
            let carried = if value.is_instance_of::<PyString>() {
                if split::MODEL_FIELDS.contains(&field.as_str()) {
                    Carried::BodyModel
                } else {
                    Carried::Id
                }
            } else {
                Carried::Numbers(value.len()?)
            };
            let landing = split::land(&object, id, &field, carried, &layout)
                .map_err(PyValueError::new_err)?;
            match landing {
                Landing::Numbers(run) => {
                    let whole = Whole::of(model, &run.array)?;
                    if run.id {
                        out.ids.push((run, whole));
                    } else {
                        let Carried::Numbers(count) = carried else {
                            unreachable!("a run of numbers carries numbers")
                        };
                        out.numbers.push(Target {
                            run,
                            first,
                            count,
                            whole,
                        });
                        first += count;
                    }
                }
                Landing::Option { field, n } => {
                    out.options.push((field, first, n));
                    first += n;
                }
                Landing::GeomFactors { body, n } => {
                    out.geom_factors.push((body, first, n));
                    first += n;
                }
                Landing::BodyModel { .. } => {}
            }
        }
        Ok(out)
    }

    /// Writes a patch of this layout: its numbers laid end to end (``values``, a
    /// C-contiguous float64 array) and the ids of its materials in order (``material_ids``).
    fn write(&self, values: &Bound<'_, PyAny>, material_ids: Vec<usize>) -> PyResult<()> {
        let values = Array::<f64>::of(values, "values", false)?;
        // SAFETY: the GIL is held and no Python code runs while the slice lives; the
        // values are not the model's.
        let values = unsafe { values.slice() };
        if material_ids.len() != self.ids.len() {
            return Err(PyValueError::new_err(format!(
                "{} material ids for {} entries",
                material_ids.len(),
                self.ids.len()
            )));
        }
        for t in &self.numbers {
            let v = values.get(t.first..t.first + t.count).ok_or_else(|| {
                PyValueError::new_err(format!("{} numbers: too few for this layout", values.len()))
            })?;
            // SAFETY: the only view of the model's array while it is written (the GIL is
            // held, no Python code runs).
            t.run
                .write(unsafe { t.whole.slice_mut() }, v)
                .map_err(PyValueError::new_err)?;
        }
        for ((run, whole), &id) in self.ids.iter().zip(&material_ids) {
            // SAFETY: as above.
            run.write_id(unsafe { whole.slice_mut() }, id)
                .map_err(PyValueError::new_err)?;
        }
        Ok(())
    }
}
