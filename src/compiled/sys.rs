//! The C functions of `patch.c` (compiled by `build.rs` against the linked MuJoCo's
//! headers, as the FFI's shim is): arrays found by name through MuJoCo's X-macro table,
//! scratch data, the derived values after a patch. The only `extern` block of this tier;
//! `linked.rs` (the linked MuJoCo behind the split tier's patch plan), `store.rs`,
//! `statistics.rs` and `worlds.rs` call it.

use std::ffi::{c_char, c_int, c_void};

use crate::mujoco::MjModel;

/// mjData, opaque here: only the C side reads it.
#[repr(C)]
pub(super) struct RawData {
    _private: [u8; 0],
}

unsafe extern "C" {
    pub(super) fn mjf_patch_array(
        m: *mut MjModel,
        name: *const c_char,
        elem: *mut usize,
        count: *mut usize,
    ) -> *mut c_void;
    pub(super) fn mjf_patch_name2id(
        m: *const MjModel,
        kind: *const c_char,
        name: *const c_char,
    ) -> c_int;
    pub(super) fn mjf_patch_make_data(m: *const MjModel) -> *mut RawData;
    pub(super) fn mjf_patch_delete_data(d: *mut RawData);
    pub(super) fn mjf_patch_nbytes(m: *const MjModel, d: *const RawData) -> i64;
    pub(super) fn mjf_patch_get_stat(m: *const MjModel, out: *mut f64);
    pub(super) fn mjf_patch_set_const(m: *mut MjModel, d: *mut RawData);
    pub(super) fn mjf_patch_kinematics(m: *const MjModel, d: *mut RawData);
    pub(super) fn mjf_patch_make_m(m: *const MjModel, d: *mut RawData);
    pub(super) fn mjf_patch_id2name(
        m: *const MjModel,
        kind: *const c_char,
        id: c_int,
    ) -> *const c_char;
    pub(super) fn mjf_patch_stat_arrays(
        m: *mut MjModel,
        d: *const RawData,
        out: *mut super::statistics::RawStatArrays,
    );
    pub(super) fn mjf_patch_set_stat(m: *mut MjModel, values: *const f64);
    pub(super) fn mjf_patch_array_name(i: c_int) -> *const c_char;
    pub(super) fn mjf_patch_size_name(i: c_int) -> *const c_char;
    pub(super) fn mjf_patch_size(m: *const MjModel, i: c_int) -> i64;
    pub(super) fn mjf_patch_names(m: *const MjModel, len: *mut i64) -> *const c_char;
    pub(super) fn mjf_patch_array_type(i: c_int) -> *const c_char;
    pub(super) fn mjf_tree_constant(name: *const c_char, found: *mut c_int) -> c_int;
    pub(super) fn mjf_tree_camlight(m: *const MjModel, d: *mut RawData);
    pub(super) fn mjf_tree_data(
        m: *const MjModel,
        d: *const RawData,
        name: *const c_char,
        count: *mut usize,
    ) -> *const f64;
    pub(super) fn mjf_patch_option(
        m: *mut MjModel,
        name: *const c_char,
        elem: *mut usize,
        count: *mut usize,
    ) -> *mut c_void;
}
