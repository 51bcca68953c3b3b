//! One compiled model patched in place: a [`PatchPlan`], the one implementation both
//! faces' model caches run. Made once per model, it finds where each entry of a patch
//! lands ([`land`], with element ids found by the model's own MuJoCo) once per layout,
//! writes a patch's numbers, material ids, `mjOption` fields, body models and geom masses,
//! and then what follows from the values: `mj_setConst` (or a caller's derivation that
//! writes the same), the compiler's statistics at `qpos0` ([`statistics`]) and the
//! statistics the document fixes ([`keep_fixed`]).
//!
//! The MuJoCo is the model's, behind [`PatchModel`]: the linked library's
//! (`crate::compiled`, through `patch.c`) or the user's `mujoco` (the Python package,
//! `python/src/split/plan.rs`). Each implements only what its MuJoCo does: find an array,
//! a name's id, compile a body model, run `mj_setConst` and the kinematics.
//!
//! ```
//! use mjcf_forge::split::{LayoutEntry, Carried};
//!
//! // A patch's layout: which field of which element each entry writes, and what it carries.
//! let entry = LayoutEntry::new("joint", "hinge", None, "damping", Carried::Numbers(1));
//! assert_eq!(entry.field, "damping");
//! ```

use super::body_copy::{MasslessFrame, ModelArrays, ModelArraysMut, copy_body_model};
use super::geom_masses::write_geom_masses;
use super::landing::{ArrayMut, Carried, Landing, ModelLayout, Run, land};
use super::massless_frames;
use super::patch_error;
use super::rules::{PatchEntry, PatchValue};
use super::statistics::{StatArrays, Statistics, keep_fixed, mean_inertia, statistics};
use super::targets::{BODY_MODELS_KEPT, PATCH_OBJECTS};
use crate::error::Error;

/// A compiled model a [`PatchPlan`] writes into, with what its own MuJoCo does for it.
///
/// Its errors are the face's words as an [`ErrorKind::Patch`](crate::ErrorKind::Patch)
/// (as are those of [`ModelArrays`], [`ModelLayout`] and
/// [`TreeModel`](super::TreeModel)); the plan passes them on as they are.
pub trait PatchModel: ModelArraysMut + ModelLayout {
    /// An array the plan writes, found once (where it starts, its type and length).
    type Target;
    /// A model compiled from MJCF text by the same MuJoCo: a body model or unit model.
    type Part: ModelArrays;
    /// Scratch data of this model (`mj_setConst` overwrites the qpos of the data it is
    /// given; the statistics read its kinematics at `qpos0`).
    type Data;

