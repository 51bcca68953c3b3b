//! Compiled variants at patch cost: a [`ModelCache`] compiles each structure of a scene once
//! and turns that model into any variant of the structure by writing the variant's patch
//! ([`crate::scene::Scene::patch`]) into its arrays, then running MuJoCo's `mj_setConst`
//! and the statistics the compiler derives from the model at `qpos0` (which `mj_setConst`
//! of 3.17 and 4.0 leaves): exactly the model MuJoCo compiles from the variant's XML
//! (`tests/model_cache.rs` compares every array bit for bit).
//!
//! The C side (`patch.c`) is compiled against the linked MuJoCo's headers, as the FFI's
//! shim is; arrays are found by name through MuJoCo's X-macro table, so no Rust copy of
//! `mjModel`'s layout is needed. Models come from the FFI ([`crate::mujoco`]), which hands
//! over the raw model, its serial number and the writable pointer through `pub(crate)` items.

use std::collections::HashMap;
use std::ffi::{CString, c_char, c_int, c_void};
use std::ptr::NonNull;

use crate::mujoco::{CompileError, CompiledModel, MjModel, ObjType, Sizes, compile_str};
use crate::scene::{PatchEntry, PatchValue, Scene, Superset, VariantPatch};

/// mjData, opaque here: only the C side reads it.
#[repr(C)]
struct RawData {
    _private: [u8; 0],
}

unsafe extern "C" {
    fn mjf_patch_array(
        m: *mut MjModel,
        name: *const c_char,
        elem: *mut usize,
        count: *mut usize,
    ) -> *mut c_void;
    fn mjf_patch_name2id(m: *const MjModel, kind: *const c_char, name: *const c_char) -> c_int;
    fn mjf_patch_make_data(m: *const MjModel) -> *mut RawData;
    fn mjf_patch_delete_data(d: *mut RawData);
    fn mjf_patch_nbytes(m: *const MjModel, d: *const RawData) -> i64;
    fn mjf_patch_get_stat(m: *const MjModel, out: *mut f64);
    fn mjf_patch_finish(m: *mut MjModel, d: *mut RawData, fixed: c_int, values: *const f64);
    fn mjf_patch_array_name(i: c_int) -> *const c_char;
    fn mjf_patch_meaninertia(m: *mut MjModel, d: *const RawData, keep: *const c_int, n: c_int);
}

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
            let bytes = |m: &CompiledModel| -> &[u8] {
                let (mut elem, mut count) = (0usize, 0usize);
                // The C side hands back a writable pointer; nothing is written through it here.
                let raw = std::ptr::from_ref(m.raw()).cast_mut();
                // SAFETY: the model is live (only read here); `name` is NUL-terminated.
                let p = unsafe { mjf_patch_array(raw, name, &mut elem, &mut count) };
                // SAFETY: `elem * count` bytes at `p` belong to the live model.
                unsafe { crate::mujoco::slice_or_empty(p.cast::<u8>().cast_const(), elem * count) }
            };
            let (a, b) = (bytes(self), bytes(other));
            if a != b {
                // SAFETY: NUL-terminated static string.
                let name = unsafe { std::ffi::CStr::from_ptr(name) }.to_string_lossy();
                let at = a.iter().zip(b).position(|(x, y)| x != y).unwrap_or(0);
                out.push(format!("{name} (byte {at})"));
            }
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
            if a[k].to_bits() != b[k].to_bits() {
                out.push(format!("stat.{name}: {} != {}", a[k], b[k]));
            }
        }
        out
    }
}

/// Scratch mjData for `mj_setConst` (which overwrites the qpos of the data it is given).
struct Scratch(NonNull<RawData>);

// SAFETY: exclusively owned heap data without thread affinity.
unsafe impl Send for Scratch {}

