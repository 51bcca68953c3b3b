//! The extern declarations of `render.c` and their wrappers, each stating what it needs of
//! its caller; the rest of the tier goes through them.

use std::ffi::{CStr, c_char, c_int};
use std::ptr::NonNull;

use crate::mujoco::MjModel;

/// `mjfGl`, opaque: a headless OpenGL context of `render.c`.
#[repr(C)]
pub(super) struct RawGl {
    _opaque: [u8; 0],
}

unsafe extern "C" {
    fn mjf_gl_new(
        backend: c_int,
        width: c_int,
        height: c_int,
        err: *mut c_char,
        err_len: c_int,
    ) -> *mut RawGl;
    fn mjf_gl_kind(gl: *const RawGl) -> *const c_char;
    fn mjf_gl_make_current(gl: *mut RawGl) -> c_int;
    fn mjf_gl_free(gl: *mut RawGl);
    fn mjf_sheet_inputs(
        m: *const MjModel,
        cam: *mut f64,
        fovy: *mut f64,
        xpos: *mut f64,
        collides: *mut c_int,
    ) -> c_int;
    fn mjf_geom_rbound(m: *const MjModel, rbound: *mut f64) -> c_int;
    fn mjf_render(
        m: *mut MjModel,
        width: c_int,
        height: c_int,
        free_cam: *const f64,
        camid: c_int,
        groups_set: *const c_int,
        groups_on: *const c_int,
        segment: c_int,
        rgb: *mut u8,
        seg: *mut c_int,
        err: *mut c_char,
        err_len: c_int,
    ) -> c_int;
}

const ERR_LEN: usize = 1024;

/// The text `render.c` wrote into `buf`.
fn message(buf: &[c_char]) -> String {
    // SAFETY: `buf` is zeroed before the call and its last byte is never written (the C
    // side writes at most `len - 1` bytes and a NUL).
    unsafe { CStr::from_ptr(buf.as_ptr()) }
        .to_string_lossy()
        .into_owned()
}

/// A context made current on this thread, or every reason none could be made.
pub(super) fn gl_new(
    backend: c_int,
    width: c_int,
    height: c_int,
) -> Result<NonNull<RawGl>, String> {
    let mut err = vec![0 as c_char; ERR_LEN];
    // SAFETY: `err` holds `ERR_LEN` bytes, as the C side is told.
    let gl = unsafe {
        mjf_gl_new(
            backend,
            width,
            height,
            err.as_mut_ptr(),
            ERR_LEN as c_int - 1,
        )
    };
    NonNull::new(gl).ok_or_else(|| message(&err))
}

/// `"egl"` or `"osmesa"`.
pub(super) fn gl_kind(gl: NonNull<RawGl>) -> &'static str {
    // SAFETY: `gl` is live; the C side returns one of two static strings.
    let kind = unsafe { CStr::from_ptr(mjf_gl_kind(gl.as_ptr())) };
    if kind.to_bytes() == b"egl" {
        "egl"
    } else {
        "osmesa"
    }
}

/// Makes `gl` current on this thread; false when the platform refuses.
pub(super) fn gl_make_current(gl: NonNull<RawGl>) -> bool {
    // SAFETY: `gl` is live (made by `gl_new`, not freed).
    unsafe { mjf_gl_make_current(gl.as_ptr()) != 0 }
}

/// # Safety
/// `gl` came from [`gl_new`] and is not used afterwards.
pub(super) unsafe fn gl_free(gl: NonNull<RawGl>) {
    // SAFETY: see the contract.
    unsafe { mjf_gl_free(gl.as_ptr()) }
}

/// What the sheet's rules read of a model (see `mjf_sheet_inputs`).
pub(super) struct SheetInputs {
    /// `mjv_defaultFreeCamera`'s lookat (3), distance, azimuth and elevation.
    pub default_cam: [f64; 6],
    /// `<visual><global fovy>`.
    pub fovy: f64,
    /// Per geom at `qpos0`: its world position; `None` when not asked for or when mjData
    /// could not be made.
    pub xpos: Option<Vec<[f64; 3]>>,
    /// Per geom: whether it collides.
    pub collides: Vec<bool>,
    /// Per geom: its bounding sphere's radius.
    pub rbound: Vec<f64>,
    /// MuJoCo's number of geom groups (`mjNGROUP`).
    pub ngroup: usize,
}