    /// The array `name` (of integers: `int`), to write; an error names an array this
    /// MuJoCo does not have.
    fn target(&mut self, name: &str, int: bool) -> Result<Self::Target, Error>;
    /// The whole array `target` (one of this model's), to write.
    fn target_mut<'a>(&'a mut self, target: &'a Self::Target) -> ArrayMut<'a>;
    /// The size `name` (`nbody`); `None` where this MuJoCo has none.
    fn size(&self, name: &str) -> Option<usize>;
    /// `mj_name2id`: the id of the element of patch object type `object` (a
    /// [`PATCH_OBJECTS`] entry's, or `material`) named `name`.
    fn id(&self, object: &str, name: &str) -> Option<usize>;
    /// Whether this MuJoCo's `mjOption` has a field `field` of `n` numbers.
    fn has_option(&self, field: &str, n: usize) -> bool;
    /// Writes `values` into the `mjOption` field `field`.
    fn write_option(&mut self, field: &str, values: &[f64]) -> Result<(), Error>;
    /// The name of body `body`, for errors (asked once per layout resolved).
    fn body_name(&self, body: usize) -> String;
    /// `xml` compiled by this model's MuJoCo.
    fn compile_part(&self, xml: &str) -> Result<Self::Part, Error>;
    /// New scratch data for this model.
    fn make_data(&self) -> Result<Self::Data, Error>;
    /// Bytes held by this model and `data`.
    fn nbytes(&self, data: &Self::Data) -> usize;
    /// `mj_setConst`.
    fn set_const(&mut self, data: &mut Self::Data) -> Result<(), Error>;
    /// `data.qpos` set to `qpos0`, then `mj_kinematics` and `mj_comPos`.
    fn kinematics(&mut self, data: &mut Self::Data) -> Result<(), Error>;
    /// The joint-space inertia from the kinematics (`mj_makeM`, or `mj_crb` where MuJoCo
    /// has no `mj_makeM`).
    fn inertia(&mut self, data: &mut Self::Data) -> Result<(), Error>;
    /// Calls `f` with the arrays the statistics read (of this model and `data`) and this
    /// model's `dof_length` (empty where this MuJoCo has none).
    fn with_statistics<R>(
        &mut self,
        data: &Self::Data,
        f: impl FnOnce(&StatArrays<'_>, &mut [f64]) -> R,
    ) -> Result<R, Error>;
    /// The model's statistics, in [`STATISTIC_NAMES`](super::STATISTIC_NAMES)' order.
    fn stat(&self) -> Statistics;
    /// Sets the model's statistics.
    fn set_stat(&mut self, stat: &Statistics) -> Result<(), Error>;
}

/// A derivation in place of `mj_setConst` ([`PatchPlan::finish`]): given the model, its
/// scratch data and the layout resolved, it writes what `mj_setConst` would and says
/// whether the data then holds the kinematics at `qpos0`.
pub type Derive<'a, M> =
    &'a mut dyn FnMut(&mut M, &mut <M as PatchModel>::Data, &[LayoutEntry]) -> Result<bool, Error>;

/// One entry of a patch's layout: the element and field it writes and what it carries
/// (the value itself is the patch's: [`PatchPlan::write`] takes them laid out by kind).
#[derive(Clone, Debug, PartialEq)]
pub struct LayoutEntry {
    /// The element's type (`body`, `geom`...), or `option`.
    pub object: String,
    /// The element's name; empty for an unnamed element, which `id` then identifies.
    pub name: String,
    /// The element's id, for an unnamed one.
    pub id: Option<usize>,
    /// The field (`rgba`, `geoms`, `geom_factors`...).
    pub field: String,
    /// What the entry carries.
    pub carried: Carried,
}

impl LayoutEntry {
    /// An entry of `object` `name` (or id `id`) writing `field`, carrying `carried`.
    pub fn new(
        object: &str,
        name: &str,
        id: Option<usize>,
        field: &str,
        carried: Carried,
    ) -> LayoutEntry {
        LayoutEntry {
            object: object.to_string(),
            name: name.to_string(),
            id,
            field: field.to_string(),
            carried,
        }
    }

    /// The layout entry of a patch entry.
    pub fn of(e: &PatchEntry) -> LayoutEntry {
        LayoutEntry::new(e.object, &e.name, e.id, e.field, carried(&e.value))
    }

    /// Whether this is the layout entry of `e`.
    fn is_of(&self, e: &PatchEntry) -> bool {
        self.object == e.object
            && self.name == e.name
            && self.id == e.id
            && self.field == e.field
            && self.carried == carried(&e.value)
    }
}

/// What `value` carries, as far as where it lands goes.
fn carried(value: &PatchValue) -> Carried {
    match value {
        PatchValue::Numbers(v) => Carried::Numbers(v.len()),
        PatchValue::Id { .. } => Carried::Id,
        PatchValue::BodyModel(_) => Carried::BodyModel,
    }
}

/// A patch of a resolved layout, its values laid out by kind in the layout's order.
#[derive(Clone, Copy, Debug)]
pub struct PatchValues<'a, S: AsRef<str>> {
    /// The numbers of every entry that carries numbers, end to end.
    pub numbers: &'a [f64],
    /// The names of the materials the `Id` entries choose.
    pub materials: &'a [S],
    /// The MJCF texts of the body-model and unit-model entries.
    pub bodies: &'a [S],
}

/// A run of numbers (from `first` in the values laid end to end, `count` of them) and the
/// array it writes.
struct NumberTarget<T> {
    run: Run,
    first: usize,
    count: usize,
    target: T,
}

/// A body-model or unit-model entry: its body, whether it is the body's geoms (else a
/// unit model, which its `geom_factors` entry reads), its name (for errors), the text the
/// layout was resolved with, and the one last written into the model (`None`: not known).
struct BodyEntry {
    body: usize,
    name: String,
    geoms: bool,
    xml0: String,
    written: Option<String>,
}

