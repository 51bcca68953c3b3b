//! The scene description: what a TOML scene file (or the same structure as JSON, for
//! Python dictionaries) says, deserialized with the position of every value that a later
//! check may need to point at.
//!
//! Only the shape is checked here (unknown keys, wrong types); what the values mean (files,
//! bodies, attributes) is checked when the scene is built, with the same positions.

use serde::Deserialize;
use toml::Spanned;

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SceneSpec {
    /// The seed of variant 0..N; `--seed` overrides it.
    #[serde(default)]
    pub(crate) seed: u64,
    /// The world or arena model every variant starts from.
    pub(crate) base: Spanned<String>,
    /// Write every variant with MuJoCo's `<compiler discardvisual="true">`: the compiled
    /// model drops what only rendering uses (visual geoms, materials, textures, unused
    /// meshes); opt-in, since it changes the model.
    #[serde(default)]
    pub(crate) discard_visual: bool,
    /// Models placed in every variant, in order.
    #[serde(default)]
    pub(crate) fixture: Vec<FixtureSpec>,
    /// Groups of objects drawn per variant, in order.
    #[serde(default)]
    pub(crate) objects: Vec<GroupSpec>,
    /// Attribute randomizers, applied in order.
    #[serde(default)]
    pub(crate) randomize: Vec<RandomizerSpec>,
}

/// A model placed in every variant.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct FixtureSpec {
    pub(crate) model: Spanned<String>,
    /// The prefix of every name of this instance (may be empty).
    pub(crate) prefix: Spanned<String>,
    /// A body of what is already placed (full name); the world body without it.
    pub(crate) into: Option<Spanned<String>>,
    /// Replaces the root body's position.
    pub(crate) pos: Option<[f64; 3]>,
    /// Replaces the root body's orientation (w x y z).
    pub(crate) quat: Option<Spanned<[f64; 4]>>,
    /// Colour of collision geoms (group 0), as robosuite draws robots; off by default so
    /// that every part compiles exactly as it does alone.
    pub(crate) collision_rgba: Option<[f64; 4]>,
    /// Name unnamed geoms of group 0/1 `g{n}_col`/`g{n}_vis` (robosuite's habit).
    #[serde(default)]
    pub(crate) name_unnamed_geoms: bool,
    /// How the model is read when it is URDF; an error for an MJCF model.
    pub(crate) urdf: Option<Spanned<UrdfSpec>>,
}

/// How a URDF model of a scene is read (`mjcf_forge::UrdfOptions`, the command line's
/// `--urdf-*` flags): MuJoCo's importer without it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct UrdfSpec {
    /// Keep each `<visual>` as a geom of group 1 (no mass, no contacts).
    #[serde(default)]
    pub(crate) visuals: bool,
    /// Fuse static links into their parents, as MuJoCo's importer does.
    #[serde(default = "yes")]
    pub(crate) fuse_static: bool,
    /// Links kept as bodies even when static links are fused.
    #[serde(default)]
    pub(crate) keep_links: Vec<String>,
    /// Package folders by name, relative to the scene file's folder.
    #[serde(default)]
    pub(crate) packages: std::collections::BTreeMap<String, String>,
    /// One actuator per hinge and slide joint.
    pub(crate) actuators: Option<ActuatorSpec>,
}

/// The actuators of a URDF model: `{ type = "position", kp = 100, kv = 10 }`,
/// `{ type = "velocity", kv = 5 }` or `{ type = "motor" }`, as the Python package's
/// `Document.from_urdf(actuators=...)` takes them.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub(crate) enum ActuatorSpec {
    Position {
        kp: f64,
        #[serde(default)]
        kv: f64,
    },
    Velocity {
        kv: f64,
    },
    Motor,
}

/// A group of objects drawn from a pool.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct GroupSpec {
    pub(crate) name: Spanned<String>,
    pub(crate) pool: Spanned<Vec<Spanned<PoolEntry>>>,
    /// How many: a number, or `[min, max]` inclusive.
    pub(crate) count: Spanned<Count>,
    /// The prefix of instance `i` of the group: `{i}` is replaced by `i`.
    pub(crate) prefix: Option<Spanned<String>>,
    /// Add a free joint to an object that has no joint in its root body (as robosuite does).
    #[serde(default = "yes")]
    pub(crate) free_joint: bool,
    pub(crate) placement: PlacementSpec,
    /// As for fixtures.
    pub(crate) collision_rgba: Option<[f64; 4]>,
    #[serde(default)]
    pub(crate) name_unnamed_geoms: bool,
    /// Give every body of the pool's models whose mass MuJoCo infers from its geoms an
    /// explicit `<inertial>`, as MuJoCo compiles the model file alone (needs MuJoCo when
    /// the scene loads): its mass randomization then scales that `<inertial>`. Unset: done
    /// when a body mass randomizer applies to the group, no randomizer changes its geoms'
    /// densities or masses, and MuJoCo is at hand (see [`super::load`]).
    #[serde(default)]
    pub(crate) write_inertials: Option<bool>,
    /// How the pool's URDF models are read (as for fixtures); an error when none is URDF.
    pub(crate) urdf: Option<Spanned<UrdfSpec>>,
}

fn yes() -> bool {
    true
}

/// One model of a pool: a file name, or a file with a weight.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(crate) enum PoolEntry {
    File(String),
    Weighted { model: String, weight: f64 },
}

impl PoolEntry {
    pub(crate) fn model(&self) -> &str {
        match self {
            PoolEntry::File(m) | PoolEntry::Weighted { model: m, .. } => m,
        }
    }
    pub(crate) fn weight(&self) -> f64 {
        match self {
            PoolEntry::File(_) => 1.0,
            PoolEntry::Weighted { weight, .. } => *weight,
        }
    }
}

