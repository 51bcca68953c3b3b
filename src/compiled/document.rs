//! Compiled models of any documents at patch cost: a [`DocumentCache`] splits each document
//! it is given into a structure key and a patch
//! ([`split_document`](crate::split::split_document)), compiles a structure the first time
//! it sees it, and from then on writes the patch into that model (then `mj_setConst` and
//! the compiler's statistics, as [`super::ModelCache`] does): the model MuJoCo compiles
//! from the document, every array bit for bit (`tests/document_cache.rs`).

use std::path::Path;

use super::internal;
use super::store::{Linked, Plan, cache_error};
use crate::document::Document;
use crate::error::Errors;
use crate::mujoco::{CompiledModel, compile_document};
use crate::split::{
    CacheBackend, Compiled, DiskStore, DocumentBackend, DocumentCore, Held, PatchFailure, Request,
    SplitOptions, Statistics, Step, StoreKey, fixed_statistics_mask, load_or_compile,
    split_document_with,
};

/// The linked MuJoCo as the split tier's document cache runs it ([`DocumentBackend`]):
/// each model with its [`Plan`], patched as the model cache patches its models. The cache
/// lends its models (`&CompiledModel`), so no caller holds or changes one: nothing is
/// written back before a patch, and no model is ever held (the pools keep one model).
struct LinkedDocs(Linked);

/// One model of a structure and its plan.
struct Working {
    model: CompiledModel,
    plan: Plan,
}

impl Held for Working {
    fn nbytes(&self) -> usize {
        self.plan.nbytes()
    }
}

/// A structure's snapshot on this face: the statistics as compiled (what the document
/// fixes is kept at these values).
struct AsCompiled(Statistics);

impl Held for AsCompiled {
    fn nbytes(&self) -> usize {
        0
    }
}

impl DocumentBackend for LinkedDocs {
    type Model = CompiledModel;
    type Working = Working;
    type Snapshot = AsCompiled;
    type Error = Errors;

    fn id(model: &CompiledModel) -> u64 {
        model.serial()
    }

    fn model(working: &Working) -> &CompiledModel {
        &working.model
    }

    fn snapshot(&mut self, model: &CompiledModel) -> Result<AsCompiled, Errors> {
        Ok(AsCompiled(self.0.stat(model)))
    }

    fn working(
        &mut self,
        mut model: CompiledModel,
        snapshot: &AsCompiled,
        request: &Request<'_>,
    ) -> Result<Working, (CompiledModel, PatchFailure<Errors>)> {
        let plan = self.0.plan(&model, request.key, request.fixed, snapshot.0);
        let mut plan = match plan {
            Ok(plan) => plan,
            Err(e) => return Err((model, PatchFailure::Backend(e))),
        };
        if let Err(e) = plan.resolve(&mut model, request.entries) {
            return Err((model, PatchFailure::NotThisStructure(e.to_string())));
        }
        Ok(Working { model, plan })
    }

    fn held(&self, _working: &Working) -> bool {
        false
    }

    fn copy(&mut self, working: &Working) -> Result<CompiledModel, Errors> {
        Ok(working.model.clone())
    }

    fn patch(
        &mut self,
        working: &mut Working,
        _snapshot: &AsCompiled,
        request: &Request<'_>,
    ) -> Result<(), PatchFailure<Errors>> {
        let Working { model, plan } = working;
        self.0.patch(plan, model, request, 0)
    }
}

/// Compiled models of documents, one per structure, patched per document; bounded in
/// count and bytes (models and their scratch data), least recently used out.
///
/// [`DocumentCache::model`] returns a model equal to MuJoCo compiling the document,
/// compiling only when no model of its structure is cached. The model is borrowed from
/// the cache: it cannot be changed through the reference, and the next call for the same
/// structure patches it again; `clone()` it (`mj_copyModel`) to keep or edit one.
///
/// MuJoCo reads each mesh and texture file once per process whatever the cache does: its
/// own asset cache (500 MB by default) keeps them decoded by file name and modification
/// time, so a compile after the first only checks the files' times.
///
/// ```
/// use mjcf_forge::Document;
/// use mjcf_forge::compiled::DocumentCache;
///
/// let xml = |rgba: &str, mass: &str| {
///     format!(
///         "<mujoco><worldbody><body name='box' pos='0 0 1'><freejoint/>\
///          <geom name='g' type='box' size='.1 .1 .1' rgba='{rgba}' mass='{mass}'/>\
///          </body></worldbody></mujoco>"
///     )
/// };
/// let mut cache = DocumentCache::new(8, None);
/// let red = Document::from_str(&xml("1 0 0 1", "1"), ".")?;
/// assert_eq!(cache.model(&red)?.sizes().ngeom, 1); // compiled
/// let blue = Document::from_str(&xml("0 0 1 1", "1"), ".")?;
/// cache.model(&blue)?; // the same structure: patched
/// let heavy = Document::from_str(&xml("0 0 1 1", "2"), ".")?;
/// cache.model(&heavy)?; // a geom's mass is structure: compiled
/// assert_eq!((cache.compiles(), cache.patches()), (2, 1));
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub struct DocumentCache {
    core: DocumentCore<LinkedDocs>,
    backend: LinkedDocs,
    /// The last compile that the cache could not keep (its structure's layout refused).
    alone: Option<CompiledModel>,
    store: Option<DiskStore>,
}

