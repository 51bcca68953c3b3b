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
//! one applies ([`Derivations::derive`]).

use std::collections::{BTreeMap, HashMap};

use super::plan::{LayoutEntry, PatchPlan};
use super::targets::{GEOM_FACTORS, JOINT_TYPES, LAYOUTS_KEPT, MODEL_FIELDS, joint_widths};
use super::{PatchModel, target_array, write_frame_flags};

/// What a tree-by-tree derivation needs of a MuJoCo beyond a [`PatchModel`].
pub trait TreeModel: PatchModel + Sized {
    /// MJCF text compiled by this model's MuJoCo, as a model of its own (a skeleton).
    fn compile_model(&self, xml: &str) -> Result<Self, String>;
    /// The value of MuJoCo's enum constant `name` (`mjWRAP_JOINT`, `mjTRN_BODY`,
    /// `mjEQ_JOINT`, `mjOBJ_SITE`...), as this MuJoCo numbers it.
    fn constant(&self, name: &str) -> Option<i32>;
    /// Whether this MuJoCo's `mj_setConst` sets the bodies', geoms' and sites' same-frame
    /// flags again from their frames (4.0 does; 3.17 keeps the compiler's).
    fn recomputes_sameframe(&self) -> Result<bool, String>;
    /// `mj_camlight` on `data` (its kinematics and centres of mass done).
    fn camlight(&mut self, data: &mut Self::Data) -> Result<(), String>;
    /// Calls `f` with `data`'s `mjtNum` arrays `names`, in order.
    fn with_data<R>(
        &self,
        data: &Self::Data,
        names: &[&str],
        f: impl FnOnce(&[&[f64]]) -> R,
    ) -> Result<R, String>;
}

/// Patch targets `mj_setConst` reads: a tree written into through them is derived again.
const INPUTS: [&str; 10] = [
    "body_pos",
    "body_quat",
    "body_ipos",
    "body_iquat",
    "body_mass",
    "body_inertia",
    "jnt_pos",
    "jnt_axis",
    "qpos0",
    "dof_armature",
];
/// Patch targets `mj_setConst` does not read (its kinematics at `qpos0` reads geom and
/// site frames, but nothing it keeps depends on them), nor the statistics that follow it
/// through a path not taken here (geom sizes go through body models).
const UNREAD_PREFIXES: [&str; 4] = ["geom_", "mat_", "site_rgba", "key_"];
const UNREAD: [&str; 10] = [
    "light_diffuse",
    "light_specular",
    "light_ambient",
    "light_attenuation",
    "cam_fovy",
    "dof_damping",
    "dof_frictionloss",
    "jnt_stiffness",
    "qpos_spring",
    "body_gravcomp",
];
/// Per-tree values copied into a skeleton (bodies, joints, dofs) and the flags that steer
/// MuJoCo's computation (copied too: the skeleton's placeholder inertials set their own).
const BODY_FLOATS: [&str; 6] = [
    "body_pos",
    "body_quat",
    "body_ipos",
    "body_iquat",
    "body_mass",
    "body_inertia",
];
const BODY_BYTES: [&str; 2] = ["body_sameframe", "body_simple"];
const JOINT_FLOATS: [&str; 2] = ["jnt_pos", "jnt_axis"];
/// The derived values copied back: per body, per dof.
const BODY_OUT: [&str; 1] = ["body_invweight0"];
const DOF_OUT: [&str; 2] = ["dof_invweight0", "dof_M0"];

/// MuJoCo's tolerance for "the same frame" (kSameFrameEps, as the compiler's kFrameEps).
const FRAME_EPS: f64 = 1e-6;

/// An index range.
type Span = std::ops::Range<usize>;

fn span(first: usize, n: usize) -> Span {
    first..first + n
}

/// `a[i*w .. (i+1)*w]` rows `rows` of an array of width `w`.
fn rows<T>(a: &[T], w: usize, r: &Span) -> Result<std::ops::Range<usize>, String> {
    let range = r.start * w..r.end * w;
    if range.end > a.len() {
        return Err("a tree's rows past its array".into());
    }
    Ok(range)
}

fn int_at(a: &[i32], i: usize) -> Result<usize, String> {
    a.get(i)
        .and_then(|&v| usize::try_from(v).ok())
        .ok_or_else(|| format!("no element {i}"))
}

