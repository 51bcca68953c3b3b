//! What `mj_setConst` derives for a superset world, tree by tree, for both faces.
//!
//! A world of a superset is the superset model with one variant's patch written in, then
//! `mj_setConst`. Most of that call's time goes to the inverse inertias of every body and
//! dof (`body_invweight0`, `dof_invweight0`, `dof_M0`), one solve with the whole model's
//! mass matrix per body, so it grows with every candidate the superset holds, placed or
//! parked. Yet each of those values depends on its own kinematic tree only (the mass
//! matrix is block diagonal by tree), and a world changes only the trees its patch writes
//! into: its placed candidates (parked ones are the same in every world).
//!
//! [`TreeDerivation`] does the same computation per tree: each tree the patch writes into
//! is compiled once alone as a skeleton (its bodies, inertials and joints, no geoms), and
//! per world the tree's values are copied into its skeleton, MuJoCo's own `mj_setConst`
//! runs there and the derived values are copied back; parked trees take the values of
//! their first computation. What spans trees is computed on the superset itself:
//! `body_subtreemass` (the same sums in the same order), the cameras' and lights'
//! reference frames (MuJoCo's kinematics at `qpos0`, then the same differences), and the
//! bodies' collision flags and margins from their geoms. The result is bit for bit what
//! `mj_setConst` gives (`python/tests/test_world_batch.py` compares every per-world array
//! of both ways); a layout that writes anything else `mj_setConst` reads (a robot's
//! armature, an actuated tree, a tendon) gets no derivation, and `mj_setConst` runs.
//!
//! [`Derivations`] keeps a plan's derivations by layout and decides, per patch, whether
//! one applies ([`Derivations::derive`]). Files: `skeleton.rs` (one tree compiled alone and
//! its values derived there), `derivation.rs` (what a layout lets through, the trees of a
//! world, what spans trees); this file the MuJoCo they need and the per-plan bookkeeping.

mod derivation;
mod skeleton;

use std::collections::HashMap;

use super::PatchModel;
use super::patch_error;
use super::plan::{LayoutEntry, PatchPlan};
use super::targets::LAYOUTS_KEPT;
use crate::error::Error;

pub use derivation::{FROM_GEOMS, TreeDerivation};

/// What a tree-by-tree derivation needs of a MuJoCo beyond a [`PatchModel`].
pub trait TreeModel: PatchModel + Sized {
    /// MJCF text compiled by this model's MuJoCo, as a model of its own (a skeleton).
    fn compile_model(&self, xml: &str) -> Result<Self, Error>;
    /// The value of MuJoCo's enum constant `name` (`mjWRAP_JOINT`, `mjTRN_BODY`,
    /// `mjEQ_JOINT`, `mjOBJ_SITE`...), as this MuJoCo numbers it.
    fn constant(&self, name: &str) -> Option<i32>;
    /// Whether this MuJoCo's `mj_setConst` sets the bodies', geoms' and sites' same-frame
    /// flags again from their frames (4.0 does; 3.17 keeps the compiler's): the face keeps
    /// the answer of [`TreeModel::sameframe_probe`] (one MuJoCo per process).
    fn recomputes_sameframe(&self) -> Result<bool, Error>;
    /// Asks this MuJoCo [`TreeModel::recomputes_sameframe`]'s question: a body's flag set
    /// to `mjSAMEFRAME_NONE` in a compiled model, then `mj_setConst`.
    fn sameframe_probe(&self) -> Result<bool, Error> {
        let xml = r#"<mujoco><worldbody><body><freejoint/><geom size=".1" pos=".1 0 0"/></body></worldbody></mujoco>"#;
        let mut model = self.compile_model(xml)?;
        let none = self
            .constant("mjSAMEFRAME_NONE")
            .and_then(|n| u8::try_from(n).ok())
            .ok_or_else(|| patch_error("this MuJoCo has no mjSAMEFRAME_NONE"))?;
        model.bytes_mut("body_sameframe")?[1] = none;
        let mut data = model.make_data()?;
        model.set_const(&mut data)?;
        Ok(model.bytes("body_sameframe")?[1] != none)
    }
    /// `mj_camlight` on `data` (its kinematics and centres of mass done).
    fn camlight(&mut self, data: &mut Self::Data) -> Result<(), Error>;
    /// Calls `f` with `data`'s `mjtNum` arrays `names`, in order.
    fn with_data<R>(
        &self,
        data: &Self::Data,
        names: &[&str],
        f: impl FnOnce(&[&[f64]]) -> R,
    ) -> Result<R, Error>;
}

/// An index range.
pub(super) type Span = std::ops::Range<usize>;

pub(super) fn span(first: usize, n: usize) -> Span {
    first..first + n
}

