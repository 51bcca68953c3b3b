//! Compiled variants at patch cost: a [`ModelCache`] compiles each structure of a scene once
//! and turns that model into any variant of the structure by writing the variant's patch
//! ([`crate::scene::Scene::patch`]) into its arrays, then running MuJoCo's `mj_setConst`
//! and the statistics the compiler derives from the model at `qpos0` (which `mj_setConst`
//! of 3.17 and 4.0 leaves): exactly the model MuJoCo compiles from the variant's XML
//! (`tests/model_cache.rs` compares every array bit for bit). The rules (misses, patches,
//! a caller's model checked, the bound) are the split tier's cache core, run over the
//! linked MuJoCo by `store.rs`, which [`super::DocumentCache`] shares.

use std::cell::Cell;

use super::store::{Core, Linked, cache_error};
use super::sys::{mjf_patch_array, mjf_patch_array_name, mjf_patch_get_stat};
use crate::mujoco::{CompileError, CompiledModel, compile_str};
use crate::scene::{Scene, Superset, VariantPatch};
use crate::split::{DiskStore, Request, StoreKey, fixed_statistics_mask, load_or_compile};
use crate::{Document, ErrorKind, Errors};

use super::bare;

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
    /// The statistics the scene's `<statistic>` fixes, as bits.
    fixed: u32,
    core: Core,
    linked: Linked,
    max: (usize, Option<usize>),
    /// With [`ModelCache::with_store`]: where structures are kept across processes.
    store: Option<DiskStore>,
    loads: u64,
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
            core: Core::new(max_models, max_bytes, false),
            linked: Linked::default(),
            max: (max_models, max_bytes),
            store: None,
            loads: 0,
        }
    }

    /// The same cache, keeping the structures it compiles in `store` across processes
    /// ([`DiskStore`]): a miss whose structure another process compiled with this MuJoCo
    /// and these files loads that model and patches it into the variant. Never for a
    /// superset (its one model is the superset's own compile). A store that fails is
    /// reported on standard error and the cache compiles as without it.
    pub fn with_store(mut self, store: DiskStore) -> Self {
        self.store = Some(store);
        self
    }

    /// Misses so far that were loads from the store (of [`ModelCache::compiles`]).
    pub fn loads(&self) -> u64 {
        self.loads
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
        self.core = Core::new(self.max.0, self.max.1, true);
        Ok(self)
    }

    /// Superset: whether a patch derives what `mj_setConst` would tree by tree, where its
    /// layout allows (`split::TreeDerivation`: the same bits, a fraction of the cost on a
    /// large superset; on by default), or runs `mj_setConst` always.
    pub fn deriving_by_tree(mut self, by_tree: bool) -> Self {
        self.linked.by_tree = by_tree;
        self
    }

    /// Superset patches whose derived values came tree by tree so far.
    pub fn derived_by_tree(&self) -> u64 {
        self.linked.derived
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

    /// The variant's patch (of its own structure, or of the superset) and, for a
    /// superset, the roots it parks.
    fn patch_of(&self, index: u64) -> Result<(VariantPatch, Option<Vec<String>>), Errors> {
        match &self.superset {
            Some(s) => Ok((
                self.scene.superset_patch(&s.superset, index)?,
                Some(self.scene.superset_parked(&s.superset, index)?),
            )),
            None => Ok((self.scene.patch(index)?, None)),
        }
    }

    /// Models compiled so far (misses).
    pub fn compiles(&self) -> u64 {
        self.core.compiles()
    }

    /// Patches applied so far.
    pub fn patches(&self) -> u64 {
        self.core.patches()
    }

    /// How many compiled models the cache holds.
    pub fn len(&self) -> usize {
        self.core.len()
    }

    /// Whether the cache holds none.
    pub fn is_empty(&self) -> bool {
        self.core.is_empty()
    }

    /// Bytes held: the cached models and every plan's scratch data.
    pub fn nbytes(&self) -> usize {
        self.core.nbytes()
    }

    /// Variant `index` as MuJoCo compiles it from its XML: the cached model of its
    /// structure patched in place, or on a miss the variant compiled (and kept). The model
    /// stays the cache's: the next call for the same structure patches it again.
    pub fn model(&mut self, index: u64) -> Result<&CompiledModel, Errors> {
        let (patch, parked) = self.patch_of(index)?;
        let request = self.request(&patch, parked.as_deref());
        let key = &patch.structure_key;
        let loaded = Cell::new(false);
        let compile = stored_compiler(
            self.scene,
            &self.superset,
            self.dir.as_deref(),
            index,
            (self.store.as_ref(), key),
            &loaded,
        );
        self.core
            .model(&mut self.linked, &request, compile)
            .map_err(|e| cache_error(e, index, key))?;
        if loaded.get() {
            // Another variant's compile, from the store: now a hit, patched into this one.
            self.loads += 1;
            let compile = compiler(self.scene, &self.superset, self.dir.as_deref(), index);
            self.core
                .model(&mut self.linked, &request, compile)
                .map_err(|e| cache_error(e, index, key))?;
        }
        self.core.last().map_err(|e| cache_error(e, index, key))
    }

    /// Patches `model`, a model of variant `index`'s structure, in place into variant
    /// `index`'s compiled model. A model of another structure is refused.
    pub fn apply(&mut self, index: u64, model: &mut CompiledModel) -> Result<(), Errors> {
        let (patch, parked) = self.patch_of(index)?;
        let request = self.request(&patch, parked.as_deref());
        let key = &patch.structure_key;
        // The structure's first sight may load its model: kept, and patched before it is
        // given out, as every cached model is.
        let loaded = Cell::new(false);
        let compile = stored_compiler(
            self.scene,
            &self.superset,
            self.dir.as_deref(),
            index,
            (self.store.as_ref(), key),
            &loaded,
        );
        self.core
            .apply(&mut self.linked, &request, model, compile)
            .map_err(|e| cache_error(e, index, key))?;
        self.loads += u64::from(loaded.get());
        Ok(())
    }

    fn request<'a>(&self, patch: &'a VariantPatch, parked: Option<&'a [String]>) -> Request<'a> {
        Request {
            key: &patch.structure_key,
            entries: &patch.entries,
            parked,
            fixed: self.fixed,
        }
    }
}

