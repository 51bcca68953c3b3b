//! Per-world arrays of a scene's superset for batched simulators ([`WorldArrays`]): world
//! `w` holds variant `indices[w]`, each world the superset patched for its variant (what
//! [`ModelCache::model`] gives with [`ModelCache::with_superset`]), and every `mjModel`
//! array the worlds differ in is kept with one row per world, in MuJoCo's own element
//! types; the others are the shared model's. MuJoCo Warp and MJX take such arrays with a
//! leading world axis; MuJoCo's batch API takes one model per world.
//!
//! The shared model must count every body any world compensates for gravity: the
//! engines apply gravity compensation only when `ngravcomp` (which `mj_setConst` counts
//! from `body_gravcomp`) is not zero, and a world that places every object counts none,
//! so its model as the shared one would let the other worlds' parked objects fall. The
//! Python `WorldBatch` gives its shared model every candidate body's compensation for that
//! count; a Rust caller takes a world that parks objects, or counts them likewise.

use std::ffi::CStr;

use super::cache::ModelCache;
use super::sys::{mjf_patch_array, mjf_patch_array_name, mjf_patch_array_type, mjf_patch_get_stat};
use crate::mujoco::CompiledModel;
use crate::split::{STATIC_PREFIXES, WorldRows};
use crate::{ErrorKind, Errors};

use super::{bare, internal};

/// The element type of an `mjModel` array, as MuJoCo declares it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dtype {
    /// `mjtNum`: `f64`.
    F64,
    /// `float`: `f32`.
    F32,
    /// `int`: `i32`.
    I32,
    /// `mjtByte`: `u8`.
    U8,
    /// Any other type, by its size in bytes.
    Other(usize),
}

impl Dtype {
    fn of(c_type: &str, size: usize) -> Dtype {
        match (c_type, size) {
            ("mjtNum", 8) => Dtype::F64,
            ("float", 4) => Dtype::F32,
            ("int", 4) => Dtype::I32,
            ("mjtByte", 1) => Dtype::U8,
            _ => Dtype::Other(size),
        }
    }

    /// Bytes per element.
    pub fn size(self) -> usize {
        match self {
            Dtype::F64 => 8,
            Dtype::F32 | Dtype::I32 => 4,
            Dtype::U8 => 1,
            Dtype::Other(n) => n,
        }
    }
}

/// One `mjModel` array with a row per world: `len` elements of `dtype` each, the worlds'
/// rows end to end in world order.
#[derive(Clone, Debug)]
pub struct WorldField {
    /// The array's name in `mjModel` (`body_pos`, `geom_rgba`, `qpos0`...).
    pub name: String,
    /// Its element type.
    pub dtype: Dtype,
    /// Elements per world (`nbody * 3` for `body_pos`).
    pub len: usize,
    bytes: Vec<u8>,
}

impl WorldField {
    /// World `w`'s row as raw native-endian bytes.
    pub fn row_bytes(&self, w: usize) -> &[u8] {
        let n = self.len * self.dtype.size();
        &self.bytes[w * n..(w + 1) * n]
    }

    /// Every world's row end to end, as `f64` (exact for `F64`, `F32` and `I32` arrays);
    /// `None` for another type.
    pub fn to_f64(&self) -> Option<Vec<f64>> {
        let s = self.dtype.size();
        let chunks = self.bytes.chunks_exact(s);
        match self.dtype {
            Dtype::F64 => Some(
                chunks
                    .map(|c| f64::from_ne_bytes(c.try_into().unwrap_or([0; 8])))
                    .collect(),
            ),
            Dtype::F32 => Some(
                chunks
                    .map(|c| f64::from(f32::from_ne_bytes(c.try_into().unwrap_or([0; 4]))))
                    .collect(),
            ),
            Dtype::I32 => Some(
                chunks
                    .map(|c| f64::from(i32::from_ne_bytes(c.try_into().unwrap_or([0; 4]))))
                    .collect(),
            ),
            _ => None,
        }
    }
}

/// The compiler's statistics of each world: `meaninertia`, `meanmass`, `meansize`,
/// `extent`, `center` (3).
pub type WorldStatistics = [f64; 7];

/// Per-world arrays of a scene's superset: see the module, and [`ModelCache::worlds`].
pub struct WorldArrays {
    /// The variant each world holds.
    pub world_variant: Vec<u64>,
    /// Every array the worlds differ in, one row per world; `qpos0` (each world's
    /// reference and initial pose) always.
    pub fields: Vec<WorldField>,
    /// The statistics of each world.
    pub statistics: Vec<WorldStatistics>,
    /// The root bodies of the objects each world parks.
    pub parked: Vec<Vec<String>>,
    /// World 0's model: every array not in `fields` is every world's.
    pub model: CompiledModel,
}

impl std::fmt::Debug for WorldArrays {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WorldArrays")
            .field("world_variant", &self.world_variant)
            .field(
                "fields",
                &self.fields.iter().map(|x| &x.name).collect::<Vec<_>>(),
            )
            .finish_non_exhaustive()
    }
}

impl WorldArrays {
    /// The per-world field named `name`, if the worlds differ in it.
    pub fn field(&self, name: &str) -> Option<&WorldField> {
        self.fields.iter().find(|f| f.name == name)
    }
}