/// `a[i*w .. (i+1)*w]` rows `rows` of an array of width `w`.
pub(super) fn rows<T>(a: &[T], w: usize, r: &Span) -> Result<std::ops::Range<usize>, Error> {
    let range = r.start * w..r.end * w;
    if range.end > a.len() {
        return Err(patch_error("a tree's rows past its array"));
    }
    Ok(range)
}

pub(super) fn int_at(a: &[i32], i: usize) -> Result<usize, Error> {
    a.get(i)
        .and_then(|&v| usize::try_from(v).ok())
        .ok_or_else(|| patch_error(format!("no element {i}")))
}

/// A plan's tree-by-tree derivations, by the layout each follows (at most
/// [`LAYOUTS_KEPT`]), and the superset's body ids by name.
pub struct Derivations<M: TreeModel> {
    by_layout: Vec<(Vec<LayoutEntry>, Option<TreeDerivation<M>>)>,
    body_ids: HashMap<String, usize>,
    /// The plan's finish count after this one's last derivation.
    at: Option<u64>,
    /// Patches derived tree by tree so far.
    pub by_tree: u64,
}

impl<M: TreeModel> Default for Derivations<M> {
    fn default() -> Self {
        Derivations {
            by_layout: Vec::new(),
            body_ids: HashMap::new(),
            at: None,
            by_tree: 0,
        }
    }
}

impl<M: TreeModel> Derivations<M> {
    /// What follows a patch `plan` wrote into `model` ([`PatchPlan::finish`]): for a
    /// superset world (`parked`: the root bodies of the objects it parks) with `by_tree`,
    /// derived tree by tree where its layout allows, else `mj_setConst`; then for a
    /// superset the world's `stat.meaninertia` ([`PatchPlan::variant_inertia`]). Whether it
    /// was derived tree by tree. The rule both faces' caches follow.
    pub fn finish<S: AsRef<str>>(
        &mut self,
        plan: &mut PatchPlan<M>,
        model: &mut M,
        parked: Option<&[S]>,
        by_tree: bool,
    ) -> Result<bool, Error> {
        let mut derived = false;
        match parked.filter(|_| by_tree) {
            None => plan.finish(model, None)?,
            Some(roots) => {
                let finishes = plan.finishes();
                let mut derive = |m: &mut M, d: &mut M::Data, layout: &[LayoutEntry]| {
                    derived = self.derive(m, d, layout, roots, finishes)?;
                    Ok(derived)
                };
                plan.finish(model, Some(&mut derive))?;
            }
        }
        if let Some(roots) = parked {
            plan.variant_inertia(model, roots)?;
        }
        Ok(derived)
    }

    /// What `mj_setConst` derives for a superset world of `layout` whose objects named
    /// `parked` are parked: tree by tree where the layout allows (returns true: `data`
    /// then holds the kinematics at `qpos0`), else `mj_setConst` itself (false).
    /// `finishes`: the plan's count of finishes before this one (a derivation made before
    /// another finish starts again from scratch).
    pub fn derive<S: AsRef<str>>(
        &mut self,
        model: &mut M,
        data: &mut M::Data,
        layout: &[LayoutEntry],
        parked: &[S],
        finishes: u64,
    ) -> Result<bool, Error> {
        let at = match self.by_layout.iter().position(|(l, _)| l == layout) {
            Some(at) => at,
            None => {
                if self.by_layout.len() >= LAYOUTS_KEPT {
                    self.by_layout.clear();
                }
                let d = TreeDerivation::build(model, layout)?;
                self.by_layout.push((layout.to_vec(), d));
                self.by_layout.len() - 1
            }
        };
        // mj_setConst also counts the bodies with gravity compensation (ngravcomp, which
        // the engines read only to apply it at all: zero or not), a size no tree
        // derivation writes: where the patch turns that count to or from zero, mj_setConst
        // itself.
        let compensated = model.floats("body_gravcomp")?.iter().any(|&g| g > 0.0);
        let counted = model.size("ngravcomp").unwrap_or(0) > 0;
        let Some(derivation) = self.by_layout[at]
            .1
            .as_mut()
            .filter(|_| compensated == counted)
        else {
            model.set_const(data)?;
            return Ok(false);
        };
        if self.at != Some(finishes) {
            derivation.forget(); // patched another way since its last derivation
        }
        let mut roots = Vec::with_capacity(parked.len());
        for name in parked {
            let name = name.as_ref();
            let id = match self.body_ids.get(name) {
                Some(&id) => id,
                None => {
                    let id = model
                        .id("body", name)
                        .ok_or_else(|| patch_error(format!("the superset has no body '{name}'")))?;
                    self.body_ids.insert(name.to_string(), id);
                    id
                }
            };
            roots.push(id);
        }
        derivation.derive(model, data, &roots)?;
        self.at = Some(finishes + 1);
        self.by_tree += 1;
        Ok(true)
    }
}