/// What the sheet's rules read of `m`, which has `ngeom` geoms; the geoms' positions at
/// `qpos0` only with `pose` (they need an mjData).
pub(super) fn sheet_inputs(m: &MjModel, ngeom: usize, pose: bool) -> SheetInputs {
    let mut cam = [0.0; 6];
    let mut fovy = 0.0;
    let mut xpos = vec![0.0; if pose { ngeom * 3 } else { 0 }];
    let mut collides: Vec<c_int> = vec![0; ngeom];
    let mut rbound = vec![0.0; ngeom];
    // SAFETY: `m` is live and only read, with `ngeom` geoms; the buffers hold what is
    // written: six numbers, one, 3 per geom (or NULL, not written), one per geom, one per
    // geom.
    let (made, ngroup) = unsafe {
        let made = mjf_sheet_inputs(
            m,
            cam.as_mut_ptr(),
            &mut fovy,
            if pose {
                xpos.as_mut_ptr()
            } else {
                std::ptr::null_mut()
            },
            collides.as_mut_ptr(),
        );
        (made == 0, mjf_geom_rbound(m, rbound.as_mut_ptr()))
    };
    SheetInputs {
        default_cam: cam,
        fovy,
        xpos: (made && pose).then(|| xpos.chunks(3).map(|p| [p[0], p[1], p[2]]).collect()),
        collides: collides.iter().map(|c| *c != 0).collect(),
        rbound,
        ngroup: usize::try_from(ngroup).unwrap_or(0),
    }
}

/// What one render asks for (see `mjf_render` in `render.c`).
pub(super) struct Job {
    pub width: c_int,
    pub height: c_int,
    pub free_cam: [f64; 6],
    pub camid: c_int,
    /// Each geom's group for the render (`ngeom` of them), or the compiled ones.
    pub groups: Option<Vec<c_int>>,
    /// Which of the `mjNGROUP` geom groups are drawn, or MuJoCo's default option.
    pub groups_on: Option<Vec<c_int>>,
    /// Also the geom id of every pixel.
    pub segment: bool,
}

/// Renders `m` with the GL context current on this thread: the pixels (bottom row first)
/// and, for a segmentation job, each pixel's geom id (-1 for none).
///
/// # Safety
/// `m` is a live model nobody else reads or writes during the call (it is changed and
/// restored), with as many geoms as `job.groups` has (when set), and an OpenGL context of
/// [`gl_new`] is current on this thread; `job.groups_on` (when set) has `mjNGROUP` flags.
pub(super) unsafe fn render(m: *mut MjModel, job: &Job) -> Result<(Vec<u8>, Vec<i32>), String> {
    let pixels = job.width as usize * job.height as usize;
    let mut rgb = vec![0u8; pixels * 3];
    let mut seg = if job.segment {
        vec![-1; pixels]
    } else {
        Vec::new()
    };
    let mut err = vec![0 as c_char; ERR_LEN];
    // SAFETY: see the contract; `rgb` holds width x height x 3 bytes and `seg` width x
    // height ints when segmenting (NULL otherwise, never written then); `err` holds
    // `ERR_LEN` bytes; the groups are NULL or as long as the contract says.
    let code = unsafe {
        mjf_render(
            m,
            job.width,
            job.height,
            job.free_cam.as_ptr(),
            job.camid,
            job.groups.as_ref().map_or(std::ptr::null(), |g| g.as_ptr()),
            job.groups_on
                .as_ref()
                .map_or(std::ptr::null(), |g| g.as_ptr()),
            c_int::from(job.segment),
            rgb.as_mut_ptr(),
            if job.segment {
                seg.as_mut_ptr()
            } else {
                std::ptr::null_mut()
            },
            err.as_mut_ptr(),
            ERR_LEN as c_int - 1,
        )
    };
    if code == 0 {
        Ok((rgb, seg))
    } else {
        Err(message(&err))
    }
}
