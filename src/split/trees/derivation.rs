//! What a layout lets a tree-by-tree derivation follow, a world's trees derived, and what
//! spans trees computed on the superset itself (see the module above).

use std::collections::{BTreeMap, HashMap};

use super::super::patch_error;
use super::super::plan::LayoutEntry;
use super::super::targets::{GEOM_FACTORS, MODEL_FIELDS};
use super::super::{target_array, write_frame_flags};
use super::skeleton::Tree;
use super::{TreeModel, int_at};
use crate::error::Error;

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
/// MuJoCo's tolerance for "the same frame" (kSameFrameEps, as the compiler's kFrameEps).
const FRAME_EPS: f64 = 1e-6;

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
    pub fn build(model: &M, layout: &[LayoutEntry]) -> Result<Option<TreeDerivation<M>>, Error> {
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
        let targets = |body: &str, target: &str| -> Result<(Vec<usize>, Vec<usize>), Error> {
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
    ) -> Result<(), Error> {
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
    fn frames(&self, model: &mut M, data: &mut M::Data) -> Result<(), Error> {
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
fn bodies_from_geoms<M: TreeModel>(model: &mut M) -> Result<(), Error> {
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
fn body_of<M: TreeModel>(model: &M, e: &LayoutEntry) -> Result<Option<usize>, Error> {
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
fn tied_bodies<M: TreeModel>(model: &M) -> Result<Option<Vec<bool>>, Error> {
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
            for &b in tendon_bodies
                .get(obj)
                .ok_or_else(|| patch_error("an actuator's tendon"))?
            {
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
                for &b in tendon_bodies
                    .get(j)
                    .ok_or_else(|| patch_error("an equality's tendon"))?
                {
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