/// An array of a live model by its number in MuJoCo's table: name, C type, bytes.
fn array(model: &CompiledModel, i: i32) -> Option<(String, Dtype, &[u8])> {
    // SAFETY: static NUL-terminated strings or null.
    let (name, c_type) = unsafe { (mjf_patch_array_name(i), mjf_patch_array_type(i)) };
    if name.is_null() || c_type.is_null() {
        return None;
    }
    // SAFETY: NUL-terminated static strings.
    let (name, c_type) = unsafe { (CStr::from_ptr(name), CStr::from_ptr(c_type)) };
    let (mut elem, mut count) = (0usize, 0usize);
    let raw = std::ptr::from_ref(model.raw()).cast_mut();
    // SAFETY: the model is live; `name` is NUL-terminated; the lookup writes nothing.
    let p = unsafe { mjf_patch_array(raw, name.as_ptr(), &mut elem, &mut count) };
    // SAFETY: `elem * count` bytes at `p` belong to the live model, borrowed as long.
    let bytes = unsafe { crate::mujoco::slice_or_empty(p.cast::<u8>().cast_const(), elem * count) };
    Some((
        name.to_string_lossy().into_owned(),
        Dtype::of(&c_type.to_string_lossy(), elem),
        bytes,
    ))
}

fn statistics(model: &CompiledModel) -> WorldStatistics {
    let mut out = [0.0; 7];
    // SAFETY: a live model; 7 values.
    unsafe { mjf_patch_get_stat(model.raw(), out.as_mut_ptr()) };
    out
}

impl ModelCache<'_> {
    /// Per-world arrays for `indices` (world `w` holds variant `indices[w]`), from a cache
    /// made [`with_superset`](ModelCache::with_superset): every world is the superset
    /// patched for its variant, bit for bit what [`ModelCache::model`] gives for it.
    /// Errors, before any array is kept: no superset, zero worlds, a variant the
    /// superset cannot carry (its index).
    ///
    /// ```no_run
    /// use mjcf_forge::compiled::ModelCache;
    /// use mjcf_forge::scene::Scene;
    ///
    /// let scene = Scene::load("corpora/scenes/patch/boxes.toml").unwrap();
    /// let mut cache = ModelCache::new(&scene, 2, None).with_superset().unwrap();
    /// let worlds = cache.worlds(&[0, 1, 2, 3]).unwrap();
    /// let pos = worlds.field("qpos0").unwrap().to_f64().unwrap(); // 4 rows of nq
    /// assert_eq!(pos.len(), 4 * worlds.model.sizes().nq);
    /// ```
    pub fn worlds(&mut self, indices: &[u64]) -> Result<WorldArrays, Errors> {
        if !self.has_superset() {
            return Err(bare(ErrorKind::NeedsSuperset));
        }
        let Some(&first) = indices.first() else {
            return Err(bare(ErrorKind::NoWorlds));
        };
        let parked = indices
            .iter()
            .map(|&i| self.parked(i))
            .collect::<Result<Vec<_>, _>>()?;
        let model = self.model(first)?.clone();
        let mut scratch = model.clone();
        // World 0's bytes of every array a patch may change, by table number; `qpos0` kept
        // for every world (split::WorldRows, the rule the Python face keeps too).
        let (mut arrays, mut first_rows) = (Vec::new(), Vec::new());
        for i in 0.. {
            let Some((name, dtype, bytes)) = array(&model, i) else {
                break;
            };
            if !STATIC_PREFIXES.iter().any(|p| name.starts_with(p)) {
                arrays.push((i, dtype, bytes.len()));
                let always = name == "qpos0";
                first_rows.push((name, bytes.to_vec(), always));
            }
        }
        let mut rows = WorldRows::new(first_rows);
        for &index in indices {
            self.apply(index, &mut scratch)?;
            let mut views = Vec::with_capacity(arrays.len());
            for (i, _, _) in &arrays {
                let Some((name, _, bytes)) = array(&scratch, *i) else {
                    return Err(internal(format!("mjModel array {i} vanished")));
                };
                if bytes.len() != arrays[views.len()].2 {
                    return Err(internal(format!("mjModel.{name} changed its size")));
                }
                views.push(bytes);
            }
            rows.push(|k| views.get(k).copied(), statistics(&scratch));
        }
        let dtypes: Vec<(String, Dtype)> = rows
            .names()
            .map(str::to_string)
            .zip(arrays.iter().map(|(_, dtype, _)| *dtype))
            .collect();
        let (kept, stats) = rows.into_kept();
        let fields = kept
            .into_iter()
            .map(|(name, bytes)| {
                let dtype = dtypes
                    .iter()
                    .find(|(n, _)| *n == name)
                    .map_or(Dtype::U8, |(_, d)| *d);
                let len = bytes.len() / indices.len().max(1) / dtype.size().max(1);
                WorldField {
                    name,
                    dtype,
                    len,
                    bytes,
                }
            })
            .collect();
        Ok(WorldArrays {
            world_variant: indices.to_vec(),
            fields,
            statistics: stats,
            parked,
            model,
        })
    }
}
