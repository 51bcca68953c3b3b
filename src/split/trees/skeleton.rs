//! One kinematic tree of a superset compiled alone as a skeleton, and its values derived
//! there by MuJoCo's own `mj_setConst` (see the module above).

use std::collections::HashMap;

use super::super::patch_error;
use super::super::targets::{JOINT_TYPES, joint_widths};
use super::{Span, TreeModel, int_at, rows, span};
use crate::error::Error;

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
pub(super) struct Tree<M: TreeModel> {
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
    pub(super) fn new(model: &M, root: usize) -> Result<Tree<M>, Error> {
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
            return Err(patch_error("not a contiguous moving tree"));
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
            return Err(patch_error("the skeleton does not have the tree's layout"));
        }
        // The mass matrix's sparsity, as the superset's (the dofs' own rows).
        let (Ok(sk_nnz), Ok(nnz)) = (skeleton.ints("M_rownnz"), model.ints("M_rownnz")) else {
            // MuJoCo 3.3 has no M_rownnz to compare (mj_setConst on the whole model then).
            return Err(patch_error("this MuJoCo has no M_rownnz"));
        };
        let (sk_adr, adr) = (skeleton.ints("M_rowadr")?, model.ints("M_rowadr")?);
        let (sk_col, col) = (skeleton.ints("M_colind")?, model.ints("M_colind")?);
        for k in 0..count {
            let (a, b) = (before + k, start + k);
            let (na, nb) = (int_at(sk_nnz, a)?, int_at(nnz, b)?);
            if na != nb {
                return Err(patch_error(
                    "the skeleton's mass matrix is not laid out as the tree's",
                ));
            }
            let (pa, pb) = (int_at(sk_adr, a)?, int_at(adr, b)?);
            let same = (0..na).all(|i| {
                let (x, y) = (sk_col.get(pa + i), col.get(pb + i));
                matches!((x, y), (Some(&x), Some(&y)) if x as i64 - before as i64 == y as i64 - start as i64)
            });
            if !same {
                return Err(patch_error(
                    "the skeleton's mass matrix is not laid out as the tree's",
                ));
            }
        }
        let bspan = span(bodies[0], bodies.len());
        if let (Ok(sk_simple), Ok(simple)) =
            (skeleton.bytes("body_simple"), model.bytes("body_simple"))
        {
            let sk = rows(sk_simple, 1, &span(b0, bodies.len()))?;
            let m = rows(simple, 1, &bspan)?;
            if sk_simple[sk] != simple[m] {
                return Err(patch_error(
                    "the skeleton's mass matrix is not laid out as the tree's",
                ));
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
    pub(super) fn derive(&mut self, model: &M) -> Result<Vec<Vec<f64>>, Error> {
        let (b0, j0, d0, q0) = self.at;
        let nb = self.bodies.len();
        let sk = &mut self.skeleton;
        let copy_floats =
            |sk: &mut M, name: &str, mine: Span, theirs: &Span, n: usize| -> Result<(), Error> {
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

    pub(super) fn write(&self, model: &mut M, values: &[Vec<f64>]) -> Result<(), Error> {
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
) -> Result<String, Error> {
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
            .ok_or_else(|| patch_error("a joint of unknown type"))?;
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