impl DocumentCache {
    /// A cache holding at most `max_models` compiled models (at least one) and, when
    /// given, about `max_bytes` of models and scratch data.
    pub fn new(max_models: usize, max_bytes: Option<usize>) -> DocumentCache {
        DocumentCache {
            core: DocumentCore::new(max_models, max_bytes),
            backend: LinkedDocs(Linked::default()),
            alone: None,
            store: None,
        }
    }

    /// `doc` as MuJoCo compiles it: the cached model of its structure patched, or on a
    /// miss the document compiled (and kept). MuJoCo's error, when it refuses the
    /// document, is at the element it names in the document's sources
    /// ([`Document::mujoco_error`]); the cache is then as it was.
    pub fn model(&mut self, doc: &Document) -> Result<&CompiledModel, Errors> {
        let split = split_document_with(doc, SplitOptions { body_models: true });
        let request = Request {
            key: &split.structure_key,
            entries: &split.entries,
            parked: None,
            fixed: fixed_statistics_mask(split.fixed_statistics.iter().copied()),
        };
        let key = &split.structure_key;
        // At most three rounds: a miss, a stored model patched, a refused one compiled.
        let mut use_store = true;
        for _ in 0..3 {
            let step = self.core.model(&mut self.backend, &request, &[]);
            let replace = match step.map_err(|e| cache_error(e, 0, key))? {
                Step::Ready => return self.given(key),
                Step::Compile { replace } => replace,
                // This cache is `&mut`: no other call compiles meanwhile.
                Step::Wait => return Err(internal(format!("structure {key} is being compiled"))),
            };
            // A failed patch compiles the document itself: the store's model is what failed.
            let store = self
                .store
                .as_ref()
                .filter(|_| use_store && !replace)
                .map(|s| {
                    (
                        s,
                        StoreKey::of_document(key, &crate::mujoco::version(), doc),
                    )
                });
            let loaded = load_or_compile(
                store.as_ref().map(|(s, k)| (*s, k.as_str())),
                CompiledModel::from_bytes,
                |m: &CompiledModel| Some(m.to_bytes()),
                || compile_document(doc).map_err(|e| Errors(vec![e])),
                &mut |w| eprintln!("mjcf-forge: {w}"),
            );
            let (model, stored) = match loaded {
                Ok((m, stored)) => (Ok(m), stored),
                Err(e) => (Err(e), false),
            };
            let kept = self
                .core
                .compiled(&mut self.backend, &request, model, replace, stored)
                .map_err(|e| cache_error(e, 0, key))?;
            match kept {
                Compiled::Kept => return self.given(key),
                Compiled::Alone(alone) => return Ok(self.alone.insert(alone)),
                Compiled::Stored => {}
                Compiled::Refused => use_store = false,
            }
        }
        Err(internal(format!(
            "structure {key}: no model after three rounds"
        )))
    }

    /// The same cache, keeping the structures it compiles in `store` across processes
    /// ([`DiskStore`]): a structure another process compiled with this MuJoCo and these
    /// files is a load and a patch here. A store that fails is reported on standard error
    /// and the cache compiles as without it.
    pub fn with_store(mut self, store: DiskStore) -> DocumentCache {
        self.store = Some(store);
        self
    }

    /// Misses so far that were loads from the store (of [`DocumentCache::compiles`]).
    pub fn loads(&self) -> u64 {
        self.core.loads()
    }

    fn given(&self, key: &str) -> Result<&CompiledModel, Errors> {
        self.core
            .given()
            .ok_or_else(|| internal(format!("structure {key} has no model")))
    }

    /// The MJCF text `xml` as MuJoCo compiles it, relative file names resolved against
    /// `dir` (read as [`Document::from_str`] reads it; its errors are ours, with their
    /// positions, when it cannot be read).
    pub fn model_xml(
        &mut self,
        xml: &str,
        dir: impl AsRef<Path>,
    ) -> Result<&CompiledModel, Errors> {
        let doc = Document::from_str(xml, dir)?;
        self.model(&doc)
    }

    /// Misses so far: models compiled, or loaded from the store.
    pub fn compiles(&self) -> u64 {
        self.core.compiles()
    }

    /// Patches applied so far (hits).
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

    /// Bytes held: the cached models and their scratch data.
    pub fn nbytes(&self) -> usize {
        self.core.nbytes()
    }
}
