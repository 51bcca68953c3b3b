//! The extern declarations: MuJoCo's own entry points whose signatures are plain C types,
//! and the shim (`shim.c`) for everything that needs a struct layout, a constant or an
//! enum, which `build.rs` compiles against the linked MuJoCo's headers. So nothing here
//! knows a layout, and one Rust build serves any MuJoCo from 3.17.0 on.
//!
//! Each wrapper states what it needs of its caller; the rest of the FFI goes through them.

use std::ffi::{CStr, c_char, c_int, c_void};
use std::ptr::NonNull;

use super::model::{Contact, ObjType};

/// `mjModel`, opaque: only the shim and MuJoCo look inside.
#[repr(C)]
pub(crate) struct MjModel {
    _opaque: [u8; 0],
}

/// `mjVFS`, opaque.
#[repr(C)]
struct RawVfs {
    _opaque: [u8; 0],
}

unsafe extern "C" {
    fn mj_version() -> c_int;
    fn mj_versionString() -> *const c_char;
    fn mj_deleteModel(m: *mut MjModel);
    fn mj_addBufferVFS(
        vfs: *mut RawVfs,
        name: *const c_char,
        buffer: *const c_void,
        nbuffer: c_int,
    ) -> c_int;
    fn mj_id2name(m: *const MjModel, kind: c_int, id: c_int) -> *const c_char;
    fn mjf_header_version() -> c_int;
    fn mjf_ngain() -> c_int;
    fn mjf_nbias() -> c_int;
    fn mjf_model_size(m: *const MjModel, name: *const c_char) -> i64;
    fn mjf_model_array(
        m: *const MjModel,
        name: *const c_char,
        elem_size: *mut usize,
    ) -> *const c_void;
    fn mjf_load_xml(
        filename: *const c_char,
        vfs: *const RawVfs,
        error: *mut c_char,
        error_sz: c_int,
    ) -> *mut MjModel;
    fn mjf_copy_model(m: *const MjModel) -> *mut MjModel;
    fn mjf_save_model(m: *const MjModel, buffer: *mut c_void, size: i64) -> i64;
    fn mjf_load_model(buffer: *const c_void, size: i64) -> *mut MjModel;
    fn mjf_signature(m: *const MjModel) -> u64;
    fn mjf_set_signature(m: *mut MjModel, signature: u64);
    fn mjf_vfs_new() -> *mut RawVfs;
    fn mjf_vfs_free(vfs: *mut RawVfs);
    fn mjf_obj_type(kind: *const c_char) -> c_int;
    fn mjf_initial_contacts(
        m: *const MjModel,
        max: c_int,
        geom1: *mut c_int,
        geom2: *mut c_int,
        dist: *mut f64,
    ) -> c_int;
}

/// A size field of `mjModel` as `usize`.
macro_rules! model_size {
    ($m:expr, $field:ident) => {
        crate::mujoco::sys::size($m, concat!(stringify!($field), "\0"))
    };
}
/// An array field of `mjModel` as a pointer to `$ty`.
macro_rules! model_array {
    ($m:expr, $field:ident, $ty:ty) => {
        crate::mujoco::sys::array::<$ty>($m, concat!(stringify!($field), "\0"))
    };
}
pub(super) use {model_array, model_size};

/// The size field `name` (NUL-terminated). A name this MuJoCo does not have is a bug of
/// this module (the field lists are fixed): it panics, naming the field.
pub(super) fn size(m: &MjModel, name: &'static str) -> usize {
    // SAFETY: `m` is live; `name` is NUL-terminated (the macros add the NUL).
    let v = unsafe { mjf_model_size(m, name.as_ptr().cast()) };
    usize::try_from(v).unwrap_or_else(|_| {
        panic!(
            "this MuJoCo's mjModel has no size field {}",
            name.trim_end_matches('\0')
        )
    })
}

/// The array field `name` (NUL-terminated) as `*const T`, checked against the element
/// size MuJoCo's headers give; panics on a field this MuJoCo does not have.
pub(super) fn array<T>(m: &MjModel, name: &'static str) -> *const T {
    let mut elem = 0usize;
    // SAFETY: `m` is live; `name` is NUL-terminated; `elem` is writable.
    let ptr = unsafe { mjf_model_array(m, name.as_ptr().cast(), &mut elem) };
    let field = name.trim_end_matches('\0');
    assert!(elem != 0, "this MuJoCo's mjModel has no array {field}");
    assert_eq!(
        elem,
        std::mem::size_of::<T>(),
        "mjModel.{field}: element size in MuJoCo's headers differs from ours"
    );
    ptr.cast()
}

/// `mjNGAIN`, the gain parameters per actuator, as the headers define it.
pub(super) fn ngain() -> usize {
    // SAFETY: returns a constant of the headers the shim was compiled with.
    usize::try_from(unsafe { mjf_ngain() }).unwrap_or(0)
}

/// `mjNBIAS`, the bias parameters per actuator, as the headers define it.
pub(super) fn nbias() -> usize {
    // SAFETY: returns a constant of the headers the shim was compiled with.
    usize::try_from(unsafe { mjf_nbias() }).unwrap_or(0)
}

/// A VFS owned by us, freed with `mj_deleteVFS`.
pub(super) struct Vfs(NonNull<RawVfs>);

impl Vfs {
    pub(super) fn new() -> Option<Vfs> {
        // SAFETY: returns null or a VFS initialised by `mj_defaultVFS`.
        NonNull::new(unsafe { mjf_vfs_new() }).map(Vfs)
    }

