//! The extern declarations of `render.c` and their wrappers, each stating what it needs of
//! its caller; the rest of the tier goes through them.

use std::ffi::{CStr, CString, c_char, c_int};
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
    fn mjf_free_camera(m: *const MjModel, out: *mut f64);
    fn mjf_render(
        m: *mut MjModel,
        width: c_int,
        height: c_int,
        free_cam: *const f64,
        camid: c_int,
        geoms: c_int,
        label: *const c_char,
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

/// `mjv_defaultFreeCamera`'s lookat (3), distance, azimuth and elevation.
pub(super) fn free_camera(m: &MjModel) -> [f64; 6] {
    let mut out = [0.0; 6];
    // SAFETY: `m` is live and only read; `out` holds the six numbers written.
    unsafe { mjf_free_camera(m, out.as_mut_ptr()) };
    out
}

/// What one render asks for (see `mjf_render` in `render.c`).
pub(super) struct Job<'a> {
    pub width: c_int,
    pub height: c_int,
    pub free_cam: [f64; 6],
    pub camid: c_int,
    pub geoms: c_int,
    pub label: Option<&'a str>,
    /// Also the geom id of every pixel.
    pub segment: bool,
}

/// Renders `m` with the GL context current on this thread: the pixels (bottom row first)
/// and, for a segmentation job, each pixel's geom id (-1 for none).
///
/// # Safety
/// `m` is a live model nobody else reads or writes during the call (it is changed and
/// restored), and an OpenGL context of [`gl_new`] is current on this thread.
pub(super) unsafe fn render(m: *mut MjModel, job: &Job<'_>) -> Result<(Vec<u8>, Vec<i32>), String> {
    let pixels = job.width as usize * job.height as usize;
    let mut rgb = vec![0u8; pixels * 3];
    let mut seg = if job.segment {
        vec![-1; pixels]
    } else {
        Vec::new()
    };
    // A label with a NUL in it cannot be drawn: it is cut there.
    let label = job
        .label
        .map(|l| CString::new(l.split('\0').next().unwrap_or_default()).unwrap_or_default());
    let mut err = vec![0 as c_char; ERR_LEN];
    // SAFETY: see the contract; `rgb` holds width x height x 3 bytes and `seg` width x
    // height ints when segmenting (NULL otherwise, never written then); `err` holds
    // `ERR_LEN` bytes; `label` is NULL or NUL-terminated and outlives the call.
    let code = unsafe {
        mjf_render(
            m,
            job.width,
            job.height,
            job.free_cam.as_ptr(),
            job.camid,
            job.geoms,
            label.as_ref().map_or(std::ptr::null(), |l| l.as_ptr()),
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
