//! The C face of the statistics after a patch: `patch.c` runs MuJoCo (`mj_setConst`, the
//! kinematics at `qpos0`) and hands over the arrays; the numbers are computed once for
//! both faces, by [`crate::split::statistics`].

use std::os::raw::c_longlong;

use super::sys::{RawData, mjf_patch_stat_arrays};
use crate::mujoco::{MjModel, slice_or_empty};
use crate::split::StatArrays;

/// `struct mjf_stat_arrays` of `patch.c`: the arrays of a model and its scratch data the
/// statistics read, with their counts.
#[repr(C)]
pub(super) struct RawStatArrays {
    xpos: *const f64,
    xipos: *const f64,
    xanchor: *const f64,
    site_xpos: *const f64,
    geom_xpos: *const f64,
    geom_rbound: *const f64,
    geom_size: *const f64,
    hfield_size: *const f64,
    body_mass: *const f64,
    inertia: *const f64,
    geom_type: *const i32,
    geom_dataid: *const i32,
    body_parentid: *const i32,
    body_geomadr: *const i32,
    body_geomnum: *const i32,
    jnt_bodyid: *const i32,
    jnt_type: *const i32,
    jnt_dofadr: *const i32,
    dof_jntid: *const i32,
    dof_bodyid: *const i32,
    m_rowadr: *const i32,
    m_rownnz: *const i32,
    dof_length: *mut f64,
    nbody: c_longlong,
    njnt: c_longlong,
    nsite: c_longlong,
    ngeom: c_longlong,
    nhfield: c_longlong,
    nv: c_longlong,
    ninertia: c_longlong,
}

/// Calls `f` with the statistics' arrays of `m` and `d` (the data as
/// `mjf_patch_set_const` left it) and the model's `dof_length`.
///
/// # Safety
/// `m` and `d` are live, of one structure, and nothing else touches them meanwhile.
pub(super) unsafe fn with_arrays<R>(
    m: *mut MjModel,
    d: *const RawData,
    f: impl FnOnce(&StatArrays<'_>, &mut [f64]) -> R,
) -> R {
    let mut raw = std::mem::MaybeUninit::<RawStatArrays>::zeroed();
    // SAFETY: live model and data; `raw` is a struct patch.c fills whole.
    let r = unsafe {
        mjf_patch_stat_arrays(m, d, raw.as_mut_ptr());
        raw.assume_init()
    };
    let n = |k: c_longlong| usize::try_from(k).unwrap_or(0);
    let (nbody, njnt, ngeom, nv) = (n(r.nbody), n(r.njnt), n(r.ngeom), n(r.nv));
    // SAFETY: each pointer addresses the model's or data's array of the count MuJoCo
    // declares for it; `dof_length` is an array of the model no other slice covers.
    unsafe {
        let (rowadr, rownnz) = (
            slice_or_empty(r.m_rowadr, nv),
            slice_or_empty(r.m_rownnz, nv),
        );
        let diagonal: Vec<i32> = rowadr.iter().zip(rownnz).map(|(a, n)| a + n - 1).collect();
        let arrays = StatArrays {
            xpos: slice_or_empty(r.xpos, 3 * nbody),
            xipos: slice_or_empty(r.xipos, 3 * nbody),
            xanchor: slice_or_empty(r.xanchor, 3 * njnt),
            site_xpos: slice_or_empty(r.site_xpos, 3 * n(r.nsite)),
            geom_xpos: slice_or_empty(r.geom_xpos, 3 * ngeom),
            geom_rbound: slice_or_empty(r.geom_rbound, ngeom),
            geom_type: slice_or_empty(r.geom_type, ngeom),
            geom_size: slice_or_empty(r.geom_size, 3 * ngeom),
            geom_dataid: slice_or_empty(r.geom_dataid, ngeom),
            hfield_size: slice_or_empty(r.hfield_size, 4 * n(r.nhfield)),
            body_parentid: slice_or_empty(r.body_parentid, nbody),
            body_geomadr: slice_or_empty(r.body_geomadr, nbody),
            body_geomnum: slice_or_empty(r.body_geomnum, nbody),
            body_mass: slice_or_empty(r.body_mass, nbody),
            jnt_bodyid: slice_or_empty(r.jnt_bodyid, njnt),
            jnt_type: slice_or_empty(r.jnt_type, njnt),
            jnt_dofadr: slice_or_empty(r.jnt_dofadr, njnt),
            dof_jntid: slice_or_empty(r.dof_jntid, nv),
            dof_bodyid: slice_or_empty(r.dof_bodyid, nv),
            inertia: slice_or_empty(r.inertia, n(r.ninertia)),
            inertia_diagonal: &diagonal,
        };
        let lengths: &mut [f64] = if nv == 0 || r.dof_length.is_null() {
            &mut []
        } else {
            std::slice::from_raw_parts_mut(r.dof_length, nv)
        };
        f(&arrays, lengths)
    }
}