/// [`compiler`] through `store` under structure key `key` (no superset), on its first call:
/// a stored model is loaded (`loaded` says so), a compiled one stored.
fn stored_compiler<'a>(
    scene: &'a Scene,
    superset: &'a Option<SupersetState>,
    dir: Option<&'a std::path::Path>,
    index: u64,
    (store, key): (Option<&'a DiskStore>, &'a str),
    loaded: &'a Cell<bool>,
) -> impl FnMut() -> Result<CompiledModel, Errors> + 'a {
    let mut compile = compiler(scene, superset, dir, index);
    // Never for a superset: its one model is the superset's own compile.
    let mut store = store.filter(|_| superset.is_none()).map(|s| (s, key));
    let dir = dir.unwrap_or_else(|| scene.template().model_dir());
    move || {
        let Some((store, key)) = store.take() else {
            return compile();
        };
        let xml = scene.variant_xml(index)?.0;
        let Ok(doc) = Document::from_str(&xml, dir) else {
            return compile();
        };
        let key = StoreKey::of_document(key, &crate::mujoco::version(), &doc);
        let (model, stored) = load_or_compile(
            Some((store, key.as_str())),
            CompiledModel::from_bytes,
            |m: &CompiledModel| Some(m.to_bytes()),
            &mut compile,
            &mut |w| eprintln!("mjcf-forge: {w}"),
        )?;
        loaded.set(stored);
        Ok(model)
    }
}

/// The compile of variant `index`'s structure: the superset, or the variant's XML, with
/// relative file names resolved against `dir` (else the template's folder).
fn compiler<'a>(
    scene: &'a Scene,
    superset: &'a Option<SupersetState>,
    dir: Option<&'a std::path::Path>,
    index: u64,
) -> impl FnMut() -> Result<CompiledModel, Errors> + 'a {
    move || {
        let xml = match superset {
            Some(s) => s.xml.clone(),
            None => scene.variant_xml(index)?.0,
        };
        let dir = dir.unwrap_or_else(|| scene.template().model_dir());
        compile_str(&xml, dir).map_err(|e: CompileError| {
            bare(ErrorKind::Compile {
                variant: index,
                message: e.to_string(),
            })
        })
    }
}

/// A superset cache's own state: the superset and its XML.
struct SupersetState {
    superset: Superset,
    xml: String,
}