    /// Adds `bytes` (`len` of them) under `name`; MuJoCo's return code.
    pub(super) fn add_buffer(&mut self, name: &CStr, bytes: &[u8], len: c_int) -> c_int {
        // SAFETY: the VFS is live and ours; `name` is NUL-terminated; MuJoCo copies `len`
        // (= `bytes.len()`) bytes before returning.
        unsafe { mj_addBufferVFS(self.0.as_ptr(), name.as_ptr(), bytes.as_ptr().cast(), len) }
    }
}

impl Drop for Vfs {
    fn drop(&mut self) {
        // SAFETY: made by `mjf_vfs_new`, freed once, here.
        unsafe { mjf_vfs_free(self.0.as_ptr()) }
    }
}

/// `mj_loadXML`, without making the model MuJoCo's last loaded XML model (the shim's
/// `mjf_load_xml`: what `mj_saveLastXML` writes stays what the process loaded itself).
///
/// # Safety
/// As `mj_loadXML`: `err` holds `err_len` writable bytes.
pub(super) unsafe fn load_xml(
    path: &CStr,
    vfs: Option<&Vfs>,
    err: *mut c_char,
    err_len: c_int,
) -> *mut MjModel {
    let vfs = vfs.map_or(std::ptr::null(), |v| v.0.as_ptr().cast_const());
    // SAFETY: see the caller's contract; `vfs` is null or live.
    unsafe { mjf_load_xml(path.as_ptr(), vfs, err, err_len) }
}

/// A deep copy of `m` (`mj_copyModel` into a new model), or null when MuJoCo cannot
/// allocate one.
pub(super) fn copy_model(m: &MjModel) -> *mut MjModel {
    // SAFETY: `m` is live; MuJoCo only reads it.
    unsafe { mjf_copy_model(m) }
}

/// `m` in MuJoCo's binary format (`mj_saveModel`).
pub(super) fn save_model(m: &MjModel) -> Vec<u8> {
    // SAFETY: `m` is live; with a null buffer MuJoCo only measures it.
    let size = unsafe { mjf_save_model(m, std::ptr::null_mut(), 0) };
    let mut out = vec![0u8; usize::try_from(size).unwrap_or(0)];
    if !out.is_empty() {
        // SAFETY: `out` holds the `size` bytes MuJoCo asked for; `m` is only read.
        unsafe { mjf_save_model(m, out.as_mut_ptr().cast(), size) };
    }
    out
}

/// `mjModel.signature`.
pub(super) fn signature(m: &MjModel) -> u64 {
    // SAFETY: `m` is live; only read.
    unsafe { mjf_signature(m) }
}

/// Sets `mjModel.signature` of a model this process owns.
///
/// # Safety
/// `m` is live and nothing else reads or writes it meanwhile.
pub(super) unsafe fn set_signature(m: *mut MjModel, signature: u64) {
    // SAFETY: see the contract.
    unsafe { mjf_set_signature(m, signature) }
}

/// A model read back from MuJoCo's binary format (`mj_loadModelBuffer`), or null.
pub(super) fn load_model(bytes: &[u8]) -> *mut MjModel {
    let Ok(size) = i64::try_from(bytes.len()) else {
        return std::ptr::null_mut();
    };
    // SAFETY: `bytes` is live for the call; MuJoCo only reads it and copies what it keeps.
    unsafe { mjf_load_model(bytes.as_ptr().cast(), size) }
}

/// # Safety
/// `m` came from [`load_xml`], [`copy_model`] or [`load_model`] and is not used afterwards.
pub(super) unsafe fn delete_model(m: *mut MjModel) {
    // SAFETY: see the contract.
    unsafe { mj_deleteModel(m) }
}

pub(super) fn linked_version() -> c_int {
    // SAFETY: `mj_version` only returns a constant.
    unsafe { mj_version() }
}

/// The linked MuJoCo's version as it names itself (`3.17.0`).
pub(super) fn version_string() -> String {
    // SAFETY: MuJoCo returns a static NUL-terminated string.
    unsafe { CStr::from_ptr(mj_versionString()) }
        .to_string_lossy()
        .into_owned()
}

pub(super) fn header_version() -> c_int {
    // SAFETY: returns a constant of the headers the shim was compiled with.
    unsafe { mjf_header_version() }
}

/// # Safety
/// `id` is in range for `obj` in the live model `m`.
pub(super) unsafe fn id2name(m: &MjModel, obj: ObjType, id: c_int) -> *const c_char {
    let kind = format!("{}\0", obj.as_str());
    // SAFETY: `kind` is NUL-terminated.
    let code = unsafe { mjf_obj_type(kind.as_ptr().cast()) };
    // SAFETY: see the contract; `code` is MuJoCo's own mjtObj value.
    unsafe { mj_id2name(m, code, id) }
}

pub(super) fn initial_contacts(m: &MjModel) -> Vec<Contact> {
    let mut cap = 64;
    loop {
        let (mut g1, mut g2, mut dist) = (vec![0; cap], vec![0; cap], vec![0.0; cap]);
        // SAFETY: `m` is live; the three buffers hold `cap` elements each.
        let n = unsafe {
            mjf_initial_contacts(
                m,
                c_int::try_from(cap).unwrap_or(c_int::MAX),
                g1.as_mut_ptr(),
                g2.as_mut_ptr(),
                dist.as_mut_ptr(),
            )
        };
        let Ok(n) = usize::try_from(n) else {
            return Vec::new();
        };
        if n <= cap {
            return (0..n)
                .map(|i| Contact {
                    geom1: usize::try_from(g1[i]).unwrap_or(usize::MAX),
                    geom2: usize::try_from(g2[i]).unwrap_or(usize::MAX),
                    dist: dist[i],
                })
                .collect();
        }
        cap = n;
    }
}
