//! Compiled variants at patch cost: a [`ModelCache`] compiles each structure of a scene once
//! and turns that model into any variant of the structure by writing the variant's patch
//! ([`crate::scene::Scene::patch`]) into its arrays, then running MuJoCo's `mj_setConst`
//! and the statistics the compiler derives from the model at `qpos0` (which `mj_setConst`
//! of 3.17 and 4.0 leaves): exactly the model MuJoCo compiles from the variant's XML
//! (`tests/model_cache.rs` compares every array bit for bit). The mechanism (models kept by
//! key, least recently used out; plans; the C side) is `store.rs`, which
//! [`super::DocumentCache`] shares.

use super::store::Store;
use super::sys::{mjf_patch_array, mjf_patch_array_name, mjf_patch_get_stat};
use crate::mujoco::{CompileError, CompiledModel, compile_str};
use crate::scene::{Scene, Superset, VariantPatch};
use crate::split::{PatchEntry, Signature, fixed_statistics_mask};
use crate::{ErrorKind, Errors};

use super::{bare, internal};

impl CompiledModel {
    /// Where `other` differs from this model: every array of `mjModel` compared bit for
    /// bit (float arrays included) and the statistics; empty when they are the same.
    /// Each difference names the array and its first differing element.
    ///
    /// ```
    /// use mjcf_forge::mujoco::compile_str;
    /// let a = compile_str("<mujoco><worldbody><geom size='1'/></worldbody></mujoco>", ".".as_ref()).unwrap();
    /// let b = compile_str("<mujoco><worldbody><geom size='2'/></worldbody></mujoco>", ".".as_ref()).unwrap();
    /// assert!(a.differences(&a.clone()).is_empty());
    /// assert!(b.differences(&a).iter().any(|d| d.starts_with("geom_size")));
    /// ```
    pub fn differences(&self, other: &CompiledModel) -> Vec<String> {
        self.compare(other, None)
    }

    /// Where `other` differs from this model beyond `bound`: integer and `float` arrays
    /// bit for bit, `mjtNum` arrays and the statistics within `bound` relative to the
    /// larger magnitude of the two values (or of the array, for values near zero: a box's
    /// centre), for results MuJoCo's own arithmetic cannot be reproduced in, such as mass
    /// properties combined from geoms' densities (docs/compiled.md). Each difference names the array and its first element beyond.
    ///
    /// ```
    /// use mjcf_forge::mujoco::compile_str;
    /// let m = |s: &str| compile_str(&format!("<mujoco><worldbody><body><freejoint/><geom size='{s}'/></body></worldbody></mujoco>"), ".".as_ref()).unwrap();
    /// assert!(m("1").differences_beyond(&m("1.0000000000000002"), 1e-12).is_empty());
    /// assert!(!m("1").differences_beyond(&m("1.001"), 1e-12).is_empty());
    /// ```
    pub fn differences_beyond(&self, other: &CompiledModel, bound: f64) -> Vec<String> {
        self.compare(other, Some(bound))
    }

    fn compare(&self, other: &CompiledModel, bound: Option<f64>) -> Vec<String> {
        let close = |a: f64, b: f64| match bound {
            None => a.to_bits() == b.to_bits(),
            Some(bound) => {
                a.to_bits() == b.to_bits()
                    || (a - b).abs() <= bound * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
            }
        };
        let mut out = Vec::new();
        if self.sizes() != other.sizes() {
            out.push("sizes".to_string());
            return out;
        }
        for i in 0.. {
            // SAFETY: a static string or null.
            let name = unsafe { mjf_patch_array_name(i) };
            if name.is_null() {
                break;
            }
            let bytes = |m: &CompiledModel| -> (&[u8], usize) {
                let (mut elem, mut count) = (0usize, 0usize);
                // The C side hands back a writable pointer; nothing is written through it here.
                let raw = std::ptr::from_ref(m.raw()).cast_mut();
                // SAFETY: the model is live (only read here); `name` is NUL-terminated.
                let p = unsafe { mjf_patch_array(raw, name, &mut elem, &mut count) };
                // SAFETY: `elem * count` bytes at `p` belong to the live model.
                let b = unsafe {
                    crate::mujoco::slice_or_empty(p.cast::<u8>().cast_const(), elem * count)
                };
                (b, elem)
            };
            let ((a, elem), (b, _)) = (bytes(self), bytes(other));
            if a == b {
                continue;
            }
            let at = if let Some(bound) = bound
                && elem == 8
                && a.len() == b.len()
            {
                let float = |x: &[u8]| f64::from_ne_bytes(x.try_into().unwrap_or([0; 8]));
                // Values near zero (a box's centre) against the array's magnitude.
                let scale = a
                    .chunks_exact(8)
                    .map(|x| float(x).abs())
                    .fold(0.0, f64::max);
                match a.chunks_exact(8).zip(b.chunks_exact(8)).position(|(x, y)| {
                    let (x, y) = (float(x), float(y));
                    !close(x, y) && (x - y).abs() > bound * scale
                }) {
                    Some(k) => 8 * k,
                    None => continue,
                }
            } else {
                a.iter().zip(b).position(|(x, y)| x != y).unwrap_or(0)
            };
            // SAFETY: NUL-terminated static string.
            let name = unsafe { std::ffi::CStr::from_ptr(name) }.to_string_lossy();
            out.push(format!("{name} (byte {at})"));
        }
        let (mut a, mut b) = ([0.0; 7], [0.0; 7]);
        // SAFETY: live models; 7 values each.
        unsafe {
            mjf_patch_get_stat(self.raw(), a.as_mut_ptr());
            mjf_patch_get_stat(other.raw(), b.as_mut_ptr());
        }
        for (k, name) in [
            "meaninertia",
            "meanmass",
            "meansize",
            "extent",
            "center",
            "center",
            "center",
        ]
        .iter()
        .enumerate()
        {
            if !close(a[k], b[k]) {
                out.push(format!("stat.{name}: {} != {}", a[k], b[k]));
            }
        }
        out
    }
}