impl Scratch {
    fn new(model: &CompiledModel) -> Result<Scratch, String> {
        // SAFETY: the model is live.
        let d = unsafe { mjf_patch_make_data(model.raw()) };
        NonNull::new(d)
            .map(Scratch)
            .ok_or_else(|| "MuJoCo could not allocate mjData for the model".to_string())
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        // SAFETY: made by mj_makeData, owned here alone.
        unsafe { mjf_patch_delete_data(self.0.as_ptr()) }
    }
}

/// Where one patch entry lands: `n` elements at `ptr` (`elem` bytes each; a one-value
/// entry fills all `n`, as a joint's damping fills each of its dofs).
struct Target {
    ptr: *mut u8,
    elem: usize,
    n: usize,
    /// The field holds integers: an id (`geom_matid`, the value a material's name) or
    /// collision bits (`geom_contype`, `geom_conaffinity`).
    int: bool,
}

/// How to patch one model: its structure key, scratch data and resolved targets.
struct Plan {
    serial: u64,
    key: String,
    scratch: Scratch,
    fields: Vec<(&'static str, String, Option<usize>, &'static str)>,
    targets: Vec<Target>,
    nbytes: usize,
}

// SAFETY: the raw pointers point into the model the plan belongs to, which is only
// written through `&mut` of that model.
unsafe impl Send for Plan {}

/// What a structure is: the sizes and names of its model, to refuse a model of another.
#[derive(PartialEq)]
struct Signature {
    sizes: Sizes,
    names: Vec<Vec<String>>,
}

