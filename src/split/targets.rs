//! Where a patch lands in MuJoCo's compiled model: the `mjModel` array of each patch
//! entry, the arrays no patch changes, and the integer arrays that tell one structure from
//! another. The one copy of these tables: the model caches (`crate::compiled`) and the
//! Python package's caches (`_cache.py`, `batch.py`, through the extension)
//! read them here.
//!
//! ```
//! use mjcf_forge::split::target_array;
//! assert_eq!(target_array("geom", "rgba").as_deref(), Some("geom_rgba"));
//! assert_eq!(target_array("joint", "damping").as_deref(), Some("dof_damping"));
//! assert_eq!(target_array("joint", "qpos0").as_deref(), Some("qpos0"));
//! assert_eq!(target_array("option", "timestep"), None);
//! ```

/// An element type a patch entry names: its `mjModel` array prefix, its `mjtObj` name
/// and the size that counts it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PatchObject {
    /// The type as MuJoCo's named accessors call it (`PatchEntry::object`).
    pub object: &'static str,
    /// The prefix of its arrays in `mjModel` (`jnt_` for a joint).
    pub prefix: &'static str,
    /// Its `mjtObj` value's name (`mjOBJ_JOINT`).
    pub obj_type: &'static str,
    /// The size that counts it (`njnt`).
    pub count: &'static str,
}

/// Every element type a patch entry can name besides `option`.
pub const PATCH_OBJECTS: [PatchObject; 8] = [
    PatchObject {
        object: "body",
        prefix: "body_",
        obj_type: "mjOBJ_BODY",
        count: "nbody",
    },
    PatchObject {
        object: "joint",
        prefix: "jnt_",
        obj_type: "mjOBJ_JOINT",
        count: "njnt",
    },
    PatchObject {
        object: "geom",
        prefix: "geom_",
        obj_type: "mjOBJ_GEOM",
        count: "ngeom",
    },
    PatchObject {
        object: "site",
        prefix: "site_",
        obj_type: "mjOBJ_SITE",
        count: "nsite",
    },
    PatchObject {
        object: "camera",
        prefix: "cam_",
        obj_type: "mjOBJ_CAMERA",
        count: "ncam",
    },
    PatchObject {
        object: "light",
        prefix: "light_",
        obj_type: "mjOBJ_LIGHT",
        count: "nlight",
    },
    PatchObject {
        object: "material",
        prefix: "mat_",
        obj_type: "mjOBJ_MATERIAL",
        count: "nmat",
    },
    PatchObject {
        object: "actuator",
        prefix: "actuator_",
        obj_type: "mjOBJ_ACTUATOR",
        count: "nu",
    },
];

/// Fields of `body` entries whose value is the MJCF text of a model of the body's geoms,
/// not numbers: `geoms`, the body model (its geoms as written, whose compile is copied
/// whole: [`copy_body_model`](super::copy_body_model)), and `unit_geoms`, its unit model
/// (each geom that counts for inertia alone, at unit density or mass:
/// [`write_geom_masses`](super::write_geom_masses)), which the body's [`GEOM_FACTORS`]
/// entry follows.
pub const MODEL_FIELDS: [&str; 2] = ["geoms", "unit_geoms"];

/// The field of a `body` entry whose numbers are the densities or masses of its unit
/// model's geoms, in order.
pub const GEOM_FACTORS: &str = "geom_factors";

/// What follows from a body's mass properties: the arrays (and statistic) in which a unit
/// model's patch ([`write_geom_masses`](super::write_geom_masses)) may differ from
/// MuJoCo's compile in the last bits (within 1e-12 relative, docs/compiled.md); every
/// other array of such a patch is MuJoCo's bit for bit.
pub const MASS_DERIVED: [&str; 8] = [
    "body_inertia",
    "body_iquat",
    "bvh_aabb",
    "body_invweight0",
    "dof_invweight0",
    "dof_M0",
    "actuator_acc0",
    "stat.meaninertia",
];

/// The arrays `mj_setConst` derives from values a patch writes: they follow a variant even
/// where no patch entry names them (a batch's per-world candidates).
pub const SET_CONST_DERIVED: [&str; 15] = [
    "body_subtreemass",
    "body_invweight0",
    "dof_invweight0",
    "dof_M0",
    "tendon_length0",
    "tendon_invweight0",
    "actuator_acc0",
    "actuator_length0",
    "cam_pos0",
    "cam_poscom0",
    "cam_mat0",
    "light_pos0",
    "light_poscom0",
    "light_dir0",
    "dof_length",
];

