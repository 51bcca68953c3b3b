//! Where a patch entry lands in a compiled model, and how its numbers are written there:
//! the one rule both faces' model caches follow. Each face finds element ids with its own
//! MuJoCo (`mj_name2id`) and hands over its arrays: the C face the linked MuJoCo's
//! (`compiled/linked.rs`, for the patch plan), the Python face the user's `MjModel` in place
//! (`python/src/split/plan.rs`).
//!
//! ```
//! use mjcf_forge::Error;
//! use mjcf_forge::split::{ArrayMut, Carried, Landing, ModelLayout, land};
//!
//! // A model with one hinge joint (type 3) whose dof is 2 of 3.
//! struct Hinge;
//! impl ModelLayout for Hinge {
//!     fn int(&self, name: &str, _i: usize) -> Result<i64, Error> {
//!         Ok(if name == "jnt_type" { 3 } else { 2 })
//!     }
//!     fn len(&self, _name: &str) -> Result<usize, Error> {
//!         Ok(3)
//!     }
//! }
//! let Landing::Numbers(run) = land("joint", Some(0), "damping", Carried::Numbers(1), &Hinge)?
//! else {
//!     unreachable!()
//! };
//! assert_eq!((run.array.as_str(), run.offset, run.n), ("dof_damping", 2, 1));
//! let mut damping = [0.0; 3];
//! run.write(ArrayMut::F64(&mut damping), &[0.5])?;
//! assert_eq!(damping, [0.0, 0.0, 0.5]);
//! # Ok::<(), Error>(())
//! ```

use super::patch_error;
use super::targets::{DOF_FIELDS, GEOM_FACTORS, QPOS_FIELDS, joint_widths, target_array};
use crate::error::Error;

/// What a model's layout tells [`land`]: its integer arrays and every array's length.
pub trait ModelLayout {
    /// Element `i` of the `int` array `name`; an error names an array this model does
    /// not have or an index outside it.
    fn int(&self, name: &str, i: usize) -> Result<i64, Error>;
    /// How many numbers the array `name` holds (rows times columns).
    fn len(&self, name: &str) -> Result<usize, Error>;
}

/// What a patch entry carries, as far as where it lands goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Carried {
    /// This many numbers (one fills every element of its target, as a joint's damping
    /// fills each of its dofs).
    Numbers(usize),
    /// A name, whose element's id is written (a material chosen for a geom).
    Id,
    /// A body model or unit model (MJCF text: what MuJoCo derives from a body's geoms).
    BodyModel,
}

/// Where one patch entry lands.
#[derive(Clone, Debug, PartialEq)]
pub enum Landing {
    /// Numbers, or an id, in one array of the model.
    Numbers(Run),
    /// The body model or unit model of body `body` (the entry's field tells which; see
    /// [`MODEL_FIELDS`](super::MODEL_FIELDS)).
    BodyModel {
        /// The body's id.
        body: usize,
    },
    /// The densities or masses of the geoms of body `body`'s unit model, `n` numbers:
    /// written by [`write_geom_masses`](super::write_geom_masses).
    GeomFactors {
        /// The body's id.
        body: usize,
        /// How many numbers.
        n: usize,
    },
    /// A field of the model's `mjOption`, `n` numbers.
    Option {
        /// The field's name.
        field: String,
        /// How many numbers the entry carries.
        n: usize,
    },
}

/// `n` elements of `array` from `offset`, again every `stride` elements for `runs` runs
/// in all (a joint's rows of every keyframe, one row of `nq` per key; one run elsewhere).
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// The `mjModel` array.
    pub array: String,
    /// Where the first run starts.
    pub offset: usize,
    /// Elements per run.
    pub n: usize,
    /// How many runs (0: a model without keyframes, nothing written).
    pub runs: usize,
    /// Elements from one run's start to the next's.
    pub stride: usize,
    /// The array holds integers: an id (a material's) or collision bits.
    pub int: bool,
    /// The entry carries a name: its element's id is written ([`Run::write_id`]).
    pub id: bool,
}

