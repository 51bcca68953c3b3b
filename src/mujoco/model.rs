//! [`CompiledModel`], the owning handle of a compiled `mjModel`, and what it reads: its
//! [`Sizes`], the names of its objects ([`ObjType`]), a few of its arrays, and the contacts
//! at its initial pose ([`Contact`]).

use std::ffi::{CStr, c_int};
use std::fmt;
use std::ptr::NonNull;
use std::sync::atomic::{AtomicU64, Ordering};

use super::sys::{self, MjModel, model_array, model_size};

/// A model compiled by MuJoCo: owns the `mjModel`, which is freed (`mj_deleteModel`) on
/// drop. All access through `&self` is read-only; only the model cache writes, through
/// `&mut`.
///
/// `CompiledModel` is `Send`: the `mjModel` is one heap allocation owned by this handle
/// alone (no other pointer to it escapes, and MuJoCo keeps none), and MuJoCo ties no thread
/// to a model, so using and freeing it on another thread is fine. It is also `Sync`: every
/// method takes `&self` and only reads the model (`mj_id2name` included), there is no
/// interior mutability, and concurrent reads of memory nobody writes are not a data race.
///
/// ```no_run
/// use std::path::Path;
/// use mjcf_forge::mujoco::{compile_file, ObjType};
///
/// let model = compile_file(Path::new("arm.xml")).unwrap();
/// let sizes = model.sizes();
/// for (name, pos) in model.names(ObjType::Body).iter().zip(model.body_pos().chunks(3)) {
///     println!("{name}: {pos:?}");
/// }
/// let handle = std::thread::spawn(move || model.sizes()); // Send
/// assert_eq!(handle.join().unwrap(), sizes);
/// ```
pub struct CompiledModel {
    ptr: NonNull<MjModel>,
    warnings: Option<String>,
    /// Unique per model made (compiled or cloned): the model cache's plans are per model.
    serial: u64,
}

/// Serial numbers of compiled models: a plan made for one model is never used for another.
static SERIAL: AtomicU64 = AtomicU64::new(1);

/// A deep copy (`mj_copyModel`): a model of the same structure, patched on its own.
impl CompiledModel {
    /// The model as the model store keeps it ([`crate::split::DiskStore`]): its
    /// `signature` (8 bytes, little-endian), which MuJoCo's binary format does not hold,
    /// then that format (`mj_saveModel`); read back by [`CompiledModel::from_bytes`] to the
    /// same model, every array and size and the signature.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = self.signature().to_le_bytes().to_vec();
        out.extend(sys::save_model(self.raw()));
        out
    }

    /// `mjModel.signature`: what the compile hashed its spec to (equal for two compiles of
    /// one structure).
    pub fn signature(&self) -> u64 {
        sys::signature(self.raw())
    }

    /// The model [`CompiledModel::to_bytes`] wrote (by this MuJoCo), or `None` when MuJoCo
    /// cannot read it.
    ///
    /// ```
    /// use mjcf_forge::mujoco::compile_str;
    /// let xml = "<mujoco><worldbody><geom size='1'/></worldbody></mujoco>";
    /// let m = compile_str(xml, std::path::Path::new("."))?;
    /// let back = mjcf_forge::mujoco::CompiledModel::from_bytes(&m.to_bytes()).unwrap();
    /// assert!(m.differences(&back).is_empty() && back.signature() == m.signature());
    /// # Ok::<(), mjcf_forge::mujoco::CompileError>(())
    /// ```
    pub fn from_bytes(bytes: &[u8]) -> Option<CompiledModel> {
        let (signature, mjb) = bytes.split_first_chunk::<8>()?;
        let ptr = NonNull::new(sys::load_model(mjb))?;
        // SAFETY: the model was just made and nothing else holds it.
        unsafe { sys::set_signature(ptr.as_ptr(), u64::from_le_bytes(*signature)) };
        Some(CompiledModel::from_raw(ptr, None))
    }
}

impl Clone for CompiledModel {
    fn clone(&self) -> Self {
        let copy = sys::copy_model(self.raw());
        let ptr = NonNull::new(copy).expect("MuJoCo could not allocate a copy of the model");
        CompiledModel::from_raw(ptr, self.warnings.clone())
    }
}

// SAFETY: see the type's documentation: exclusive ownership of a heap allocation without
// thread affinity.
unsafe impl Send for CompiledModel {}
// SAFETY: see the type's documentation: only reads through `&self`.
unsafe impl Sync for CompiledModel {}