/// How to patch one model: its scratch data, where each entry of the last layout lands
/// and the body models compiled so far.
pub struct PatchPlan<M: PatchModel> {
    /// The structure key of the model.
    pub key: String,
    /// The scratch data.
    pub data: M::Data,
    layout: Vec<LayoutEntry>,
    resolved: bool,
    numbers: Vec<NumberTarget<M::Target>>,
    ids: Vec<(Run, M::Target)>,
    options: Vec<(String, usize, usize)>,
    /// The `geom_factors` entries: body, first number, count, the body's name.
    factors: Vec<(usize, usize, usize, String)>,
    bodies: Vec<BodyEntry>,
    /// Body models and unit models compiled so far, by their text, the newest last.
    parts: Vec<(String, M::Part)>,
    /// The unit model of each body with one (an index into `parts`' texts).
    units: Vec<(usize, String)>,
    massless: Vec<(usize, MasslessFrame)>,
    /// The statistics the document fixes (bits as [`keep_fixed`] takes them) and their
    /// values as MuJoCo compiled them.
    fixed: u32,
    fixed_values: Statistics,
    nbytes: usize,
    compiled_parts: u64,
    /// How many times [`PatchPlan::finish`] ran.
    finishes: u64,
    /// A superset's parked roots seen so far, by name: the dofs of each one's subtree.
    subtree_dofs: Vec<(String, Vec<usize>)>,
}

impl<M: PatchModel> PatchPlan<M> {
    /// The plan of `model` (of structure `key`), its massless bodies' frames as it holds
    /// them now; `fixed` the statistics the document fixes, at `fixed_values`.
    pub fn new(model: &M, key: &str, fixed: u32, fixed_values: Statistics) -> Result<Self, Error> {
        let data = model.make_data()?;
        let nbytes = model.nbytes(&data);
        Ok(PatchPlan {
            key: key.to_string(),
            data,
            layout: Vec::new(),
            resolved: false,
            numbers: Vec::new(),
            ids: Vec::new(),
            options: Vec::new(),
            factors: Vec::new(),
            bodies: Vec::new(),
            parts: Vec::new(),
            units: Vec::new(),
            massless: massless_frames(model)?,
            fixed,
            fixed_values,
            nbytes,
            compiled_parts: 0,
            finishes: 0,
            subtree_dofs: Vec::new(),
        })
    }

    /// Bytes held: the model and the scratch data.
    pub fn nbytes(&self) -> usize {
        self.nbytes
    }

    /// How many body models and unit models this plan has compiled.
    pub fn compiled_parts(&self) -> u64 {
        self.compiled_parts
    }

    /// How many times [`PatchPlan::finish`] ran (a derivation made before another
    /// finish knows the model was patched some other way since).
    pub fn finishes(&self) -> u64 {
        self.finishes
    }

    /// How many body-model and unit-model entries the layout last resolved has.
    pub fn body_models(&self) -> usize {
        self.bodies.len()
    }

    /// The layout last resolved.
    pub fn layout(&self) -> &[LayoutEntry] {
        &self.layout
    }

    /// Where every entry of `layout` lands in `model`; the next [`PatchPlan::write`]
    /// takes a patch of it.
    pub fn resolve(&mut self, model: &mut M, layout: Vec<LayoutEntry>) -> Result<(), Error> {
        self.resolved = false;
        let (mut numbers, mut ids, mut options, mut factors, mut bodies) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut first = 0;
        for e in &layout {
            let id = element_id(model, e)?;
            let landing = land(&e.object, id, &e.field, e.carried, &*model)
                .map_err(|x| patch_error(format!("{} '{}': {x}", e.object, e.name)))?;
            match landing {
                Landing::Numbers(run) if run.id => {
                    let target = model.target(&run.array, run.int)?;
                    ids.push((run, target));
                }
                Landing::Numbers(run) => {
                    let Carried::Numbers(count) = e.carried else {
                        return Err(patch_error(format!(
                            "{} '{}': numbers expected",
                            e.object, e.name
                        )));
                    };
                    let target = model.target(&run.array, run.int)?;
                    numbers.push(NumberTarget {
                        run,
                        first,
                        count,
                        target,
                    });
                    first += count;
                }
                Landing::Option { field, n } => {
                    if !model.has_option(&field, n) {
                        return Err(patch_error(format!(
                            "this MuJoCo's mjOption has no field {field}"
                        )));
                    }
                    options.push((field, first, n));
                    first += n;
                }
                Landing::GeomFactors { body, n } => {
                    factors.push((body, first, n, model.body_name(body)));
                    first += n;
                }
                Landing::BodyModel { body } => bodies.push(BodyEntry {
                    body,
                    name: model.body_name(body),
                    geoms: e.field == "geoms",
                    xml0: String::new(),
                    written: None,
                }),
            }
        }
        (
            self.numbers,
            self.ids,
            self.options,
            self.factors,
            self.bodies,
        ) = (numbers, ids, options, factors, bodies);
        self.layout = layout;
        self.resolved = true;
        Ok(())
    }