impl Signature {
    fn of(m: &CompiledModel) -> Signature {
        Signature {
            sizes: m.sizes(),
            names: [ObjType::Body, ObjType::Joint, ObjType::Geom, ObjType::Site]
                .into_iter()
                .map(|o| m.names(o))
                .collect(),
        }
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
    /// Cached models by structure key, least recently used first.
    entries: Vec<(String, CompiledModel)>,
    state: State,
}

/// Everything but the cached models (so that a cached model and the plans can be borrowed
/// at once).
struct State {
    max_models: usize,
    max_bytes: Option<usize>,
    /// Plans by model serial (cached models' and callers'), least recently used first.
    plans: Vec<Plan>,
    signatures: HashMap<String, Signature>,
    /// Per structure, the statistics the scene fixes (see `Scene::fixed_statistics`).
    stats: HashMap<String, [f64; 7]>,
    fixed: c_int,
    compiles: u64,
    patches: u64,
}

impl<'s> ModelCache<'s> {
    /// A cache for `scene` holding at most `max_models` compiled models (at least one)
    /// and, when given, about `max_bytes` of models and scratch data.
    pub fn new(scene: &'s Scene, max_models: usize, max_bytes: Option<usize>) -> Self {
        let fixed = scene
            .fixed_statistics()
            .iter()
            .map(|s| match *s {
                "meaninertia" => 1,
                "meanmass" => 2,
                "meansize" => 4,
                "extent" => 8,
                _ => 16,
            })
            .fold(0, |a, b| a | b);
        ModelCache {
            scene,
            dir: None,
            superset: None,
            entries: Vec::new(),
            state: State {
                max_models: max_models.max(1),
                max_bytes,
                plans: Vec::new(),
                signatures: HashMap::new(),
                stats: HashMap::new(),
                fixed,
                compiles: 0,
                patches: 0,
            },
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
    pub fn with_superset(mut self) -> Result<Self, String> {
        let superset = self.scene.superset().map_err(|e| e.to_string())?;
        let xml = superset.document.to_xml_string();
        self.superset = Some(SupersetState {
            superset,
            xml,
            kept_dofs: HashMap::new(),
        });
        Ok(self)
    }

    /// The variant's patch: of its own structure, or of the superset.
    fn patch_of(&self, index: u64) -> Result<VariantPatch, String> {
        match &self.superset {
            Some(s) => self.scene.superset_patch(&s.superset, index),
            None => self.scene.patch(index),
        }
        .map_err(|e| e.to_string())
    }

    /// Models compiled so far (misses).
    pub fn compiles(&self) -> u64 {
        self.state.compiles
    }

    /// Patches applied so far.
    pub fn patches(&self) -> u64 {
        self.state.patches
    }

    /// How many compiled models the cache holds.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether the cache holds none.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Bytes held: the cached models and every plan's scratch data.
    pub fn nbytes(&self) -> usize {
        self.state.nbytes()
    }

    /// Variant `index` as MuJoCo compiles it from its XML: the cached model of its
    /// structure patched in place, or on a miss the variant compiled (and kept). The model
    /// stays the cache's: the next call for the same structure patches it again.
    pub fn model(&mut self, index: u64) -> Result<&CompiledModel, String> {
        let patch = self.patch_of(index)?;
        let key = patch.structure_key;
        let at = match self.entries.iter().position(|(k, _)| *k == key) {
            None => {
                self.compile(index, &key)?;
                // The superset as compiled parks every object: place the variant's.
                self.superset.is_some()
            }
            Some(at) => {
                let entry = self.entries.remove(at);
                self.entries.push(entry);
                true
            }
        };
        let last = self.entries.len() - 1;
        if at {
            let model = &mut self.entries[last].1;
            let target = (index, key.as_str(), patch.entries.as_slice());
            patch_variant(
                self.scene,
                &mut self.superset,
                &mut self.state,
                target,
                model,
            )?;
            self.state.trim(&mut self.entries);
        }
        Ok(&self.entries[self.entries.len() - 1].1)
    }

    /// Patches `model`, a model of variant `index`'s structure, in place into variant
    /// `index`'s compiled model. A model of another structure is refused.
    pub fn apply(&mut self, index: u64, model: &mut CompiledModel) -> Result<(), String> {
        let patch = self.patch_of(index)?;
        let key = patch.structure_key;
        let known = self.state.plans.iter().find(|p| p.serial == model.serial());
        match known {
            Some(p) if p.key != key => {
                return Err(format!(
                    "the model has structure {}, variant {index} has {key}: a patch cannot \
                     change a structure (ModelCache::model compiles it)",
                    p.key
                ));
            }
            Some(_) => {}
            None => {
                if !self.state.signatures.contains_key(&key) {
                    self.compile(index, &key)?;
                }
                if self.state.signatures.get(&key) != Some(&Signature::of(model)) {
                    return Err(format!(
                        "the model does not have the structure of variant {index} (key \
                         {key}): its sizes or names differ"
                    ));
                }
            }
        }
        let target = (index, key.as_str(), patch.entries.as_slice());
        patch_variant(
            self.scene,
            &mut self.superset,
            &mut self.state,
            target,
            model,
        )?;
        self.state.trim(&mut self.entries);
        Ok(())
    }

    fn compile(&mut self, index: u64, key: &str) -> Result<(), String> {
        let xml = match &self.superset {
            Some(s) => s.xml.clone(),
            None => self.scene.variant_xml(index).map_err(|e| e.to_string())?.0,
        };
        let dir = self
            .dir
            .as_deref()
            .unwrap_or_else(|| self.scene.template().model_dir());
        let model = compile_str(&xml, dir)
            .map_err(|e: CompileError| format!("variant {index}: MuJoCo: {e}"))?;
        let state = &mut self.state;
        state.compiles += 1;
        let mut stat = [0.0; 7];
        // SAFETY: the model is live; `stat` holds 7 values.
        unsafe { mjf_patch_get_stat(model.raw(), stat.as_mut_ptr()) };
        state.stats.insert(key.to_string(), stat);
        state
            .signatures
            .insert(key.to_string(), Signature::of(&model));
        // Its plan now, so that its bytes count.
        state.plan_of(&model, key)?;
        self.entries.push((key.to_string(), model));
        self.state.trim(&mut self.entries);
        Ok(())
    }
}

impl State {
    fn nbytes(&self) -> usize {
        self.plans.iter().map(|p| p.nbytes).sum()
    }

    /// Drops the least recently used models (and plans) beyond the bounds.
    fn trim(&mut self, entries: &mut Vec<(String, CompiledModel)>) {
        while entries.len() > 1
            && (entries.len() > self.max_models
                || self.max_bytes.is_some_and(|b| self.nbytes() > b))
        {
            let (_, gone) = entries.remove(0);
            self.plans.retain(|p| p.serial != gone.serial());
        }
        // Plans of callers' models: as many as cached models are allowed.
        let cached: Vec<u64> = entries.iter().map(|(_, m)| m.serial()).collect();
        let mut extra = self
            .plans
            .iter()
            .filter(|p| !cached.contains(&p.serial))
            .count();
        self.plans.retain(|p| {
            if extra > self.max_models && !cached.contains(&p.serial) {
                extra -= 1;
                false
            } else {
                true
            }
        });
    }

    /// The index of `model`'s plan, made on first sight.
    fn plan_of(&mut self, model: &CompiledModel, key: &str) -> Result<usize, String> {
        if let Some(at) = self.plans.iter().position(|p| p.serial == model.serial()) {
            return Ok(at);
        }
        let scratch = Scratch::new(model)?;
        // SAFETY: model and data are live.
        let nbytes = unsafe { mjf_patch_nbytes(model.raw(), scratch.0.as_ptr()) };
        self.plans.push(Plan {
            serial: model.serial(),
            key: key.to_string(),
            scratch,
            fields: Vec::new(),
            targets: Vec::new(),
            nbytes: usize::try_from(nbytes).unwrap_or(0),
        });
        Ok(self.plans.len() - 1)
    }

    fn patch_model(
        &mut self,
        model: &mut CompiledModel,
        key: &str,
        entries: &[PatchEntry],
    ) -> Result<(), String> {
        let at = self.plan_of(model, key)?;
        let plan = &mut self.plans[at];
        let same =
            plan.fields.len() == entries.len()
                && plan.fields.iter().zip(entries).all(|(f, e)| {
                    f.0 == e.object && f.1 == e.name && f.2 == e.id && f.3 == e.field
                });
        if !same {
            plan.targets = resolve(model, entries)?;
            plan.fields = entries
                .iter()
                .map(|e| (e.object, e.name.clone(), e.id, e.field))
                .collect();
        }
        let ptr = model.as_mut_ptr();
        for (t, e) in plan.targets.iter().zip(entries) {
            write(ptr, t, &e.value)?;
        }
        let stat = self.stats.get(key).copied().unwrap_or_default();
        // SAFETY: the model and its scratch data are live and of one structure.
        unsafe { mjf_patch_finish(ptr, plan.scratch.0.as_ptr(), self.fixed, stat.as_ptr()) };
        let plan = self.plans.remove(at);
        self.plans.push(plan);
        self.patches += 1;
        Ok(())
    }
}

/// A superset cache's own state: the superset, its XML, and per set of parked objects the
/// dofs of the variant's own model.
struct SupersetState {
    superset: Superset,
    xml: String,
    kept_dofs: HashMap<Vec<String>, Vec<c_int>>,
}

/// Writes variant `index`'s patch (`key`, `entries`) into `model`, and for a superset
/// `stat.meaninertia` (which scales the constraint solver's tolerance) as the variant's own
/// model has it: the mass matrix's diagonal over the dofs of what the variant places (the
/// superset's dof order is the variant's), parked objects left out.
fn patch_variant(
    scene: &Scene,
    superset: &mut Option<SupersetState>,
    state: &mut State,
    (index, key, entries): (u64, &str, &[PatchEntry]),
    model: &mut CompiledModel,
) -> Result<(), String> {
    state.patch_model(model, key, entries)?;
    let Some(sup) = superset else {
        return Ok(());
    };
    let roots = scene
        .superset_parked(&sup.superset, index)
        .map_err(|e| e.to_string())?;
    if !sup.kept_dofs.contains_key(&roots) {
        let keep = kept_dofs(model, &roots)?;
        sup.kept_dofs.insert(roots.clone(), keep);
    }
    let keep = &sup.kept_dofs[&roots];
    let Some(plan) = state.plans.iter().find(|p| p.serial == model.serial()) else {
        return Ok(());
    };
    // SAFETY: live model and its scratch data (left at qpos0 by the statistics); `keep`
    // holds valid dof indices of this structure.
    unsafe {
        mjf_patch_meaninertia(
            model.as_mut_ptr(),
            plan.scratch.0.as_ptr(),
            keep.as_ptr(),
            keep.len() as c_int,
        );
    }
    Ok(())
}

/// The dofs of `model` outside the subtrees of the bodies named in `parked`, in order.
fn kept_dofs(model: &mut CompiledModel, parked: &[String]) -> Result<Vec<c_int>, String> {
    let nbody = model.sizes().nbody;
    let nv = model.sizes().nv;
    let parent = model.body_parentid().to_vec();
    let ints = |model: &mut CompiledModel, name: &str| -> Result<Vec<c_int>, String> {
        let c = CString::new(name).map_err(|e| e.to_string())?;
        let (mut elem, mut count) = (0usize, 0usize);
        // SAFETY: live model; NUL-terminated name.
        let p = unsafe { mjf_patch_array(model.as_mut_ptr(), c.as_ptr(), &mut elem, &mut count) };
        if elem != 4 || p.is_null() {
            return Err(format!("this MuJoCo's mjModel has no int array {name}"));
        }
        // SAFETY: `count` ints at `p`.
        Ok(unsafe { std::slice::from_raw_parts(p.cast::<c_int>(), count) }.to_vec())
    };
    let dofadr = ints(model, "body_dofadr")?;
    let dofnum = ints(model, "body_dofnum")?;
    let mut out_of = vec![false; nbody];
    for root in parked {
        let kind = CString::new("body").map_err(|e| e.to_string())?;
        let name = CString::new(root.as_str()).map_err(|e| e.to_string())?;
        // SAFETY: live model; NUL-terminated strings.
        let id = unsafe { mjf_patch_name2id(model.as_mut_ptr(), kind.as_ptr(), name.as_ptr()) };
        let id = usize::try_from(id).map_err(|_| format!("the superset has no body '{root}'"))?;
        out_of[id] = true;
    }
    // Bodies come after their parents: one pass marks whole subtrees.
    for b in 1..nbody {
        if out_of[parent[b] as usize] {
            out_of[b] = true;
        }
    }
    let mut parked_dof = vec![false; nv];
    for b in (0..nbody).filter(|&b| out_of[b]) {
        let first = usize::try_from(dofadr[b]).unwrap_or(0);
        let n = usize::try_from(dofnum[b]).unwrap_or(0);
        parked_dof[first..first + n].fill(true);
    }
    Ok((0..nv as c_int)
        .filter(|&d| !parked_dof[d as usize])
        .collect())
}

/// Writes one entry's value at its target.
fn write(model: *mut MjModel, t: &Target, value: &PatchValue) -> Result<(), String> {
    match value {
        PatchValue::Id { object, name } => {
            let kind = CString::new(*object).map_err(|e| e.to_string())?;
            let name = CString::new(name.as_str()).map_err(|e| e.to_string())?;
            // SAFETY: the model is live; both strings are NUL-terminated.
            let id = unsafe { mjf_patch_name2id(model, kind.as_ptr(), name.as_ptr()) };
            if id < 0 || !t.int || t.elem != 4 {
                return Err(format!("no {} named '{}'", object, name.to_string_lossy()));
            }
            // SAFETY: `ptr` points at `n` >= 1 ints of the live model (see `resolve`).
            unsafe { t.ptr.cast::<c_int>().write_unaligned(id) };
        }
        PatchValue::Numbers(v) => {
            for k in 0..t.n {
                let x = if v.len() == 1 { v[0] } else { v[k] };
                // SAFETY: `ptr` points at `n` elements of `elem` bytes of the live model,
                // checked against the array's length in `resolve`.
                unsafe {
                    match (t.elem, t.int) {
                        (4, true) => t.ptr.cast::<c_int>().add(k).write_unaligned(x as c_int),
                        (4, false) => t.ptr.cast::<f32>().add(k).write_unaligned(x as f32),
                        _ => t.ptr.cast::<f64>().add(k).write_unaligned(x),
                    }
                }
            }
        }
    }
    Ok(())
}

/// Where every entry lands in `model`.
fn resolve(model: &mut CompiledModel, entries: &[PatchEntry]) -> Result<Vec<Target>, String> {
    let ptr = model.as_mut_ptr();
    let array = |name: &str| -> Result<(*mut u8, usize, usize), String> {
        let c = CString::new(name).map_err(|e| e.to_string())?;
        let (mut elem, mut count) = (0usize, 0usize);
        // SAFETY: the model is live; `c` is NUL-terminated.
        let p = unsafe { mjf_patch_array(ptr, c.as_ptr(), &mut elem, &mut count) };
        if p.is_null() && count > 0 || elem == 0 {
            return Err(format!("this MuJoCo's mjModel has no array {name}"));
        }
        Ok((p.cast(), elem, count))
    };
    let int_at = |name: &str, i: usize| -> Result<usize, String> {
        let (p, elem, count) = array(name)?;
        if elem != 4 || i >= count {
            return Err(format!("{name}[{i}] out of range"));
        }
        // SAFETY: `i` < count ints at `p`.
        let v = unsafe { p.cast::<c_int>().add(i).read_unaligned() };
        usize::try_from(v).map_err(|_| format!("{name}[{i}] is negative"))
    };
    let mut out = Vec::with_capacity(entries.len());
    for e in entries {
        let id = match e.id {
            Some(id) => id,
            None => {
                let kind = CString::new(e.object).map_err(|x| x.to_string())?;
                let name = CString::new(e.name.as_str()).map_err(|x| x.to_string())?;
                // SAFETY: the model is live; both strings are NUL-terminated.
                let id = unsafe { mjf_patch_name2id(ptr, kind.as_ptr(), name.as_ptr()) };
                usize::try_from(id).map_err(|_| {
                    format!(
                        "the patch names {} '{}', which the compiled model does not have",
                        e.object, e.name
                    )
                })?
            }
        };
        let width = match &e.value {
            PatchValue::Numbers(v) => v.len(),
            PatchValue::Id { .. } => 1,
        };
        let (name, offset, n) = match (e.object, e.field) {
            ("joint", f @ ("damping" | "armature" | "frictionloss")) => {
                let dofs = match int_at("jnt_type", id)? {
                    0 => 6,
                    1 => 3,
                    _ => 1,
                };
                (format!("dof_{f}"), int_at("jnt_dofadr", id)?, dofs)
            }
            ("joint", f @ ("qpos0" | "qpos_spring")) => {
                let n = match int_at("jnt_type", id)? {
                    0 => 7,
                    1 => 4,
                    _ => 1,
                };
                (f.to_string(), int_at("jnt_qposadr", id)?, n)
            }
            (object, field) => {
                let prefix = match object {
                    "body" => "body_",
                    "joint" => "jnt_",
                    "geom" => "geom_",
                    "site" => "site_",
                    "camera" => "cam_",
                    "light" => "light_",
                    _ => "mat_",
                };
                (format!("{prefix}{field}"), id * width, width)
            }
        };
        let (p, elem, count) = array(&name)?;
        if offset + n > count {
            return Err(format!(
                "{} '{}': {name}[{offset}..{}] is outside the model's {count}",
                e.object,
                e.name,
                offset + n
            ));
        }
        out.push(Target {
            // SAFETY: in bounds, checked above.
            ptr: unsafe { p.add(offset * elem) },
            elem,
            n,
            int: matches!(e.field, "matid" | "contype" | "conaffinity"),
        });
    }
    Ok(out)
}