/// A whole `mjModel` array, to write, by its element type.
#[derive(Debug)]
pub enum ArrayMut<'a> {
    /// `mjtNum`.
    F64(&'a mut [f64]),
    /// `float` (colours, material and light values).
    F32(&'a mut [f32]),
    /// `int`.
    I32(&'a mut [i32]),
}

/// The fields that hold integers: ids and collision bits.
const INT_FIELDS: [&str; 3] = ["matid", "contype", "conaffinity"];

/// Where the entry of `object`'s `field` lands in a model of `layout`: `id` is the
/// element's id in that model (found by the caller's MuJoCo; ignored for `option`).
pub fn land(
    object: &str,
    id: Option<usize>,
    field: &str,
    carried: Carried,
    layout: &impl ModelLayout,
) -> Result<Landing, Error> {
    if object == "option" {
        return match carried {
            Carried::Numbers(n) => Ok(Landing::Option {
                field: field.to_string(),
                n,
            }),
            _ => Err(patch_error(format!("option {field}: not numbers"))),
        };
    }
    let id = id.ok_or_else(|| patch_error(format!("{object} {field}: no element id")))?;
    let width = match carried {
        Carried::Numbers(n) => n,
        Carried::Id => 1,
        Carried::BodyModel => return Ok(Landing::BodyModel { body: id }),
    };
    if object == "body" && field == GEOM_FACTORS {
        return Ok(Landing::GeomFactors { body: id, n: width });
    }
    let array = target_array(object, field)
        .ok_or_else(|| patch_error(format!("a patch names no array for {object}.{field}")))?;
    let index = |name: &str, i: usize| -> Result<usize, Error> {
        usize::try_from(layout.int(name, i)?)
            .map_err(|_| patch_error(format!("{name}[{i}] is negative")))
    };
    let (mut runs, mut stride) = (1, 0);
    let (offset, n) = match object {
        "joint" if DOF_FIELDS.contains(&field) => {
            let (dofs, _) = joint_widths(layout.int("jnt_type", id)?);
            (index("jnt_dofadr", id)?, dofs)
        }
        "joint" if QPOS_FIELDS.contains(&field) => {
            let (_, n) = joint_widths(layout.int("jnt_type", id)?);
            if field == "key_qpos" {
                // The joint's rows of every keyframe: one row of nq per key.
                stride = layout.len("qpos0")?;
                runs = layout.len("key_qpos")?.checked_div(stride).unwrap_or(0);
            }
            (index("jnt_qposadr", id)?, n)
        }
        _ => (id * width, width),
    };
    let count = layout.len(&array)?;
    let end = offset + n + runs.saturating_sub(1) * stride;
    if runs > 0 && end > count {
        return Err(patch_error(format!(
            "{object} {id}: {array}[{offset}..{end}] is outside the model's {count}"
        )));
    }
    if let Carried::Numbers(k) = carried
        && k != 1
        && k != n
    {
        return Err(patch_error(format!(
            "{object} {id}: {k} numbers for {n} elements of {array}"
        )));
    }
    Ok(Landing::Numbers(Run {
        array,
        offset,
        n,
        runs,
        stride,
        int: INT_FIELDS.contains(&field),
        id: carried == Carried::Id,
    }))
}

impl Run {
    /// Writes `values` (one fills every element; else one per element) into `whole`,
    /// this run's array: a `float` array takes them rounded, as MuJoCo's compiler rounds
    /// them; an `int` array (ids, collision bits) takes whole numbers.
    pub fn write(&self, whole: ArrayMut<'_>, values: &[f64]) -> Result<(), Error> {
        if values.len() != 1 && values.len() != self.n {
            return Err(patch_error(format!(
                "{}: {} numbers for {} elements",
                self.array,
                values.len(),
                self.n
            )));
        }
        let value = |k: usize| {
            if values.len() == 1 {
                values[0]
            } else {
                values[k]
            }
        };
        match whole {
            ArrayMut::F64(a) if !self.int => self.fill(a, value),
            ArrayMut::F32(a) if !self.int => self.fill(a, |k| value(k) as f32),
            ArrayMut::I32(a) if self.int => self.fill(a, |k| value(k) as i32),
            _ => Err(patch_error(format!(
                "{}: not an array of that type",
                self.array
            ))),
        }
    }

    /// Writes the id `id` (of the element the entry names) into `whole`, this run's array
    /// of `int`.
    pub fn write_id(&self, whole: ArrayMut<'_>, id: usize) -> Result<(), Error> {
        let id = i32::try_from(id)
            .map_err(|_| patch_error(format!("{}: id {id} too large", self.array)))?;
        match whole {
            ArrayMut::I32(a) if self.int => self.fill(a, |_| id),
            _ => Err(patch_error(format!("{}: not an array of ids", self.array))),
        }
    }

    fn fill<T>(&self, a: &mut [T], value: impl Fn(usize) -> T) -> Result<(), Error> {
        for run in 0..self.runs {
            let start = self.offset + run * self.stride;
            let Some(rows) = a.get_mut(start..start + self.n) else {
                return Err(patch_error(format!(
                    "{}[{start}..] is outside the array",
                    self.array
                )));
            };
            for (k, x) in rows.iter_mut().enumerate() {
                *x = value(k);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two keys of a model of nq 9: a free joint (7 coordinates) then a hinge.
    struct Keys;
    impl ModelLayout for Keys {
        fn int(&self, name: &str, i: usize) -> Result<i64, Error> {
            Ok(match (name, i) {
                ("jnt_type", 0) => 0,
                ("jnt_type", _) => 3,
                ("jnt_qposadr", 0) => 0,
                ("jnt_qposadr", _) => 7,
                _ => return Err(patch_error(format!("no {name}"))),
            })
        }
        fn len(&self, name: &str) -> Result<usize, Error> {
            Ok(match name {
                "qpos0" => 8,
                "key_qpos" => 16,
                _ => 4,
            })
        }
    }

    #[test]
    fn a_joints_rows_of_every_key() {
        let Ok(Landing::Numbers(run)) =
            land("joint", Some(1), "key_qpos", Carried::Numbers(1), &Keys)
        else {
            panic!("not numbers")
        };
        let mut keys = [0.0; 16];
        run.write(ArrayMut::F64(&mut keys), &[2.0]).unwrap();
        assert_eq!(keys[7], 2.0);
        assert_eq!(keys[15], 2.0);
        assert_eq!(keys.iter().filter(|&&x| x != 0.0).count(), 2);
    }

    #[test]
    fn outside_the_array_is_an_error() {
        let e = land("geom", Some(1), "rgba", Carried::Numbers(4), &Keys).unwrap_err();
        assert!(matches!(e.kind, crate::ErrorKind::Patch(_)), "{e:?}");
        assert!(e.to_string().contains("outside"), "{e}");
    }

    #[test]
    fn the_wrong_type_is_an_error() {
        let run = Run {
            array: "geom_matid".into(),
            offset: 0,
            n: 1,
            runs: 1,
            stride: 0,
            int: true,
            id: true,
        };
        assert!(run.write(ArrayMut::F64(&mut [0.0]), &[1.0]).is_err());
        let mut ids = [0];
        run.write_id(ArrayMut::I32(&mut ids), 3).unwrap();
        assert_eq!(ids, [3]);
    }
}