    /// Writes `patch` (of any layout: resolved again where it differs from the last) and
    /// what follows from it ([`PatchPlan::finish`], with `mj_setConst`).
    pub fn apply(&mut self, model: &mut M, patch: &[PatchEntry]) -> Result<(), Error> {
        self.apply_with(model, patch, None)
    }

    /// Whether `patch` is of the layout last resolved (its next write lands as resolved).
    pub fn is_layout_of(&self, patch: &[PatchEntry]) -> bool {
        self.resolved
            && self.layout.len() == patch.len()
            && self.layout.iter().zip(patch).all(|(l, e)| l.is_of(e))
    }

    /// [`PatchPlan::apply`] with [`PatchPlan::finish`]'s `derive` in place of `mj_setConst`.
    pub fn apply_with(
        &mut self,
        model: &mut M,
        patch: &[PatchEntry],
        derive: Option<Derive<'_, M>>,
    ) -> Result<(), Error> {
        self.write_patch(model, patch)?;
        self.finish(model, derive)
    }

    /// Writes `patch` (of any layout: resolved again where it differs from the last), and
    /// nothing of what follows from it ([`PatchPlan::finish`]).
    pub fn write_patch(&mut self, model: &mut M, patch: &[PatchEntry]) -> Result<(), Error> {
        let same = self.is_layout_of(patch);
        let mut numbers = Vec::new();
        let (mut materials, mut bodies) = (Vec::new(), Vec::new());
        for e in patch {
            match &e.value {
                PatchValue::Numbers(v) => numbers.extend_from_slice(v),
                PatchValue::Id { name, .. } => materials.push(name.as_str()),
                PatchValue::BodyModel(xml) => bodies.push(xml.as_str()),
            }
        }
        if !same {
            self.resolve_patch(model, patch)?;
        }
        let values = PatchValues {
            numbers: &numbers,
            materials: &materials,
            bodies: &bodies,
        };
        self.write(model, values)
    }

    /// Where every entry of `patch` lands in `model` ([`PatchPlan::resolve`] of its
    /// layout), its body models taken as what the model holds.
    pub fn resolve_patch(&mut self, model: &mut M, patch: &[PatchEntry]) -> Result<(), Error> {
        self.resolve(model, patch.iter().map(LayoutEntry::of).collect())?;
        let bodies: Vec<&str> = patch
            .iter()
            .filter_map(|e| match &e.value {
                PatchValue::BodyModel(xml) => Some(xml.as_str()),
                _ => None,
            })
            .collect();
        self.set_resolved_bodies(&bodies);
        Ok(())
    }

    /// Records the body texts of the patch the layout was resolved with (a body model
    /// the arrays already hold, as compiled and as last written, is not written again).
    pub fn set_resolved_bodies<S: AsRef<str>>(&mut self, bodies: &[S]) {
        for (b, xml) in self.bodies.iter_mut().zip(bodies) {
            b.xml0 = xml.as_ref().to_string();
            b.written = None;
        }
    }