impl Drop for CompiledModel {
    fn drop(&mut self) {
        // SAFETY: `ptr` came from `mj_loadXML` or `mj_copyModel`, is owned by `self` alone and
        // freed only here.
        unsafe { sys::delete_model(self.ptr.as_ptr()) }
    }
}

impl fmt::Debug for CompiledModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CompiledModel")
            .field("sizes", &self.sizes())
            .field("warnings", &self.warnings)
            .finish()
    }
}

/// The kinds of named object [`CompiledModel::names`] lists (MuJoCo's `mjtObj`).
///
/// ```
/// use mjcf_forge::mujoco::ObjType;
///
/// assert_eq!(ObjType::Geom.as_str(), "geom");
/// assert_eq!(ObjType::ALL.len(), 14);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ObjType {
    /// `mjOBJ_BODY` (index 0 is `world`).
    Body,
    /// `mjOBJ_JOINT`.
    Joint,
    /// `mjOBJ_GEOM`.
    Geom,
    /// `mjOBJ_SITE`.
    Site,
    /// `mjOBJ_CAMERA`.
    Camera,
    /// `mjOBJ_LIGHT`.
    Light,
    /// `mjOBJ_MESH`.
    Mesh,
    /// `mjOBJ_MATERIAL`.
    Material,
    /// `mjOBJ_TEXTURE`.
    Texture,
    /// `mjOBJ_TENDON`.
    Tendon,
    /// `mjOBJ_ACTUATOR`.
    Actuator,
    /// `mjOBJ_SENSOR`.
    Sensor,
    /// `mjOBJ_EQUALITY`.
    Equality,
    /// `mjOBJ_KEY` (keyframes).
    Key,
}

impl ObjType {
    /// Every variant, in declaration order.
    pub const ALL: [ObjType; 14] = [
        ObjType::Body,
        ObjType::Joint,
        ObjType::Geom,
        ObjType::Site,
        ObjType::Camera,
        ObjType::Light,
        ObjType::Mesh,
        ObjType::Material,
        ObjType::Texture,
        ObjType::Tendon,
        ObjType::Actuator,
        ObjType::Sensor,
        ObjType::Equality,
        ObjType::Key,
    ];

    /// The MJCF element name of this kind (`"body"`, `"joint"`, ..., `"key"`).
    pub fn as_str(self) -> &'static str {
        match self {
            ObjType::Body => "body",
            ObjType::Joint => "joint",
            ObjType::Geom => "geom",
            ObjType::Site => "site",
            ObjType::Camera => "camera",
            ObjType::Light => "light",
            ObjType::Mesh => "mesh",
            ObjType::Material => "material",
            ObjType::Texture => "texture",
            ObjType::Tendon => "tendon",
            ObjType::Actuator => "actuator",
            ObjType::Sensor => "sensor",
            ObjType::Equality => "equality",
            ObjType::Key => "key",
        }
    }
}