/// A count: fixed, or a range.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Count {
    Fixed(u32),
    Range([u32; 2]),
}

impl<'de> Deserialize<'de> for Count {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Count, D::Error> {
        // By hand rather than `untagged`, whose error ("did not match any variant")
        // does not say what is expected.
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Count;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a count: a whole number, or [min, max]")
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Count, E> {
                u32::try_from(v)
                    .map(Count::Fixed)
                    .map_err(|_| E::invalid_value(serde::de::Unexpected::Signed(v), &self))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Count, E> {
                u32::try_from(v)
                    .map(Count::Fixed)
                    .map_err(|_| E::invalid_value(serde::de::Unexpected::Unsigned(v), &self))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Count, A::Error> {
                let lo: u32 = seq
                    .next_element()?
                    .ok_or_else(|| serde::de::Error::invalid_length(0, &self))?;
                let hi: u32 = seq
                    .next_element()?
                    .ok_or_else(|| serde::de::Error::invalid_length(1, &self))?;
                if seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
                    return Err(serde::de::Error::invalid_length(3, &self));
                }
                Ok(Count::Range([lo, hi]))
            }
        }
        d.deserialize_any(Visit)
    }
}

/// Where a group's objects go.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PlacementSpec {
    /// The body or site whose frame the region is in; the world frame without it.
    pub(crate) on: Option<Spanned<String>>,
    /// Stack on an object of this earlier group instead of the region's surface.
    pub(crate) on_top_of: Option<Spanned<String>>,
    /// Range of the object's x in the region's frame (on top of an object: around its
    /// centre).
    pub(crate) x: Spanned<[f64; 2]>,
    pub(crate) y: Spanned<[f64; 2]>,
    /// Height of the surface in the region's frame.
    #[serde(default)]
    pub(crate) z: f64,
    /// Space left between the surface and the object's lowest point.
    #[serde(default)]
    pub(crate) gap: f64,
    pub(crate) rotation: Option<RotationSpec>,
    /// `"radius"` (robosuite's rule: horizontal radii may not overlap) or `"allow"`.
    #[serde(default)]
    pub(crate) overlap: Overlap,
    /// Tries per object before the variant fails.
    #[serde(default = "default_tries")]
    pub(crate) max_tries: u32,
}

fn default_tries() -> u32 {
    1000
}

/// Overlap rule.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub(crate) enum Overlap {
    #[default]
    Radius,
    Allow,
}

/// A rotation about one axis, the angle from a range or a list; the unit is in the key.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RotationSpec {
    /// `"x"`, `"y"`, `"z"` or a vector.
    pub(crate) axis: Option<Spanned<Axis>>,
    pub(crate) range_deg: Option<[f64; 2]>,
    pub(crate) range_rad: Option<[f64; 2]>,
    pub(crate) values_deg: Option<Vec<f64>>,
    pub(crate) values_rad: Option<Vec<f64>>,
}

/// A rotation axis.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(crate) enum Axis {
    Named(String),
    Vector([f64; 3]),
}

/// One attribute randomizer.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RandomizerSpec {
    /// Element tag (`geom`, `light`, `camera`, `material`, `body`...).
    pub(crate) kind: Spanned<String>,
    /// Glob (`*`, `?`) over the element's name as written in its model file.
    pub(crate) name: Option<Spanned<String>>,
    /// `"base"`, a fixture's prefix, or an object group's name.
    pub(crate) part: Option<Spanned<String>>,
    pub(crate) attribute: Spanned<String>,
    pub(crate) uniform: Option<Spanned<[Values; 2]>>,
    pub(crate) log_uniform: Option<Spanned<[Values; 2]>>,
    pub(crate) normal: Option<Spanned<NormalSpec>>,
    pub(crate) choice: Option<Spanned<Vec<ChoiceEntry>>>,
    /// Multiply the current value instead of replacing it.
    #[serde(default)]
    pub(crate) scale: bool,
    /// `"deg"` or `"rad"`: the unit of the numbers given, for angle attributes.
    pub(crate) unit: Option<Spanned<String>>,
    /// Which components the numbers set (all from 0 without it).
    pub(crate) components: Option<Spanned<Vec<usize>>>,
    /// One draw for all the selected elements of a variant instead of one each.
    #[serde(default)]
    pub(crate) shared: bool,
}

/// A number, or one per component.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub(crate) enum Values {
    One(f64),
    Each(Vec<f64>),
}

impl Values {
    pub(crate) fn as_slice(&self) -> &[f64] {
        match self {
            Values::One(x) => std::slice::from_ref(x),
            Values::Each(v) => v,
        }
    }
}

/// A normal distribution cut to `[min, max]` (redrawn until inside).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct NormalSpec {
    pub(crate) mean: Values,
    pub(crate) std: Values,
    pub(crate) min: Values,
    pub(crate) max: Values,
}

/// A string choice: a value, or a value with a weight.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(crate) enum ChoiceEntry {
    Value(String),
    Weighted { value: String, weight: f64 },
}

impl ChoiceEntry {
    pub(crate) fn value(&self) -> &str {
        match self {
            ChoiceEntry::Value(v) | ChoiceEntry::Weighted { value: v, .. } => v,
        }
    }
    pub(crate) fn weight(&self) -> f64 {
        match self {
            ChoiceEntry::Value(_) => 1.0,
            ChoiceEntry::Weighted { weight, .. } => *weight,
        }
    }
}