/// A number as MJCF text reads it back exactly.
fn num(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| format!("{v:?}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The width (elements per row) of array `a` over `n` rows.
fn width(len: usize, n: usize) -> usize {
    len.checked_div(n).unwrap_or(0)
}

/// One kinematic tree of the superset compiled alone as a skeleton, and where its bodies,
/// joints, dofs and coordinates sit in the superset (contiguous ranges) and in the
/// skeleton.
///
/// MuJoCo's dot products over all dofs (`mju_dot`, as in `body_invweight0`'s `J M^-1 J'`)
/// add in four interleaved partial sums, then the last `nv % 4` terms one by one: which
/// sum a term joins depends on its dof's index. So the skeleton puts its tree's dofs at
/// the superset's indices modulo 4 (slide joints of a padding body before them) and on the
/// same side of that tail (padding after them): the same terms, in the same sums, the
/// same bits.
struct Tree<M: TreeModel> {
    skeleton: M,
    data: M::Data,
    bodies: Span,
    joints: Span,
    dofs: Span,
    qpos: Span,
    /// The skeleton's first body, joint, dof and coordinate of the tree.
    at: (usize, usize, usize, usize),
}

impl<M: TreeModel> Tree<M> {
    fn new(model: &M, root: usize) -> Result<Tree<M>, String> {
        let rootid = model.ints("body_rootid")?;
        let bodies: Vec<usize> = (0..rootid.len())
            .filter(|&b| rootid[b] as usize == root)
            .collect();
        let in_tree =
            |b: i32| usize::try_from(b).is_ok_and(|b| rootid.get(b) == Some(&(root as i32)));
        let jnt_body = model.ints("jnt_bodyid")?;
        let joints: Vec<usize> = (0..jnt_body.len())
            .filter(|&j| in_tree(jnt_body[j]))
            .collect();
        let dof_body = model.ints("dof_bodyid")?;
        let dofs: Vec<usize> = (0..dof_body.len())
            .filter(|&d| in_tree(dof_body[d]))
            .collect();
        let contiguous = |v: &[usize]| v.last().is_some_and(|&l| l - v[0] + 1 == v.len());
        if !contiguous(&bodies) || joints.is_empty() || !contiguous(&joints) || !contiguous(&dofs) {
            return Err("not a contiguous moving tree".into());
        }
        let qposadr = model.ints("jnt_qposadr")?;
        let jnt_type = model.ints("jnt_type")?;
        let (j0, j1) = (joints[0], joints[joints.len() - 1]);
        let first = int_at(qposadr, j0)?;
        let last = int_at(qposadr, j1)?;
        let last_width = joint_widths(i64::from(jnt_type[j1])).1;
        let (start, count) = (dofs[0], dofs.len());
        let nv = dof_body.len();
        let before = start % 4;
        let after = if start + count <= nv - nv % 4 {
            (4 - (before + count) % 4) % 4
        } else {
            nv - start - count
        };
        let xml = skeleton_xml(model, &bodies, &joints, before, after)?;
        let skeleton = model.compile_model(&xml)?;
        let b0 = 1 + usize::from(before > 0);
        let sk_nbody = skeleton.ints("body_parentid")?.len();
        let sk_dofadr = skeleton.ints("jnt_dofadr")?;
        let sk_nv = skeleton.ints("dof_bodyid")?.len();
        if sk_nbody != bodies.len() + b0 + usize::from(after > 0)
            || sk_nv != before + count + after
            || sk_dofadr.get(before).copied() != Some(before as i32)
        {
            return Err("the skeleton does not have the tree's layout".into());
        }
        // The mass matrix's sparsity, as the superset's (the dofs' own rows).
        let (Ok(sk_nnz), Ok(nnz)) = (skeleton.ints("M_rownnz"), model.ints("M_rownnz")) else {
            // MuJoCo 3.3 has no M_rownnz to compare (mj_setConst on the whole model then).
            return Err("this MuJoCo has no M_rownnz".into());
        };
        let (sk_adr, adr) = (skeleton.ints("M_rowadr")?, model.ints("M_rowadr")?);
        let (sk_col, col) = (skeleton.ints("M_colind")?, model.ints("M_colind")?);
        for k in 0..count {
            let (a, b) = (before + k, start + k);
            let (na, nb) = (int_at(sk_nnz, a)?, int_at(nnz, b)?);
            if na != nb {
                return Err("the skeleton's mass matrix is not laid out as the tree's".into());
            }
            let (pa, pb) = (int_at(sk_adr, a)?, int_at(adr, b)?);
            let same = (0..na).all(|i| {
                let (x, y) = (sk_col.get(pa + i), col.get(pb + i));
                matches!((x, y), (Some(&x), Some(&y)) if x as i64 - before as i64 == y as i64 - start as i64)
            });
            if !same {
                return Err("the skeleton's mass matrix is not laid out as the tree's".into());
            }
        }
        let bspan = span(bodies[0], bodies.len());
        if let (Ok(sk_simple), Ok(simple)) =
            (skeleton.bytes("body_simple"), model.bytes("body_simple"))
        {
            let sk = rows(sk_simple, 1, &span(b0, bodies.len()))?;
            let m = rows(simple, 1, &bspan)?;
            if sk_simple[sk] != simple[m] {
                return Err("the skeleton's mass matrix is not laid out as the tree's".into());
            }
        }
        let data = skeleton.make_data()?;
        Ok(Tree {
            skeleton,
            data,
            bodies: bspan,
            joints: span(j0, joints.len()),
            dofs: span(start, count),
            qpos: first..last + last_width,
            at: (b0, before, before, before),
        })
    }

    /// The tree's derived values for the superset's current values.
    fn derive(&mut self, model: &M) -> Result<Vec<Vec<f64>>, String> {
        let (b0, j0, d0, q0) = self.at;
        let nb = self.bodies.len();
        let sk = &mut self.skeleton;
        let copy_floats =
            |sk: &mut M, name: &str, mine: Span, theirs: &Span, n: usize| -> Result<(), String> {
                let from = model.floats(name)?;
                let w = width(from.len(), n);
                let src = rows(from, w, theirs)?;
                let dst = sk.floats_mut(name)?;
                let d = rows(dst, w, &mine)?;
                dst[d].copy_from_slice(&from[src]);
                Ok(())
            };
        let nbody = model.ints("body_parentid")?.len();
        let njnt = model.ints("jnt_bodyid")?.len();
        let nv = model.ints("dof_bodyid")?.len();
        for name in BODY_FLOATS {
            copy_floats(sk, name, span(b0, nb), &self.bodies, nbody)?;
        }
        for name in BODY_BYTES {
            let Ok(from) = model.bytes(name) else {
                continue;
            };
            let src = rows(from, 1, &self.bodies)?;
            let values = from[src].to_vec();
            let dst = sk.bytes_mut(name)?;
            let d = rows(dst, 1, &span(b0, nb))?;
            dst[d].copy_from_slice(&values);
        }
        for name in JOINT_FLOATS {
            copy_floats(sk, name, span(j0, self.joints.len()), &self.joints, njnt)?;
        }
        copy_floats(
            sk,
            "dof_armature",
            span(d0, self.dofs.len()),
            &self.dofs,
            nv,
        )?;
        if let Ok(from) = model.ints("dof_simplenum") {
            let values = from[rows(from, 1, &self.dofs)?].to_vec();
            let dst = sk.ints_mut("dof_simplenum")?;
            let d = rows(dst, 1, &span(d0, self.dofs.len()))?;
            dst[d].copy_from_slice(&values);
        }
        {
            let from = model.floats("qpos0")?;
            let values = from[rows(from, 1, &self.qpos)?].to_vec();
            let dst = sk.floats_mut("qpos0")?;
            let d = rows(dst, 1, &span(q0, self.qpos.len()))?;
            dst[d].copy_from_slice(&values);
        }
        sk.set_const(&mut self.data)?;
        let mut out = Vec::new();
        for name in BODY_OUT {
            let a = sk.floats(name)?;
            let w = width(a.len(), sk.ints("body_parentid")?.len());
            out.push(a[rows(a, w, &span(b0, nb))?].to_vec());
        }
        for name in DOF_OUT {
            let a = sk.floats(name)?;
            out.push(a[rows(a, 1, &span(d0, self.dofs.len()))?].to_vec());
        }
        Ok(out)
    }

    fn write(&self, model: &mut M, values: &[Vec<f64>]) -> Result<(), String> {
        let nbody = model.ints("body_parentid")?.len();
        for (name, v) in BODY_OUT.iter().zip(values) {
            let a = model.floats_mut(name)?;
            let w = width(a.len(), nbody);
            let r = rows(a, w, &self.bodies)?;
            a[r].copy_from_slice(v);
        }
        for (name, v) in DOF_OUT.iter().zip(&values[BODY_OUT.len()..]) {
            let a = model.floats_mut(name)?;
            let r = rows(a, 1, &self.dofs)?;
            a[r].copy_from_slice(v);
        }
        Ok(())
    }
}

/// The tree's bodies and joints with placeholder inertials (every value that matters is
/// copied in before each use), between padding bodies of `before` and `after` slide
/// joints.
fn skeleton_xml<M: TreeModel>(
    model: &M,
    bodies: &[usize],
    joints: &[usize],
    before: usize,
    after: usize,
) -> Result<String, String> {
    let (jnt_body, jnt_type) = (model.ints("jnt_bodyid")?, model.ints("jnt_type")?);
    let (jnt_pos, jnt_axis) = (model.floats("jnt_pos")?, model.floats("jnt_axis")?);
    let (body_pos, body_quat) = (model.floats("body_pos")?, model.floats("body_quat")?);
    let parent = model.ints("body_parentid")?;
    let simple = model.bytes("body_simple").ok();
    let inertial = r#"<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>"#;
    // The compiler makes a body whose inertial frame is its own "simple" (a sparser mass
    // matrix): the skeleton's bodies are simple exactly where the superset's are.
    let offset = r#"<inertial pos=".01 .02 .03" quat=".9 .1 .2 .3" mass="1" diaginertia="1 1 1"/>"#;
    let mut joint_xml: HashMap<usize, String> = HashMap::new();
    for &j in joints {
        let kind = JOINT_TYPES
            .get(int_at(jnt_type, j)?)
            .ok_or("a joint of unknown type")?;
        joint_xml
            .entry(int_at(jnt_body, j)?)
            .or_default()
            .push_str(&format!(
                r#"<joint type="{kind}" pos="{}" axis="{}"/>"#,
                num(&jnt_pos[3 * j..3 * j + 3]),
                num(&jnt_axis[3 * j..3 * j + 3])
            ));
    }
    let mut out = String::from(r#"<mujoco><compiler angle="radian"/><worldbody>"#);
    let padding = |n: usize, out: &mut String| {
        if n > 0 {
            out.push_str("<body>");
            out.push_str(inertial);
            for _ in 0..n {
                out.push_str(r#"<joint type="slide" axis="1 0 0"/>"#);
            }
            out.push_str("</body>");
        }
    };
    padding(before, &mut out);
    // Depth first, children in id order, as the superset holds them.
    let mut stack: Vec<(usize, bool)> = vec![(bodies[0], false)];
    while let Some((b, closing)) = stack.pop() {
        if closing {
            out.push_str("</body>");
            continue;
        }
        out.push_str(&format!(
            r#"<body pos="{}" quat="{}">"#,
            num(&body_pos[3 * b..3 * b + 3]),
            num(&body_quat[4 * b..4 * b + 4])
        ));
        let is_simple = simple.is_none_or(|s| s.get(b) != Some(&0));
        out.push_str(if is_simple { inertial } else { offset });
        if let Some(j) = joint_xml.get(&b) {
            out.push_str(j);
        }
        stack.push((b, true));
        let children: Vec<usize> = bodies
            .iter()
            .copied()
            .filter(|&c| c != b && parent[c] as usize == b)
            .collect();
        for &c in children.iter().rev() {
            stack.push((c, false));
        }
    }
    padding(after, &mut out);
    out.push_str("</worldbody></mujoco>");
    Ok(out)
}

/// Which trees a world places or parks, as last written.
#[derive(Clone, Copy, PartialEq)]
enum State {
    Parked,
    Placed,
}

/// `mj_setConst` for a superset world, per tree (see the module).
pub struct TreeDerivation<M: TreeModel> {
    /// Per root the patch writes into: its skeleton (`None` for a tree welded to the
    /// world: nothing to derive but its flags).
    trees: BTreeMap<usize, Option<Tree<M>>>,
    /// Bodies, geoms and sites whose same-frame flags a patch may change.
    framed: (Vec<usize>, Vec<usize>, Vec<usize>),
    state: HashMap<usize, State>,
    parked: HashMap<usize, Vec<Vec<f64>>>,
    parent: Vec<usize>,
    cam: (Vec<usize>, Vec<usize>),
    light: (Vec<usize>, Vec<usize>),
    sameframe: bool,
}

/// Whether rows `i` of two quaternion arrays are the same rotation within MuJoCo's
/// same-frame tolerance (`q` or `-q`).
fn same_quat(a: &[f64], i: usize, b: [f64; 4]) -> bool {
    let q = &a[4 * i..4 * i + 4];
    (0..4).all(|k| (q[k] - b[k]).abs() < FRAME_EPS)
        || (0..4).all(|k| (q[k] + b[k]).abs() < FRAME_EPS)
}

impl<M: TreeModel> TreeDerivation<M> {
    /// The derivation for `model` (a superset) and patches of `layout`, or `None` when
    /// such a patch writes what it does not follow (`mj_setConst` then).
    pub fn build(model: &M, layout: &[LayoutEntry]) -> Result<Option<TreeDerivation<M>>, String> {
        if model.size("nflex").unwrap_or(0) > 0 {
            return Ok(None);
        }
        let rootid = model.ints("body_rootid")?;
        let geom_body = model.ints("geom_bodyid")?;
        let site_body = model.ints("site_bodyid")?;
        let mut roots: Vec<usize> = Vec::new();
        let mut framed_bodies: Vec<usize> = Vec::new();
        let (mut geoms, mut sites): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
        for e in layout {
            if e.object == "option" {
                continue;
            }
            let mut target = target_array(&e.object, &e.field);
            if MODEL_FIELDS.contains(&e.field.as_str()) || e.field == GEOM_FACTORS {
                target = Some("body_mass".to_string());
            }
            let t = target.as_deref();
            if matches!(t, Some("geom_pos" | "geom_quat" | "site_pos" | "site_quat")) {
                let Some(i) = id_of(model, e) else {
                    return Ok(None);
                };
                if e.object == "geom" {
                    geoms.push(i);
                } else {
                    sites.push(i);
                }
            }
            let Some(t) = t else { continue };
            if UNREAD_PREFIXES.iter().any(|p| t.starts_with(p)) || UNREAD.contains(&t) {
                continue;
            }
            if !INPUTS.contains(&t) {
                return Ok(None);
            }
            let Some(body) = body_of(model, e)? else {
                return Ok(None);
            };
            roots.push(int_at(rootid, body)?);
            if e.field == "geoms" {
                // A body model writes the geoms' frames too.
                framed_bodies.push(body);
                geoms.extend((0..geom_body.len()).filter(|&g| geom_body[g] as usize == body));
            } else if t == "body_ipos" || t == "body_iquat" || e.field == GEOM_FACTORS {
                framed_bodies.push(body);
            }
        }
        roots.retain(|&r| r != 0);
        roots.sort_unstable();
        roots.dedup();
        // A geom or site whose own frame no patch writes and whose orientation is its
        // body's keeps its flag (BODY or BODYROT) whatever the body's inertial frame.
        let unit = [1.0, 0.0, 0.0, 0.0];
        let (geom_quat, site_quat) = (model.floats("geom_quat")?, model.floats("site_quat")?);
        framed_bodies.sort_unstable();
        framed_bodies.dedup();
        for (g, &b) in geom_body.iter().enumerate() {
            if framed_bodies.contains(&(b as usize)) && !same_quat(geom_quat, g, unit) {
                geoms.push(g);
            }
        }
        for (s, &b) in site_body.iter().enumerate() {
            if framed_bodies.contains(&(b as usize)) && !same_quat(site_quat, s, unit) {
                sites.push(s);
            }
        }
        geoms.sort_unstable();
        geoms.dedup();
        sites.sort_unstable();
        sites.dedup();
        // A frame written outside the trees followed here: its flags would go stale.
        let owners = framed_bodies
            .iter()
            .copied()
            .chain(geoms.iter().map(|&g| geom_body[g] as usize))
            .chain(sites.iter().map(|&s| site_body[s] as usize));
        for b in owners {
            if !roots.contains(&int_at(rootid, b)?) {
                return Ok(None);
            }
        }
        let Some(tied) = tied_bodies(model)? else {
            return Ok(None);
        };
        let weld = model.ints("body_weldid")?;
        let mut trees = BTreeMap::new();
        for &root in &roots {
            let tree: Vec<usize> = (0..rootid.len())
                .filter(|&b| rootid[b] as usize == root)
                .collect();
            if tree.iter().any(|&b| tied[b]) {
                return Ok(None);
            }
            let moving = tree.iter().any(|&b| weld[b] != 0);
            let skeleton = if moving {
                match Tree::new(model, root) {
                    Ok(t) => Some(t),
                    Err(_) => return Ok(None),
                }
            } else {
                None
            };
            trees.insert(root, skeleton);
        }
        let parent = model
            .ints("body_parentid")?
            .iter()
            .map(|&p| p.max(0) as usize)
            .collect();
        let targets = |body: &str, target: &str| -> Result<(Vec<usize>, Vec<usize>), String> {
            let b: Vec<usize> = model
                .ints(body)?
                .iter()
                .map(|&v| v.max(0) as usize)
                .collect();
            let t = model
                .ints(target)?
                .iter()
                .zip(&b)
                .map(|(&t, &b)| usize::try_from(t).unwrap_or(b))
                .collect();
            Ok((b, t))
        };
        Ok(Some(TreeDerivation {
            trees,
            framed: (framed_bodies, geoms, sites),
            state: HashMap::new(),
            parked: HashMap::new(),
            parent,
            cam: targets("cam_bodyid", "cam_targetbodyid")?,
            light: targets("light_bodyid", "light_targetbodyid")?,
            sameframe: model.recomputes_sameframe()?,
        }))
    }

    /// The model was patched some other way since the last call: every tree is derived
    /// again at the next.
    pub fn forget(&mut self) {
        self.state.clear();
    }

    /// Writes into `model` what `mj_setConst` derives from its values (`parked`: the root
    /// bodies of the candidates this world parks), in its order: same-frame flags, then
    /// the trees, subtree masses, cameras and lights, the bodies' flags from their geoms.
    /// `data` (scratch) is left with MuJoCo's kinematics and centres of mass at `qpos0`.
    pub fn derive(
        &mut self,
        model: &mut M,
        data: &mut M::Data,
        parked: &[usize],
    ) -> Result<(), String> {
        let mut changed = Vec::new();
        for &root in self.trees.keys() {
            let now = if parked.contains(&root) {
                State::Parked
            } else {
                State::Placed
            };
            // A tree parked in the last world too holds its values already.
            if now != State::Parked || self.state.get(&root) != Some(&State::Parked) {
                changed.push((root, now));
            }
        }
        if self.sameframe && !changed.is_empty() {
            let (b, g, s) = &self.framed;
            write_frame_flags(model, b, g, s)?;
        }
        for (root, now) in changed {
            if let Some(Some(tree)) = self.trees.get_mut(&root) {
                let values = match (now, self.parked.get(&root)) {
                    (State::Parked, Some(v)) => v.clone(),
                    _ => {
                        let v = tree.derive(model)?;
                        if now == State::Parked {
                            self.parked.insert(root, v.clone());
                        }
                        v
                    }
                };
                tree.write(model, &values)?;
            }
            self.state.insert(root, now);
        }
        // Subtree masses: the same sums in the same order as MuJoCo's.
        let mut mass = model.floats("body_mass")?.to_vec();
        for i in (1..mass.len()).rev() {
            let p = self.parent[i];
            mass[p] += mass[i];
        }
        model.floats_mut("body_subtreemass")?.copy_from_slice(&mass);
        self.frames(model, data)?;
        bodies_from_geoms(model)
    }

    /// MuJoCo's kinematics and centres of mass at `qpos0`, and from them the cameras' and
    /// lights' offsets from their bodies and subtree centres, as `mj_setConst` takes them
    /// (every camera and light held fixed).
    fn frames(&self, model: &mut M, data: &mut M::Data) -> Result<(), String> {
        let (ncam, nlight) = (self.cam.0.len(), self.light.0.len());
        if ncam == 0 && nlight == 0 {
            return model.kinematics(data);
        }
        let cam_mode = model.ints("cam_mode")?.to_vec();
        let light_mode = model.ints("light_mode")?.to_vec();
        model.ints_mut("cam_mode")?.fill(0);
        model.ints_mut("light_mode")?.fill(0);
        let r = model.kinematics(data).and_then(|()| model.camlight(data));
        model.ints_mut("cam_mode")?.copy_from_slice(&cam_mode);
        model.ints_mut("light_mode")?.copy_from_slice(&light_mode);
        r?;
        let names = [
            "xpos",
            "subtree_com",
            "cam_xpos",
            "cam_xmat",
            "light_xpos",
            "light_xdir",
        ];
        let offsets = |x: &[f64], bodies: &[usize], base: &[f64]| -> Vec<f64> {
            let mut out = Vec::with_capacity(x.len());
            for (i, &b) in bodies.iter().enumerate() {
                for k in 0..3 {
                    out.push(x[3 * i + k] - base[3 * b + k]);
                }
            }
            out
        };
        let (cam_pos0, cam_poscom0, cam_mat0, light_pos0, light_poscom0, light_dir0) = model
            .with_data(data, &names, |a| {
                let (xpos, com, cam_xpos, cam_xmat, light_xpos, light_xdir) =
                    (a[0], a[1], a[2], a[3], a[4], a[5]);
                (
                    offsets(cam_xpos, &self.cam.0, xpos),
                    offsets(cam_xpos, &self.cam.1, com),
                    cam_xmat.to_vec(),
                    offsets(light_xpos, &self.light.0, xpos),
                    offsets(light_xpos, &self.light.1, com),
                    light_xdir.to_vec(),
                )
            })?;
        if ncam > 0 {
            model.floats_mut("cam_pos0")?.copy_from_slice(&cam_pos0);
            model
                .floats_mut("cam_poscom0")?
                .copy_from_slice(&cam_poscom0);
            model.floats_mut("cam_mat0")?.copy_from_slice(&cam_mat0);
        }
        if nlight > 0 {
            model.floats_mut("light_pos0")?.copy_from_slice(&light_pos0);
            model
                .floats_mut("light_poscom0")?
                .copy_from_slice(&light_poscom0);
            model.floats_mut("light_dir0")?.copy_from_slice(&light_dir0);
        }
        Ok(())
    }
}

/// The arrays a tree-by-tree derivation writes from the geoms, as `mj_setConst` does
/// (a world's geom margins move its bodies' margins): `body_margin`, `body_contype`,
/// `body_conaffinity`.
pub const FROM_GEOMS: [&str; 3] = ["body_margin", "body_contype", "body_conaffinity"];

/// What `mj_setConst` also derives from the geoms and no tree derivation does: each
/// body's `contype` and `conaffinity` (its geoms' flags or-ed) and `margin` (their largest
/// margin, 0 without geoms): [`FROM_GEOMS`]. A body's geoms are contiguous, in body order.
fn bodies_from_geoms<M: TreeModel>(model: &mut M) -> Result<(), String> {
    let num = model.ints("body_geomnum")?.to_vec();
    let adr = model.ints("body_geomadr")?.to_vec();
    let margin = model.floats("geom_margin")?.to_vec();
    let contype = model.ints("geom_contype")?.to_vec();
    let conaffinity = model.ints("geom_conaffinity")?.to_vec();
    let mut body_margin = model.floats("body_margin")?.to_vec();
    let mut body_contype = model.ints("body_contype")?.to_vec();
    let mut body_conaffinity = model.ints("body_conaffinity")?.to_vec();
    for b in 0..num.len() {
        let n = num[b].max(0) as usize;
        if n == 0 {
            continue;
        }
        let g = adr[b].max(0) as usize;
        let geoms = g..g + n;
        body_margin[b] = margin[geoms.clone()].iter().copied().fold(0.0, f64::max);
        body_contype[b] = contype[geoms.clone()].iter().fold(0, |a, &c| a | c);
        body_conaffinity[b] = conaffinity[geoms].iter().fold(0, |a, &c| a | c);
    }
    let [margin, contype, conaffinity] = FROM_GEOMS;
    model.floats_mut(margin)?.copy_from_slice(&body_margin);
    model.ints_mut(contype)?.copy_from_slice(&body_contype);
    model
        .ints_mut(conaffinity)?
        .copy_from_slice(&body_conaffinity);
    Ok(())
}

/// The element id entry `e` names (its own, or by name).
fn id_of<M: TreeModel>(model: &M, e: &LayoutEntry) -> Option<usize> {
    match e.id {
        Some(id) => Some(id),
        None => model.id(&e.object, &e.name),
    }
}

/// The body entry `e` writes into (its joint's or geom's; `None` for a site's or an
/// unknown element).
fn body_of<M: TreeModel>(model: &M, e: &LayoutEntry) -> Result<Option<usize>, String> {
    let Some(i) = id_of(model, e) else {
        return Ok(None);
    };
    Ok(match e.object.as_str() {
        "site" => None,
        "joint" => Some(int_at(model.ints("jnt_bodyid")?, i)?),
        "geom" => Some(int_at(model.ints("geom_bodyid")?, i)?),
        _ => Some(i),
    })
}

/// Bodies an actuator, equality or tendon reaches (their trees' derived values are not
/// the tree's own: `actuator_acc0`, `eq_data`, `tendon_invweight0`); `None` where a
/// constant this MuJoCo should have is missing.
fn tied_bodies<M: TreeModel>(model: &M) -> Result<Option<Vec<bool>>, String> {
    let nbody = model.ints("body_parentid")?.len();
    let mut tied = vec![false; nbody];
    let c = |name: &str| model.constant(name);
    let (Some(wrap_joint), Some(wrap_site), Some(wrap_sphere), Some(wrap_cylinder)) = (
        c("mjWRAP_JOINT"),
        c("mjWRAP_SITE"),
        c("mjWRAP_SPHERE"),
        c("mjWRAP_CYLINDER"),
    ) else {
        return Ok(None);
    };
    let jnt_body = model.ints("jnt_bodyid")?;
    let site_body = model.ints("site_bodyid")?;
    let geom_body = model.ints("geom_bodyid")?;
    let mut tendon_bodies: Vec<Vec<usize>> = Vec::new();
    let (adr, num) = (model.ints("tendon_adr")?, model.ints("tendon_num")?);
    let (wtype, wobj) = (model.ints("wrap_type")?, model.ints("wrap_objid")?);
    for t in 0..adr.len() {
        let mut bodies = Vec::new();
        let first = adr[t].max(0) as usize;
        for w in first..first + num[t].max(0) as usize {
            let (kind, obj) = (wtype[w], wobj[w].max(0) as usize);
            if kind == wrap_joint {
                bodies.push(int_at(jnt_body, obj)?);
            } else if kind == wrap_site {
                bodies.push(int_at(site_body, obj)?);
            } else if kind == wrap_sphere || kind == wrap_cylinder {
                bodies.push(int_at(geom_body, obj)?);
            }
        }
        for &b in &bodies {
            tied[b] = true;
        }
        tendon_bodies.push(bodies);
    }
    let (
        Some(trn_joint),
        Some(trn_parent),
        Some(trn_site),
        Some(trn_crank),
        Some(trn_body),
        Some(trn_tendon),
    ) = (
        c("mjTRN_JOINT"),
        c("mjTRN_JOINTINPARENT"),
        c("mjTRN_SITE"),
        c("mjTRN_SLIDERCRANK"),
        c("mjTRN_BODY"),
        c("mjTRN_TENDON"),
    )
    else {
        return Ok(None);
    };
    let (trntype, trnid) = (
        model.ints("actuator_trntype")?,
        model.ints("actuator_trnid")?,
    );
    for i in 0..trntype.len() {
        let (kind, obj) = (trntype[i], trnid[2 * i].max(0) as usize);
        if kind == trn_joint || kind == trn_parent {
            tied[int_at(jnt_body, obj)?] = true;
        } else if kind == trn_site || kind == trn_crank {
            tied[int_at(site_body, obj)?] = true;
        } else if kind == trn_body {
            tied[obj] = true;
        } else if kind == trn_tendon {
            for &b in tendon_bodies.get(obj).ok_or("an actuator's tendon")? {
                tied[b] = true;
            }
        } else {
            tied.fill(true);
        }
    }
    let (Some(eq_joint), Some(eq_tendon), Some(obj_body), Some(obj_site)) = (
        c("mjEQ_JOINT"),
        c("mjEQ_TENDON"),
        c("mjOBJ_BODY"),
        c("mjOBJ_SITE"),
    ) else {
        return Ok(None);
    };
    let (eq_type, eq_objtype) = (model.ints("eq_type")?, model.ints("eq_objtype")?);
    let (obj1, obj2) = (model.ints("eq_obj1id")?, model.ints("eq_obj2id")?);
    for i in 0..eq_type.len() {
        let (kind, objtype) = (eq_type[i], eq_objtype[i]);
        for j in [obj1[i], obj2[i]] {
            let Ok(j) = usize::try_from(j) else {
                continue;
            };
            if kind == eq_joint {
                tied[int_at(jnt_body, j)?] = true;
            } else if kind == eq_tendon {
                for &b in tendon_bodies.get(j).ok_or("an equality's tendon")? {
                    tied[b] = true;
                }
            } else if objtype == obj_body {
                tied[j] = true;
            } else if objtype == obj_site {
                tied[int_at(site_body, j)?] = true;
            } else {
                tied.fill(true);
            }
        }
    }
    Ok(Some(tied))
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
    ) -> Result<bool, String> {
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
    ) -> Result<bool, String> {
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
                        .ok_or_else(|| format!("the superset has no body '{name}'"))?;
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