impl fmt::Display for ObjType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Defines [`Sizes`] from one list, so the struct, [`Sizes::entries`] and
/// [`Sizes::to_json`] cannot disagree on fields or order.
macro_rules! sizes_struct {
    ($($field:ident: $doc:literal,)*) => {
        /// Sizes of a compiled model (copied from `mjModel`), e.g. `nbody` counts the world
        /// body too. [`Sizes::to_json`] writes them as one JSON object with a fixed key order:
        /// `nbody njnt ngeom nsite nu nsensor nq nv nmesh`, then the rest as declared.
        ///
        /// ```no_run
        /// use std::path::Path;
        /// use mjcf_forge::mujoco::compile_file;
        ///
        /// let sizes = compile_file(Path::new("arm.xml")).unwrap().sizes();
        /// println!("{} bodies, {} dofs", sizes.nbody, sizes.nv);
        /// assert!(sizes.to_json().starts_with("{\"nbody\":"));
        /// ```
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
        pub struct Sizes {
            $(#[doc = $doc] pub $field: usize,)*
        }

        impl Sizes {
            /// Number of fields, i.e. of [`Sizes::entries`].
            pub const LEN: usize = [$(stringify!($field)),*].len();

            /// `(name, value)` of every field, in [`Sizes::to_json`]'s order.
            pub fn entries(&self) -> [(&'static str, usize); Self::LEN] {
                [$((stringify!($field), self.$field)),*]
            }

            fn from_model(m: &MjModel) -> Self {
                Self { $($field: model_size!(m, $field),)* }
            }
        }
    };
}

sizes_struct! {
    nbody: "Bodies, including the world body.",
    njnt: "Joints.",
    ngeom: "Geoms.",
    nsite: "Sites.",
    nu: "Scalar controls (`dim(ctrl)`).",
    nsensor: "Sensors.",
    nq: "Generalized coordinates (`dim(qpos)`).",
    nv: "Degrees of freedom (`dim(qvel)`).",
    nmesh: "Meshes.",
    na: "Activation states (`dim(act)`).",
    nactuator: "Actuators.",
    ncam: "Cameras.",
    nlight: "Lights.",
    ntex: "Textures.",
    nmat: "Materials.",
    ntendon: "Tendons.",
    nwrap: "Tendon wrap objects.",
    neq: "Equality constraints.",
    nkey: "Keyframes.",
    nmocap: "Mocap bodies.",
    nhfield: "Height fields.",
    nskin: "Skins.",
    nflex: "Flexes.",
    npair: "Predefined geom pairs.",
    nexclude: "Excluded body pairs.",
    nnumeric: "Numeric custom fields.",
    ntext: "Text custom fields.",
    ntuple: "Tuple custom fields.",
    nplugin: "Plugin instances.",
    nsensordata: "Sensor data values (`dim(sensordata)`).",
    nuser_body: "User numbers per body.",
    nuser_jnt: "User numbers per joint.",
    nuser_geom: "User numbers per geom.",
    nuser_site: "User numbers per site.",
    nuser_cam: "User numbers per camera.",
    nuser_tendon: "User numbers per tendon.",
    nuser_actuator: "User numbers per actuator.",
    nuser_sensor: "User numbers per sensor.",
    nnames: "Bytes of the names buffer.",
}

impl Sizes {
    /// One JSON object, keys in [`Sizes::entries`] order, no whitespace:
    /// `{"nbody":2,"njnt":1,...}`.
    ///
    /// ```
    /// use mjcf_forge::mujoco::Sizes;
    ///
    /// let sizes = Sizes { nbody: 2, nq: 7, ..Sizes::default() };
    /// let json = sizes.to_json();
    /// assert!(json.starts_with(r#"{"nbody":2,"njnt":0,"ngeom":0,"nsite":0,"nu":0,"#));
    /// assert!(json.contains(r#""nq":7,"nv":0,"nmesh":0,"na":0"#));
    /// ```
    pub fn to_json(&self) -> String {
        let mut out = String::from("{");
        for (i, (key, value)) in self.entries().iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            out.push_str(&format!("\"{key}\":{value}"));
        }
        out.push('}');
        out
    }
}

/// A contact found by [`CompiledModel::initial_contacts`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The first geom's id.
    pub geom1: usize,
    /// The second geom's id.
    pub geom2: usize,
    /// Signed distance: negative when the geoms interpenetrate.
    pub dist: f64,
}