/// The sizes that count rows of mesh, texture, height-field, skin and bounding-volume data:
/// no patch writes their arrays, and they are most of a model's bytes, so a cache that
/// restores a model before a patch leaves them (the Python `DocumentCache`).
pub const BULK_SIZES: [&str; 18] = [
    "nmeshvert",
    "nmeshnormal",
    "nmeshtexcoord",
    "nmeshface",
    "nmeshgraph",
    "nmeshpoly",
    "nmeshpolyvert",
    "nmeshpolymap",
    "ntexdata",
    "nhfielddata",
    "nbvh",
    "nbvhstatic",
    "nbvhdynamic",
    "noct",
    "nskinvert",
    "nskintexvert",
    "nskinface",
    "nskinbonevert",
];

/// The same arrays by their name's start, for a MuJoCo whose bindings do not say which size
/// counts an array's rows.
pub const BULK_PREFIXES: [&str; 14] = [
    "mesh_vert",
    "mesh_normal",
    "mesh_texcoord",
    "mesh_face",
    "mesh_graph",
    "mesh_poly",
    "tex_data",
    "hfield_data",
    "bvh_",
    "oct_",
    "skin_vert",
    "skin_texcoord",
    "skin_face",
    "skin_bonevert",
];

/// A joint's fields that are per degree of freedom (`dof_<field>`).
pub const DOF_FIELDS: [&str; 3] = ["damping", "armature", "frictionloss"];

/// A joint's fields that are per `qpos` coordinate, arrays of their own (`key_qpos`: its
/// rows of every keyframe).
pub const QPOS_FIELDS: [&str; 3] = ["qpos0", "qpos_spring", "key_qpos"];

/// How many compiled body models (a body's geoms compiled alone, `geoms` entries) a
/// structure's patch plan keeps, the oldest dropped first: both faces' bound.
pub const BODY_MODELS_KEPT: usize = 64;

/// How many superset layouts (which objects a world places) a cache keeps derived things
/// of (a layout's patch, its tree-by-tree derivation), all dropped when one more comes.
pub const LAYOUTS_KEPT: usize = 64;

/// MuJoCo's joint types by their compiled number (`mjtJoint`, `jnt_type`): the schema's
/// `enum<jointtype>` keywords, in that order.
///
/// ```
/// assert_eq!(mjcf_forge::split::JOINT_TYPES[3], "hinge");
/// ```
pub const JOINT_TYPES: &[&str] = crate::document::vocab::KW_JOINTTYPE;

/// How many degrees of freedom and `qpos` coordinates a joint of MuJoCo type `jnt_type`
/// has (free, ball, slide, hinge).
///
/// ```
/// assert_eq!(mjcf_forge::split::joint_widths(0), (6, 7));
/// assert_eq!(mjcf_forge::split::joint_widths(3), (1, 1));
/// ```
pub fn joint_widths(jnt_type: i64) -> (usize, usize) {
    match jnt_type {
        0 => (6, 7),
        1 => (3, 4),
        _ => (1, 1),
    }
}

/// The `mjModel` array a patch entry of an `object`'s `field` writes (a joint's dof and
/// qpos fields have arrays of their own), or `None` for the options and body models.
pub fn target_array(object: &str, field: &str) -> Option<String> {
    if object == "joint" && DOF_FIELDS.contains(&field) {
        return Some(format!("dof_{field}"));
    }
    if object == "joint" && QPOS_FIELDS.contains(&field) {
        return Some(field.to_string());
    }
    PATCH_OBJECTS
        .iter()
        .find(|o| o.object == object)
        .map(|o| format!("{}{field}", o.prefix))
}

/// The prefixes of `mjModel` arrays no patch changes (meshes, textures, height fields,
/// skins, flexes, bounding-volume trees, names, sensors, keyframes): never compared
/// across a batch's worlds, never per world.
pub const STATIC_PREFIXES: [&str; 15] = [
    "mesh_", "tex_", "hfield_", "skin_", "flex", "bvh_", "oct_", "name", "text_", "paths",
    "tuple_", "numeric_", "plugin", "sensor_", "key_",
];

/// Sizes of `mjModel` that a patch can change (`mj_setConst` counts the bodies with
/// gravity compensation): left out of the structure signature, which is every other
/// size, the names buffer and [`SIGNATURE_ARRAYS`].
pub const SIGNATURE_SKIPPED_SIZES: [&str; 1] = ["ngravcomp"];

/// Integer arrays that, with the sizes and the names, tell one structure's compiled model
/// from another's (a model cache refuses to patch a model of another structure).
pub const SIGNATURE_ARRAYS: [&str; 7] = [
    "body_parentid",
    "jnt_type",
    "geom_type",
    "geom_bodyid",
    "geom_dataid",
    "mesh_vertnum",
    "tex_width",
];
