//! The MuJoCo FFI tier: compile MJCF with MuJoCo's own C library (cargo feature `mujoco`).
//!
//! [`compile_file`], [`compile_str`] and [`compile_document`] run MuJoCo's XML loader as
//! `mj_loadXML` runs it (parse, then compile, the same messages) but leave MuJoCo's last
//! loaded XML model, the one `mj_saveLastXML` writes, to the process (the shim's
//! `mjf_load_xml` frees the parsed model instead of keeping it), and return a [`CompiledModel`], a safe owning handle to the resulting
//! `mjModel`, or a [`CompileError`] carrying MuJoCo's own message and, when MuJoCo names
//! one, the line of the offending element. [`write_inertials`] and
//! [`write_all_inertials`] write what MuJoCo compiles back into a document.
//!
//! One binding for any MuJoCo from 3.17.0 on: `build.rs` compiles our small C shim
//! (`shim.c`) against the headers of the MuJoCo it links, so no Rust copy of `mjModel`'s
//! layout exists; fields are read by name through MuJoCo's X-macro tables.
//!
//! - `compile.rs`: the loader, its errors, the version check;
//! - `model.rs`: [`CompiledModel`] and what it reads ([`Sizes`], [`ObjType`], arrays,
//!   [`Contact`]s);
//! - `inertia.rs`: compiled inertias written back into a document;
//! - `sys.rs`: the extern declarations (MuJoCo's and the shim's) and their wrappers.
//!
//! May use: the document tier and `crate::error`. Knows nothing of models, scenes, the
//! compiled tier (whose model cache gets what it needs from here through `pub(crate)`
//! items) or the faces above.
//!
//! # Thread safety
//!
//! The loader is called without any lock of ours: MuJoCo's parser and compiler are safe to
//! call from several threads at once in MuJoCo 3.x. `mj_loadXML`'s only process-wide state,
//! the "last loaded spec" kept for `mj_saveLastXML`, is not touched here (see above:
//! `tests/mujoco_compile.rs` checks that a compile of ours leaves it); the compiler reports
//! engine errors through thread-local handlers (`_mjPRIVATE__set_tls_error_fn`) and a
//! thread-local jump buffer; the XML reader switches the number locale per thread
//! (`uselocale`); each call here gets its own VFS. (Source: MuJoCo's `xml_api.cc`,
//! `xml_global.cc`, `xml.cc` and `user_model.cc`; the wheel's own `thread_safety_test.py`
//! creates models from several threads.) `tests/mujoco_compile.rs` checks it with 8
//! threads compiling different models, with and without mesh files, 50 times each. What
//! stays global in MuJoCo is what this module never touches: the user error/warning
//! callbacks (`mju_user_error`, `mju_user_warning`) and the last loaded XML model.
//!
//! # Example
//!
//! ```
//! use std::path::Path;
//! use mjcf_forge::mujoco::{compile_str, ObjType};
//!
//! let xml = r#"<mujoco><worldbody>
//!   <body name="ball"><freejoint/><geom name="g" size="0.1"/></body>
//! </worldbody></mujoco>"#;
//! let model = compile_str(xml, Path::new(".")).expect("valid model");
//! assert_eq!(model.sizes().nbody, 2);
//! assert_eq!(model.names(ObjType::Body), ["world", "ball"]);
//! ```

// The FFI calls into MuJoCo are confined to this tier and the compiled tier; the crate root
// denies unsafe code elsewhere (it must use `deny`, not `forbid`, in builds with MuJoCo).
#![allow(unsafe_code)]

mod compile;
mod inertia;
mod model;
mod sys;

pub use compile::{CompileError, compile_document, compile_file, compile_str};
pub(crate) use inertia::{compiled_inertia, free_joint_qpos0};
pub use inertia::{write_all_inertials, write_inertials};
pub use model::{CompiledModel, Contact, ObjType, Sizes};

/// The linked MuJoCo's version as it names itself, as `mujoco.__version__` does in Python
/// (`3.17.0`): what the model store keys a compiled structure by, with its files.
///
/// ```
/// assert!(mjcf_forge::mujoco::version().starts_with(|c: char| c.is_ascii_digit()));
/// ```
pub fn version() -> String {
    sys::version_string()
}
// For the compiled tier's model cache, which patches models in place through its own C.
pub(crate) use model::slice_or_empty;
pub(crate) use sys::MjModel;