/// Defines read-only slice accessors for `mjModel` arrays: `name: type, |m| length`.
macro_rules! model_arrays {
    ($($(#[$doc:meta])* $field:ident: $ty:ty, |$m:ident| $len:expr;)*) => {
        impl CompiledModel {
            $(
                $(#[$doc])*
                pub fn $field(&self) -> &[$ty] {
                    let $m = self.raw();
                    // SAFETY: MuJoCo allocates `$field` with exactly this many elements
                    // (see mjmodel.h) inside the model, which lives as long as `self` and
                    // is never written after compilation.
                    unsafe { slice_or_empty(model_array!($m, $field, $ty), $len) }
                }
            )*
        }
    };
}

model_arrays! {
    /// Body positions relative to the parent body, 3 per body (`nbody x 3`).
    body_pos: f64, |m| model_size!(m, nbody) * 3;
    /// Body orientations relative to the parent body, quaternions `w x y z` (`nbody x 4`).
    body_quat: f64, |m| model_size!(m, nbody) * 4;
    /// Body masses (`nbody`).
    body_mass: f64, |m| model_size!(m, nbody);
    /// Body principal moments of inertia (`nbody x 3`).
    body_inertia: f64, |m| model_size!(m, nbody) * 3;
    /// Positions of the bodies' inertial frames in the body frames (`nbody x 3`).
    body_ipos: f64, |m| model_size!(m, nbody) * 3;
    /// Orientations of the bodies' inertial frames in the body frames (`nbody x 4`).
    body_iquat: f64, |m| model_size!(m, nbody) * 4;
    /// Parent body ids (`nbody`; the world body is its own parent).
    body_parentid: i32, |m| model_size!(m, nbody);
    /// Per body, the id of its top-level ancestor (the body itself at the top).
    body_rootid: i32, |m| model_size!(m, nbody);
    /// Joint types (`mjtJoint`: 0 free, 1 ball, 2 slide, 3 hinge) (`njnt`).
    jnt_type: i32, |m| model_size!(m, njnt);
    /// Joint axes in the body frame (`njnt x 3`).
    jnt_axis: f64, |m| model_size!(m, njnt) * 3;
    /// Joint limits (`njnt x 2`).
    jnt_range: f64, |m| model_size!(m, njnt) * 2;
    /// Geom types (`mjtGeom`) (`ngeom`).
    geom_type: i32, |m| model_size!(m, ngeom);
    /// Ids of the geoms' bodies (`ngeom`).
    geom_bodyid: i32, |m| model_size!(m, ngeom);
    /// Geom size parameters (`ngeom x 3`).
    geom_size: f64, |m| model_size!(m, ngeom) * 3;
    /// Geom positions relative to their body (`ngeom x 3`).
    geom_pos: f64, |m| model_size!(m, ngeom) * 3;
    /// Geom orientations relative to their body, `w x y z` (`ngeom x 4`).
    geom_quat: f64, |m| model_size!(m, ngeom) * 4;
    /// Geom friction: slide, spin, roll (`ngeom x 3`).
    geom_friction: f64, |m| model_size!(m, ngeom) * 3;
    /// Geom colors when no material is set (`ngeom x 4`).
    geom_rgba: f32, |m| model_size!(m, ngeom) * 4;
    /// Site positions relative to their body (`nsite x 3`).
    site_pos: f64, |m| model_size!(m, nsite) * 3;
    /// Actuator gain parameters, `mjNGAIN` (10) per actuator (`nactuator x 10`).
    actuator_gainprm: f64, |m| model_size!(m, nactuator) * sys::ngain();
    /// Actuator bias parameters, `mjNBIAS` (10) per actuator (`nactuator x 10`).
    actuator_biasprm: f64, |m| model_size!(m, nactuator) * sys::nbias();
    /// Default pose (`nq`).
    qpos0: f64, |m| model_size!(m, nq);
    /// Keyframe times (`nkey`).
    key_time: f64, |m| model_size!(m, nkey);
    /// Keyframe positions (`nkey x nq`).
    key_qpos: f64, |m| model_size!(m, nkey) * model_size!(m, nq);
}

/// `len` elements at `ptr`, or an empty slice when `len` is 0 (MuJoCo may leave such
/// arrays null).
///
/// # Safety
/// When `len > 0`, `ptr` must point to `len` initialized elements that stay valid and
/// unwritten for `'a`.
pub(crate) unsafe fn slice_or_empty<'a, T>(ptr: *const T, len: usize) -> &'a [T] {
    if len == 0 || ptr.is_null() {
        &[]
    } else {
        // SAFETY: guaranteed by the caller.
        unsafe { std::slice::from_raw_parts(ptr, len) }
    }
}

impl CompiledModel {
    /// The contacts MuJoCo finds at the model's initial pose (`qpos0`): `mj_forward` on
    /// fresh data, which is freed again. Geoms with a negative `dist` interpenetrate.
    ///
    /// ```
    /// use mjcf_forge::mujoco::compile_str;
    /// let xml = r#"<mujoco><worldbody><geom type="plane" size="1 1 1"/>
    ///   <body pos="0 0 0.05"><freejoint/><geom type="sphere" size="0.1"/></body>
    ///   </worldbody></mujoco>"#;
    /// let model = compile_str(xml, std::path::Path::new(".")).unwrap();
    /// let contacts = model.initial_contacts();
    /// assert_eq!(contacts.len(), 1);
    /// assert!((contacts[0].dist + 0.05).abs() < 1e-9);
    /// ```
    pub fn initial_contacts(&self) -> Vec<Contact> {
        sys::initial_contacts(self.raw())
    }

    /// Takes ownership of `ptr`, a model MuJoCo just made, under a new serial number.
    pub(super) fn from_raw(ptr: NonNull<MjModel>, warnings: Option<String>) -> Self {
        CompiledModel {
            ptr,
            warnings,
            serial: SERIAL.fetch_add(1, Ordering::Relaxed),
        }
    }

    /// The model, for reading (the model cache's C side reads it too).
    pub(crate) fn raw(&self) -> &MjModel {
        // SAFETY: `ptr` is a live model owned by `self` (see `Drop`).
        unsafe { self.ptr.as_ref() }
    }

    /// The model, for writing in place: what the model cache patches. `&mut self`, so no
    /// reader of this handle sees it change.
    pub(crate) fn as_mut_ptr(&mut self) -> *mut MjModel {
        self.ptr.as_ptr()
    }

    /// This model's serial number, unique per model made in this process (compiled or
    /// cloned): what the model cache keys its per-model plans by.
    pub(crate) fn serial(&self) -> u64 {
        self.serial
    }

    /// The model's sizes (see [`Sizes`]).
    ///
    /// ```
    /// use std::path::Path;
    /// use mjcf_forge::mujoco::compile_str;
    ///
    /// let m = compile_str("<mujoco><worldbody><body><freejoint/><geom size='1'/></body>\
    ///                      </worldbody></mujoco>", Path::new(".")).unwrap();
    /// let s = m.sizes();
    /// assert_eq!((s.nbody, s.njnt, s.nq, s.nv), (2, 1, 7, 6));
    /// ```
    pub fn sizes(&self) -> Sizes {
        Sizes::from_model(self.raw())
    }

    /// The names of all objects of kind `obj`, indexed by MuJoCo id (so `names(Body)[0]`
    /// is `"world"`); unnamed objects give `""`.
    ///
    /// ```
    /// use std::path::Path;
    /// use mjcf_forge::mujoco::{compile_str, ObjType};
    ///
    /// let m = compile_str("<mujoco><worldbody><geom name='floor' type='plane' size='1 1 1'/>\
    ///                      <geom size='1'/></worldbody></mujoco>", Path::new(".")).unwrap();
    /// assert_eq!(m.names(ObjType::Geom), ["floor", ""]);
    /// ```
    pub fn names(&self, obj: ObjType) -> Vec<String> {
        let m = self.raw();
        let count = match obj {
            ObjType::Body => model_size!(m, nbody),
            ObjType::Joint => model_size!(m, njnt),
            ObjType::Geom => model_size!(m, ngeom),
            ObjType::Site => model_size!(m, nsite),
            ObjType::Camera => model_size!(m, ncam),
            ObjType::Light => model_size!(m, nlight),
            ObjType::Mesh => model_size!(m, nmesh),
            ObjType::Material => model_size!(m, nmat),
            ObjType::Texture => model_size!(m, ntex),
            ObjType::Tendon => model_size!(m, ntendon),
            ObjType::Actuator => model_size!(m, nactuator),
            ObjType::Sensor => model_size!(m, nsensor),
            ObjType::Equality => model_size!(m, neq),
            ObjType::Key => model_size!(m, nkey),
        };
        let count = c_int::try_from(count).unwrap_or(0);
        (0..count)
            .map(|id| {
                // SAFETY: the model is live; `id` is in range for `obj`; MuJoCo returns
                // null or a NUL-terminated string inside the model's names buffer.
                let name = unsafe { sys::id2name(m, obj, id) };
                if name.is_null() {
                    String::new()
                } else {
                    // SAFETY: non-null, NUL-terminated, lives as long as the model.
                    unsafe { CStr::from_ptr(name) }
                        .to_string_lossy()
                        .into_owned()
                }
            })
            .collect()
    }

    /// The number of mesh vertices of the compiled model (`nmeshvert`), all meshes together.
    ///
    /// ```
    /// use std::path::Path;
    /// use mjcf_forge::mujoco::compile_str;
    ///
    /// let m = compile_str("<mujoco><worldbody><geom size='1'/></worldbody></mujoco>",
    ///                     Path::new(".")).unwrap();
    /// assert_eq!(m.mesh_vertex_count(), 0);
    /// ```
    pub fn mesh_vertex_count(&self) -> usize {
        model_size!(self.raw(), nmeshvert)
    }

    /// The compiler's warnings, if any (MuJoCo reports them in the error buffer of a
    /// successful `mj_loadXML`), joined by newlines as MuJoCo joins them.
    ///
    /// ```no_run
    /// use std::path::Path;
    /// use mjcf_forge::mujoco::compile_file;
    ///
    /// let model = compile_file(Path::new("arm.xml")).unwrap();
    /// if let Some(w) = model.warnings() {
    ///     eprintln!("MuJoCo warned: {w}");
    /// }
    /// ```
    pub fn warnings(&self) -> Option<&str> {
        self.warnings.as_deref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_key_order() {
        let json = Sizes::default().to_json();
        let keys: Vec<&str> = json
            .trim_matches(|c| c == '{' || c == '}')
            .split(',')
            .map(|kv| kv.split(':').next().unwrap().trim_matches('"'))
            .collect();
        assert_eq!(
            &keys[..9],
            [
                "nbody", "njnt", "ngeom", "nsite", "nu", "nsensor", "nq", "nv", "nmesh"
            ]
        );
        assert_eq!(keys.len(), Sizes::LEN);
    }
}