    /// Writes a patch of the resolved layout: its numbers, material ids, options, body
    /// models and geom masses (nothing of what follows from them: [`PatchPlan::finish`]).
    pub fn write<S: AsRef<str>>(
        &mut self,
        model: &mut M,
        values: PatchValues<'_, S>,
    ) -> Result<(), Error> {
        if !self.resolved {
            return Err(patch_error("the plan has no layout to write"));
        }
        if values.materials.len() != self.ids.len() || values.bodies.len() != self.bodies.len() {
            return Err(patch_error(format!(
                "{} material names and {} body models for a layout of {} and {}",
                values.materials.len(),
                values.bodies.len(),
                self.ids.len(),
                self.bodies.len()
            )));
        }
        let numbers = values.numbers;
        for t in &self.numbers {
            let v = numbers.get(t.first..t.first + t.count).ok_or_else(|| {
                patch_error(format!(
                    "{} numbers: too few for this layout",
                    numbers.len()
                ))
            })?;
            t.run.write(model.target_mut(&t.target), v)?;
        }
        for ((run, target), name) in self.ids.iter().zip(values.materials) {
            let name = name.as_ref();
            let id = model
                .id("material", name)
                .ok_or_else(|| patch_error(format!("no material named '{name}'")))?;
            run.write_id(model.target_mut(target), id)?;
        }
        for (field, first, n) in &self.options {
            let v = numbers.get(*first..first + n).ok_or_else(|| {
                patch_error(format!(
                    "{} numbers: too few for this layout",
                    numbers.len()
                ))
            })?;
            model.write_option(field, v)?;
        }
        for k in 0..self.bodies.len() {
            let xml = values.bodies[k].as_ref();
            let (body, geoms) = (self.bodies[k].body, self.bodies[k].geoms);
            if !geoms {
                // A unit model: its geom factors' entry reads it.
                self.compiled(model, k, xml)?;
                match self.units.iter_mut().find(|(b, _)| *b == body) {
                    Some(u) => u.1 = xml.to_string(),
                    None => self.units.push((body, xml.to_string())),
                }
                continue;
            }
            let b = &self.bodies[k];
            // As compiled and as last written: the arrays already hold it.
            if b.xml0 == xml && b.written.as_deref() == Some(xml) {
                continue;
            }
            self.bodies[k].written = None;
            let at = self.compiled(model, body, xml)?;
            let kept = self
                .massless
                .iter()
                .find(|(m, _)| *m == body)
                .map(|(_, f)| f);
            let name = model.body_name(body);
            copy_body_model(model, body, &name, kept, &self.parts[at].1)?;
            self.bodies[k].written = Some(xml.to_string());
        }
        for (body, first, n, name) in &self.factors {
            let (body, first, n) = (*body, *first, *n);
            let unit = self
                .units
                .iter()
                .find(|(b, _)| *b == body)
                .and_then(|(_, xml)| self.parts.iter().find(|(x, _)| x == xml))
                .ok_or_else(|| {
                    patch_error(format!("body '{name}': geom factors without a unit model"))
                })?;
            let factors = numbers.get(first..first + n).ok_or_else(|| {
                patch_error(format!(
                    "{} numbers: too few for this layout",
                    numbers.len()
                ))
            })?;
            write_geom_masses(model, body, name, &unit.1, factors)?;
        }
        Ok(())
    }

    /// The index of the compile of `xml` (a model of the geoms of the body of body entry
    /// `k`) in `parts`, compiled by the model's MuJoCo on first sight (the last
    /// [`BODY_MODELS_KEPT`] kept).
    fn compiled(&mut self, model: &M, k: usize, xml: &str) -> Result<usize, Error> {
        if let Some(at) = self.parts.iter().position(|(x, _)| x == xml) {
            return Ok(at);
        }
        let part = model.compile_part(xml).map_err(|e| {
            patch_error(format!(
                "body '{}': its geoms alone: {e}",
                self.bodies[k].name
            ))
        })?;
        self.compiled_parts += 1;
        if self.parts.len() >= BODY_MODELS_KEPT {
            self.parts.remove(0);
        }
        self.parts.push((xml.to_string(), part));
        Ok(self.parts.len() - 1)
    }

    /// What follows the values: `mj_setConst` (or `derive(model, data, layout)`, which
    /// writes the same and says whether the data then holds the kinematics at `qpos0`),
    /// the compiler's statistics and dof lengths, then the statistics the document fixes.
    pub fn finish(&mut self, model: &mut M, derive: Option<Derive<'_, M>>) -> Result<(), Error> {
        self.finishes += 1;
        let fresh = match derive {
            None => {
                model.set_const(&mut self.data)?;
                false
            }
            Some(derive) => derive(model, &mut self.data, &self.layout)?,
        };
        if !fresh {
            model.kinematics(&mut self.data)?;
        }
        model.inertia(&mut self.data)?;
        let previous = model.stat();
        let mut stat = model.with_statistics(&self.data, |arrays, lengths| {
            statistics(arrays, &previous, Some(lengths))
        })?;
        keep_fixed(&mut stat, self.fixed, &self.fixed_values);
        model.set_stat(&stat)
    }