/// Compiled models of a [`Scene`]'s variants, one per structure, patched per variant;
/// bounded in count and bytes (models and their scratch data), least recently used out.
///
/// ```no_run
/// use mjcf_forge::compiled::ModelCache;
/// use mjcf_forge::scene::Scene;
///
/// let scene = Scene::demo().unwrap();
/// let mut cache = ModelCache::new(&scene, 8, None);
/// // Variant 3 as MuJoCo compiles it from its XML: compiled now, patched next time.
/// let nbody = cache.model(3).unwrap().sizes().nbody;
/// // An environment's own model, patched in place into variant 4 (same structure).
/// let mut mine = cache.model(3).unwrap().clone();
/// if scene.patch(4).unwrap().structure_key == scene.patch(3).unwrap().structure_key {
///     cache.apply(4, &mut mine).unwrap();
/// }
/// # let _ = nbody;
/// ```
pub struct ModelCache<'s> {
    scene: &'s Scene,
    /// The folder relative file names in the variants' XML resolve against.
    dir: Option<std::path::PathBuf>,
    /// With [`ModelCache::with_superset`]: the scene's superset.
    superset: Option<SupersetState>,
    /// The statistics the scene's `<statistic>` fixes, as bits (see `Store::insert`).
    fixed: u32,
    store: Store,
}

impl<'s> ModelCache<'s> {
    /// A cache for `scene` holding at most `max_models` compiled models (at least one)
    /// and, when given, about `max_bytes` of models and scratch data.
    pub fn new(scene: &'s Scene, max_models: usize, max_bytes: Option<usize>) -> Self {
        ModelCache {
            scene,
            dir: None,
            superset: None,
            fixed: fixed_statistics_mask(scene.fixed_statistics()),
            store: Store::new(max_models, max_bytes),
        }
    }

    /// Compiles variants with relative file names resolved against `dir` (a scene whose
    /// assets were relocated into an output folder) instead of the template's folder.
    pub fn compiling_in(mut self, dir: impl Into<std::path::PathBuf>) -> Self {
        self.dir = Some(dir.into());
        self
    }

    /// Makes every variant a patch of one model, the scene's superset
    /// ([`Scene::superset`]): `model(i)` is that model patched for variant `i`.
    pub fn with_superset(mut self) -> Result<Self, Errors> {
        let superset = self.scene.superset()?;
        let xml = superset.document.to_xml_string();
        self.superset = Some(SupersetState { superset, xml });
        Ok(self)
    }

    /// Whether every variant is a patch of the superset ([`ModelCache::with_superset`]).
    pub(super) fn has_superset(&self) -> bool {
        self.superset.is_some()
    }

    /// The root bodies of the objects variant `index` parks in the superset.
    pub(super) fn parked(&self, index: u64) -> Result<Vec<String>, Errors> {
        let Some(s) = &self.superset else {
            return Err(bare(ErrorKind::NeedsSuperset));
        };
        self.scene.superset_parked(&s.superset, index)
    }

    /// The variant's patch: of its own structure, or of the superset.
    fn patch_of(&self, index: u64) -> Result<VariantPatch, Errors> {
        match &self.superset {
            Some(s) => self.scene.superset_patch(&s.superset, index),
            None => self.scene.patch(index),
        }
    }

    /// Models compiled so far (misses).
    pub fn compiles(&self) -> u64 {
        self.store.compiles
    }

    /// Patches applied so far.
    pub fn patches(&self) -> u64 {
        self.store.patches
    }

    /// How many compiled models the cache holds.
    pub fn len(&self) -> usize {
        self.store.len()
    }

    /// Whether the cache holds none.
    pub fn is_empty(&self) -> bool {
        self.store.len() == 0
    }

    /// Bytes held: the cached models and every plan's scratch data.
    pub fn nbytes(&self) -> usize {
        self.store.nbytes()
    }

    /// Variant `index` as MuJoCo compiles it from its XML: the cached model of its
    /// structure patched in place, or on a miss the variant compiled (and kept). The model
    /// stays the cache's: the next call for the same structure patches it again.
    pub fn model(&mut self, index: u64) -> Result<&CompiledModel, Errors> {
        let patch = self.patch_of(index)?;
        let key = patch.structure_key;
        let patch_it = if self.store.touch(&key) {
            true
        } else {
            self.compile(index, &key)?;
            // The superset as compiled parks every object: place the variant's.
            self.superset.is_some()
        };
        if patch_it {
            let target = (index, key.as_str(), patch.entries.as_slice());
            let patched = patch_variant(self.scene, &self.superset, &mut self.store, target, None);
            match patched {
                Ok(()) => self.store.trim(),
                // A body's geoms that compile to another layout (sizes that turn its
                // principal axes): not a patch of this structure, so the variant is
                // compiled (and kept). The superset has no other structure to offer.
                Err(_) if self.superset.is_none() => {
                    self.store.remove(&key);
                    self.compile(index, &key)?;
                }
                Err(e) => return Err(internal(e)),
            }
        }
        self.store
            .last()
            .ok_or_else(|| internal("the cache holds no model".to_string()))
    }

    /// Patches `model`, a model of variant `index`'s structure, in place into variant
    /// `index`'s compiled model. A model of another structure is refused.
    pub fn apply(&mut self, index: u64, model: &mut CompiledModel) -> Result<(), Errors> {
        let patch = self.patch_of(index)?;
        let key = patch.structure_key;
        match self.store.plan_key(model) {
            Some(found) if found != key => {
                return Err(bare(ErrorKind::OtherStructure {
                    variant: index,
                    found: Some(found.to_string()),
                    key,
                }));
            }
            Some(_) => {}
            None => {
                if !self.store.signatures.contains_key(&key) {
                    self.compile(index, &key)?;
                }
                if self.store.signatures.get(&key) != Some(&Signature::of(model)) {
                    return Err(bare(ErrorKind::OtherStructure {
                        variant: index,
                        key,
                        found: None,
                    }));
                }
            }
        }
        let target = (index, key.as_str(), patch.entries.as_slice());
        patch_variant(
            self.scene,
            &self.superset,
            &mut self.store,
            target,
            Some(model),
        )
        .map_err(internal)?;
        self.store.trim();
        Ok(())
    }

    fn compile(&mut self, index: u64, key: &str) -> Result<(), Errors> {
        let xml = match &self.superset {
            Some(s) => s.xml.clone(),
            None => self.scene.variant_xml(index)?.0,
        };
        let dir = self
            .dir
            .as_deref()
            .unwrap_or_else(|| self.scene.template().model_dir());
        let model = compile_str(&xml, dir).map_err(|e: CompileError| {
            bare(ErrorKind::Compile {
                variant: index,
                message: e.to_string(),
            })
        })?;
        self.store.insert(key, model, self.fixed).map_err(internal)
    }
}

/// A superset cache's own state: the superset and its XML.
struct SupersetState {
    superset: Superset,
    xml: String,
}

/// Writes variant `index`'s patch (`key`, `entries`) into `model`, and for a superset
/// `stat.meaninertia` as the variant's own model has it (`PatchPlan::variant_inertia`).
fn patch_variant(
    scene: &Scene,
    superset: &Option<SupersetState>,
    store: &mut Store,
    (index, key, entries): (u64, &str, &[PatchEntry]),
    model: Option<&mut CompiledModel>,
) -> Result<(), String> {
    let roots = match superset {
        Some(sup) => Some(
            scene
                .superset_parked(&sup.superset, index)
                .map_err(|e| e.to_string())?,
        ),
        None => None,
    };
    store.with_plan(model, key, |plan, model| {
        plan.apply(model, entries)?;
        match &roots {
            Some(roots) => plan.variant_inertia(model, roots),
            None => Ok(()),
        }
    })?;
    store.patches += 1;
    Ok(())
}