    /// The mean of the joint-space inertia's diagonal over `dofs` (in order), from the
    /// scratch data as [`PatchPlan::finish`] left it: a superset world's
    /// `stat.meaninertia`, the dofs of what its variant places.
    pub fn mean_inertia(&self, model: &mut M, dofs: &[usize]) -> Result<f64, Error> {
        if dofs.is_empty() {
            return Err(patch_error("no dofs to take the mean inertia over"));
        }
        model.with_statistics(&self.data, |arrays, _| {
            mean_inertia(arrays, dofs.iter().copied())
        })
    }
}

impl<M: PatchModel> PatchPlan<M> {
    /// Superset: `stat.meaninertia` (which scales the constraint solver's tolerance) as the
    /// variant's own model has it, after [`PatchPlan::finish`]: the mean of the mass
    /// matrix's diagonal over the dofs of what the variant places (the superset's dof
    /// order is the variant's), the subtrees of the bodies named `parked` left out;
    /// nothing when no dof is left.
    pub fn variant_inertia<S: AsRef<str>>(
        &mut self,
        model: &mut M,
        parked: &[S],
    ) -> Result<(), Error> {
        let nv = model.ints("dof_bodyid")?.len();
        let mut out = vec![false; nv];
        for root in parked {
            let root = root.as_ref();
            let at = match self.subtree_dofs.iter().position(|(r, _)| r == root) {
                Some(at) => at,
                None => {
                    let dofs = subtree_dofs(model, root)?;
                    self.subtree_dofs.push((root.to_string(), dofs));
                    self.subtree_dofs.len() - 1
                }
            };
            for &d in &self.subtree_dofs[at].1 {
                out[d] = true;
            }
        }
        let keep: Vec<usize> = (0..nv).filter(|&d| !out[d]).collect();
        if keep.is_empty() {
            return Ok(());
        }
        let mut stat = model.stat();
        stat[0] = self.mean_inertia(model, &keep)?;
        model.set_stat(&stat)
    }
}

/// The dofs of the subtree of the body named `root` in `model`, in order.
fn subtree_dofs<M: PatchModel>(model: &M, root: &str) -> Result<Vec<usize>, Error> {
    let id = model
        .id("body", root)
        .ok_or_else(|| patch_error(format!("the superset has no body '{root}'")))?;
    let parent = model.ints("body_parentid")?;
    let mut inside = vec![false; parent.len()];
    *inside
        .get_mut(id)
        .ok_or_else(|| patch_error(format!("body '{root}': an id past the model's bodies")))? =
        true;
    // Bodies come after their parents: one pass marks the whole subtree.
    for b in 1..parent.len() {
        let up = usize::try_from(parent[b])
            .ok()
            .and_then(|p| inside.get(p).copied());
        inside[b] |= up == Some(true);
    }
    Ok(model
        .ints("dof_bodyid")?
        .iter()
        .enumerate()
        .filter(|&(_, &b)| usize::try_from(b).is_ok_and(|b| inside.get(b) == Some(&true)))
        .map(|(d, _)| d)
        .collect())
}

/// The id of `e`'s element in `model` (none for an option): its own, checked against the
/// model's count, or its name's.
fn element_id<M: PatchModel>(model: &M, e: &LayoutEntry) -> Result<Option<usize>, Error> {
    if e.object == "option" {
        return Ok(None);
    }
    let missing = || {
        patch_error(format!(
            "the patch names {} '{}', which the compiled model does not have",
            e.object, e.name
        ))
    };
    match e.id {
        Some(id) => {
            let count = PATCH_OBJECTS
                .iter()
                .find(|o| o.object == e.object)
                .and_then(|o| model.size(o.count));
            match count {
                Some(n) if id < n => Ok(Some(id)),
                _ => Err(missing()),
            }
        }
        None => model.id(&e.object, &e.name).map(Some).ok_or_else(missing),
    }
}
