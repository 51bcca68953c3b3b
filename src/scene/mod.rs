//! The batch tier: a scene description in, any number of seeded variants out.
//!
//! A [`Scene`] is loaded once: every model file read once, the part that never changes
//! (the base with its fixtures) assembled once into a template, the object pools prefixed
//! lazily per slot and shared read-only by all threads. [`Scene::variant`] then clones the
//! template (a few flat `Vec` copies), draws the objects of each group and places them,
//! applies the randomizers and merges the objects in. Every random number of variant `i`
//! comes from `(seed, i)` alone, so its bytes are the same for any thread count, any shard
//! split and any order.
//!
//! ```
//! use mjcf_forge::scene::Scene;
//! let scene = Scene::demo()?;
//! let a = scene.variant(3)?;
//! let b = scene.variant(3)?;
//! assert_eq!(a.xml(), b.xml());
//! assert!(!a.params.objects.is_empty());
//! // Every placed object is in the XML where the parameters say.
//! let first = &a.params.objects[0];
//! assert!(a.xml().contains(&format!(r#"<body name="{}""#, first.body)));
//! # Ok::<(), mjcf_forge::Errors>(())
//! ```
//!
//! The scene file is TOML; `corpora/scenes/demo/demo.toml` is a commented example and
//! `docs/scenes.md` describes every key.
//!
//! Files: `spec.rs` (the scene file), `load/` (checks, template, instances), `place.rs`,
//! `randomize.rs`, `rng.rs`, `splice.rs` (variants as text), `params.rs` (the manifest),
//! `patch.rs` (a variant's structure key and patch, by the split tier's rules),
//! `superset.rs` (one model for every variant),
//! `check.rs` (MuJoCo validation), `demo.rs` (the built-in scene).
//!
//! May use: the split, model and document tiers, `crate::output` (asset store, ordered
//! pipeline), `crate::error`, and the MuJoCo FFI (`check.rs`, in builds with MuJoCo).
//! Knows nothing of the compiled-model cache or the faces above.

#[cfg(mjcf_mujoco)]
mod check;
mod demo;
mod load;
mod params;
mod patch;
mod place;
mod randomize;
mod rng;
mod spec;
mod splice;
mod superset;

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use rayon::prelude::*;

use crate::document::Document;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind, Errors, Location};
use crate::model::merge::MergePart;

#[cfg(mjcf_mujoco)]
pub use check::{PENETRATION_TOLERANCE, check_model, check_variant};
pub use params::{Params, PlacedObject, RandomizedValue};
pub use patch::VariantPatch;
pub use randomize::MUJOCO_DEFAULTS;
pub use superset::Superset;

use place::Placement;
use randomize::{AttrTarget, Overlay, Randomizer};
use rng::Rng;

/// A loaded scene description, ready to make variants. Cheap to share between threads
/// (`Send + Sync`; everything is read-only after loading except per-slot instances, which
/// are made once on first use).
///
/// ```
/// use mjcf_forge::scene::Scene;
/// use rayon::prelude::*;
/// let scene = Scene::demo()?;
/// assert_eq!(scene.seed(), 7);
/// let variants: Vec<_> = scene.variants(0..4).collect::<Result<_, _>>()?;
/// assert_eq!(variants.len(), 4);
/// assert_eq!(variants[2].index, 2);
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
#[derive(Debug)]
pub struct Scene {
    seed: u64,
    /// The scene file (for messages) and its folder (model paths are relative to it).
    file: Arc<Path>,
    /// Base and fixtures, merged once.
    template: Document,
    /// Per randomizer, the template's elements it sets (node handles stay valid in clones).
    template_targets: Vec<Vec<Target>>,
    groups: Vec<Group>,
    randomizers: Vec<Randomizer>,
    /// Every model file the scene uses, as absolute paths (for exporting its assets).
    model_files: Vec<PathBuf>,
    /// No instance prefix begins another, so names of different instances never clash.
    prefixes_apart: bool,
    /// The template's text with holes and insertion points, when variants can be written
    /// by splicing (see `splice`).
    splice: Option<splice::Template>,
    /// What the scene's settings let a patch carry, and what its structure keys start
    /// from (a hash of the template and every pool model), made on first use.
    structure: OnceLock<(crate::split::Rules, [u8; 32])>,
    /// Variants are written with `<compiler discardvisual="true">`.
    discard_visual: bool,
    /// What the loads of its models warned about, in the scene's order.
    warnings: Vec<crate::error::Warning>,
}

/// One element a randomizer sets, with what the manifest says of it.
#[derive(Clone, Debug)]
pub(crate) struct Target {
    node: Node,
    /// The element's (full) name, if it has one.
    name: Option<String>,
    /// The part it belongs to: `base`, a fixture's prefix, an object group's name.
    part: Arc<str>,
    /// The prefix of that part's names (given to chosen names of objects).
    prefix: Arc<str>,
    /// For a geom that carries its body's mass (a body whose inertia MuJoCo infers from its
    /// geoms): that body. Its geoms' `density` (or `mass`, where written) are scaled by
    /// one factor drawn per body.
    mass_of: Option<Node>,
}

/// A group of objects: its pool, count, prefix pattern and placement.
#[derive(Debug)]
struct Group {
    name: String,
    location: Location,
    count: (u32, u32),
    /// `{i}` replaced by the slot index.
    prefix_pattern: String,
    pool: Vec<PoolModel>,
    weights: Vec<f64>,
    placement: Placement,
    /// Index of the earlier group to stack on.
    on_top_of: Option<usize>,
    /// Per slot and pool model (slot * pool.len() + model), made on first use.
    instances: Vec<OnceLock<Result<Instance, Errors>>>,
    options: crate::model::XmlModelOptions,
}

/// A model of a pool, loaded once, before any prefix.
#[derive(Debug)]
struct PoolModel {
    /// As written in the scene file.
    file: String,
    doc: Document,
    /// Extent in the root body's frame.
    bounds: crate::model::geometry::Bounds,
}

/// A pool model prefixed for one slot of its group.
#[derive(Debug)]
struct Instance {
    doc: Document,
    prefix: String,
    root: Node,
    root_name: String,
    /// Per randomizer that applies to this group, the elements it sets.
    targets: Vec<(usize, Vec<Target>)>,
    /// The instance's text to splice into the template's, when it can be.
    fragments: Option<splice::Fragments>,
}

/// Everything drawn for one variant, before it is written.
pub(crate) struct Drawn<'s> {
    /// Values of the template's randomized attributes.
    template: Overlay<'s>,
    /// Each placed object: its instance and its values (root pose first).
    placed: Vec<(&'s Instance, Overlay<'s>)>,
    /// Each placed object's (group, slot, pool model), in the order of `placed`.
    choices: Vec<(usize, u32, usize)>,
    params: Params,
}

/// One variant: its index, its document, and everything that was drawn for it.
#[derive(Clone, Debug)]
pub struct Variant {
    /// The variant's index.
    pub index: u64,
    /// The scene, ready to write or compile.
    pub document: Document,
    /// What was drawn: the objects and their poses, every randomized value.
    pub params: Params,
}

impl Variant {
    /// The variant as compact XML.
    pub fn xml(&self) -> String {
        self.document.to_xml_string()
    }

    /// The parameters as one line of JSON (the manifest's line, without the file name).
    pub fn params_json(&self) -> String {
        self.params.to_json(self.index, None)
    }
}

impl Scene {
    /// The seed (variant `i` draws from `(seed, i)`).
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The same scene with another seed.
    pub fn with_seed(mut self, seed: u64) -> Scene {
        self.seed = seed;
        self
    }

    /// The scene file (or label) this scene was read from.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// What the loads of the scene's models warned about (each URDF model's inputs that
    /// MuJoCo's importer warns about, see [`Document::warnings`]), base first, then the
    /// fixtures and the groups' pools in the scene file's order. The command line prints
    /// them; the Python package raises each as a `UserWarning`.
    pub fn warnings(&self) -> &[crate::error::Warning] {
        &self.warnings
    }

    /// The template every variant starts from: the base with the fixtures merged in.
    pub fn template(&self) -> &Document {
        &self.template
    }

    /// The model files the scene uses (absolute; empty for the built-in demo).
    pub fn model_files(&self) -> &[PathBuf] {
        &self.model_files
    }

    /// Rewrites every file reference of the scene (template, object models, file choices
    /// of randomizers) to the store's relocatable names, so that variants written into the
    /// store's folder compile wherever the folder goes.
    pub fn relocate_assets(&mut self, store: &crate::output::AssetStore) -> Result<(), Errors> {
        self.template.relocate_assets(store)?;
        for group in &mut self.groups {
            for model in &mut group.pool {
                model.doc.relocate_assets(store)?;
            }
            // Instances made before were made from the models as they were.
            for slot in &mut group.instances {
                *slot = OnceLock::new();
            }
        }
        for r in &mut self.randomizers {
            r.relocate_files(store)?;
        }
        Ok(())
    }

    /// Variant `index`: the same document and parameters for the same seed and index,
    /// whatever else was made before, on whatever thread.
    pub fn variant(&self, index: u64) -> Result<Variant, Errors> {
        let drawn = self.draw(index)?;
        let mut doc = self.template.clone();
        drawn.template.apply_to(&mut doc);
        let parts: Vec<(Document, &str)> = drawn
            .placed
            .iter()
            .map(|(inst, overlay)| {
                let mut part = inst.doc.clone();
                place::clear_orientation(&mut part, inst.root);
                overlay.apply_to(&mut part);
                (part, inst.prefix.as_str())
            })
            .collect();
        if !parts.is_empty() {
            let merge: Vec<MergePart<'_>> = parts
                .iter()
                .map(|(doc, prefix)| MergePart {
                    doc,
                    into: None,
                    prefix,
                })
                .collect();
            // Each instance was checked against the template when it was made; instances
            // cannot clash with each other when no prefix begins another.
            if !self.prefixes_apart {
                let docs: Vec<&Document> = parts.iter().map(|(d, _)| d).collect();
                let clashes = doc.name_clashes(&docs);
                if !clashes.is_empty() {
                    return Err(Errors(clashes));
                }
            }
            doc.merge_unchecked(&merge, false)?;
        }
        if self.discard_visual {
            doc.set_discard_visual();
        }
        Ok(Variant {
            index,
            document: doc,
            params: drawn.params,
        })
    }

    /// Variant `index` as compact XML with its parameters: the same bytes as
    /// `variant(index)?.xml()`, made without building the document where the scene
    /// allows (the template's text is copied with the variant's values and objects
    /// spliced in; see `splice`).
    ///
    /// ```
    /// let scene = mjcf_forge::scene::Scene::demo()?;
    /// let (xml, params) = scene.variant_xml(5)?;
    /// let v = scene.variant(5)?;
    /// assert_eq!(xml, v.xml());
    /// assert_eq!(params, v.params);
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn variant_xml(&self, index: u64) -> Result<(String, Params), Errors> {
        let mut xml = String::new();
        let params = self.variant_xml_into(index, &mut xml)?;
        Ok((xml, params))
    }

    /// [`Scene::variant_xml`] into `out` (cleared first), whose memory is reused: a batch
    /// that keeps its buffers does not allocate a new text per variant.
    ///
    /// ```
    /// let scene = mjcf_forge::scene::Scene::demo()?;
    /// let mut xml = String::new();
    /// let params = scene.variant_xml_into(3, &mut xml)?;
    /// assert_eq!((xml, params), scene.variant_xml(3)?);
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn variant_xml_into(&self, index: u64, out: &mut String) -> Result<Params, Errors> {
        out.clear();
        self.variant_xml_append(index, out)
    }

    /// [`Scene::variant_xml`] appended to `out` (what it holds stays): for writing a
    /// variant straight into a larger buffer, such as its tar member after the header.
    ///
    /// ```
    /// let scene = mjcf_forge::scene::Scene::demo()?;
    /// let mut out = String::from("<!-- 3 -->");
    /// let params = scene.variant_xml_append(3, &mut out)?;
    /// assert_eq!(out, format!("<!-- 3 -->{}", scene.variant_xml(3)?.0));
    /// assert_eq!(params, scene.variant_xml(3)?.1);
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn variant_xml_append(&self, index: u64, out: &mut String) -> Result<Params, Errors> {
        // Splicing checks no names: only where instances cannot clash (see `variant`).
        if let Some(splice) = self.splice.as_ref().filter(|_| self.prefixes_apart) {
            let drawn = self.draw(index)?;
            if splice.write(&drawn, out) {
                return Ok(drawn.params);
            }
        }
        let v = self.variant(index)?;
        out.push_str(&v.xml());
        Ok(v.params)
    }

    /// Makes variants `range` as XML in parallel (on the current rayon pool) and hands each
    /// to `sink` in index order, with [`crate::output::for_each_ordered`]: at most `ring`
    /// variants are made and not yet handed over, so memory stays bounded however long
    /// the range, and each variant's text is written into a reused buffer. `sink` runs on
    /// the workers, one at a time. A variant that fails is handed over as its error;
    /// `sink` stops everything by returning an error.
    ///
    /// `sink` drops on one worker the [`Params`] another one made. glibc's malloc takes a
    /// lock for such frees, and on two threads that can cost more than the second thread
    /// gains: a program that streams many variants should use an allocator that frees
    /// across threads without one, such as mimalloc, which the command line and the Python
    /// module use.
    ///
    /// ```
    /// let scene = mjcf_forge::scene::Scene::demo()?;
    /// let mut seen = Vec::new();
    /// scene.stream(10..20, 4, |i, made| {
    ///     let (xml, _params) = made?;
    ///     seen.push((i, xml.len()));
    ///     Ok::<(), mjcf_forge::Errors>(())
    /// })?;
    /// assert_eq!(seen.iter().map(|s| s.0).collect::<Vec<_>>(), (10..20).collect::<Vec<_>>());
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn stream<E: Send>(
        &self,
        range: Range<u64>,
        ring: usize,
        mut sink: impl FnMut(u64, Result<(&str, Params), Errors>) -> Result<(), E> + Send,
    ) -> Result<(), E> {
        crate::output::for_each_ordered(
            range,
            ring,
            |i, xml: &mut String| self.variant_xml_into(i, xml),
            |i, xml, made| sink(i, made.map(|params| (xml.as_str(), params))),
        )
    }

    /// Writes variants `range` to `out` as a tar stream in the layout of `generate -o -`
    /// (the variants' XML with file references as the scene has them: absolute unless
    /// [`Scene::relocate_assets`] was called, whose store then writes the `assets/`
    /// members first with [`crate::AssetStore::write_to_tar`]).
    ///
    /// ```
    /// let scene = mjcf_forge::scene::Scene::demo()?;
    /// let mut tar = mjcf_forge::TarWriter::new(Vec::new(), "memory");
    /// scene.write_tar(0..3, &mut tar)?;
    /// let bytes = tar.finish()?;
    /// assert!(bytes.len() > 3 * 2 * 512);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn write_tar<W: std::io::Write + Send>(
        &self,
        range: Range<u64>,
        tar: &mut crate::output::TarWriter<W>,
    ) -> Result<(), Errors> {
        /// A variant's two members, written on the worker that made it (so its `Params`
        /// are dropped there too, see [`Scene::stream`]).
        #[derive(Default)]
        struct Members {
            xml: String,
            json: String,
        }
        crate::output::for_each_ordered(
            range,
            128,
            |i, m: &mut Members| -> Result<(), Errors> {
                let params = self.variant_xml_into(i, &mut m.xml)?;
                m.json.clear();
                params.write_json(i, Some(&format!("{i:09}.xml")), &mut m.json);
                Ok(())
            },
            |i, m, made| {
                made?;
                tar.append(&format!("{i:09}.xml"), m.xml.as_bytes())?;
                tar.append(&format!("{i:09}.json"), m.json.as_bytes())?;
                Ok(())
            },
        )
    }

    /// Whether [`Scene::variant_xml`] writes by splicing text (rather than building each
    /// variant's document) for every object instance made so far.
    pub fn splices(&self) -> bool {
        self.splice.is_some()
            && self.groups.iter().all(|g| {
                g.instances
                    .iter()
                    .filter_map(OnceLock::get)
                    .all(|i| i.as_ref().is_ok_and(|i| i.fragments.is_some()))
            })
    }

    /// Everything drawn for variant `index`: the template's values, each placed
    /// instance with its values (pose included), and the parameters.
    fn draw(&self, index: u64) -> Result<Drawn<'_>, Errors> {
        let mut params = Params::default();
        let mut draws = randomize::Draws::new(self.seed, index, self.randomizers.len());
        let mut template = Overlay::new(&self.template);
        for (k, targets) in self.template_targets.iter().enumerate() {
            self.randomizers[k].apply(&mut template, targets, &mut draws, &mut params)?;
        }
        let mut rng = Rng::new(self.seed, index, 0);
        let mut placed: Vec<place::Placed> = Vec::new();
        let mut instances: Vec<(&Instance, Overlay<'_>)> = Vec::new();
        let mut group_members: Vec<Vec<usize>> = Vec::with_capacity(self.groups.len());
        let mut choices = Vec::new();
        for (gi, group) in self.groups.iter().enumerate() {
            let count = rng.int_in(u64::from(group.count.0), u64::from(group.count.1)) as u32;
            let mut members = Vec::with_capacity(count as usize);
            for slot in 0..count {
                let m = rng.weighted(&group.weights);
                let inst = self.instance(group, slot, m)?;
                let support = group.on_top_of.map(|g| &group_members[g]);
                let pose = group
                    .placement
                    .sample(
                        &mut rng,
                        &group.pool[m].bounds,
                        &placed,
                        support.map(|s| s.as_slice()),
                    )
                    .map_err(|why| {
                        Error::at(
                            group.location.clone(),
                            ErrorKind::Invalid(format!(
                                "variant {index}: group '{}': no place for object {slot} ({}) {why}",
                                group.name, group.pool[m].file
                            )),
                        )
                    })?;
                let mut overlay = Overlay::new(&inst.doc);
                let (pos, quat) = place::pose_text(&pose.pose);
                overlay.set(inst.root, "pos", pos.clone());
                overlay.set(inst.root, "quat", quat.clone());
                for (k, targets) in &inst.targets {
                    self.randomizers[*k].apply(&mut overlay, targets, &mut draws, &mut params)?;
                }
                params.objects.push(PlacedObject {
                    group: group.name.clone(),
                    slot,
                    model: group.pool[m].file.clone(),
                    prefix: inst.prefix.clone(),
                    body: inst.root_name.clone(),
                    pos,
                    quat,
                });
                members.push(placed.len());
                placed.push(pose);
                instances.push((inst, overlay));
                choices.push((gi, slot, m));
            }
            group_members.push(members);
        }
        Ok(Drawn {
            template,
            placed: instances,
            choices,
            params,
        })
    }

    /// Variant `index` as a structure key and a patch: variants with the same key compile
    /// to models that differ only in the patch's values (and what MuJoCo's `mj_setConst`
    /// derives from them), so one compiled model of the structure, patched, is exactly
    /// the variant's. What cannot be patched exactly (an attribute without a rule in
    /// [`PATCHABLE`], an unnamed element) is part of the key.
    ///
    /// ```
    /// let scene = mjcf_forge::scene::Scene::demo()?;
    /// let p = scene.patch(3)?;
    /// assert_eq!(p.structure_key.len(), 32);
    /// // Placed objects' free joints are patched: their qpos0 is where they were placed.
    /// assert!(p.entries.iter().any(|e| e.object == "joint" && e.field == "qpos0"));
    /// assert_eq!(scene.patch(3)?, p);
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn patch(&self, index: u64) -> Result<VariantPatch, Errors> {
        let drawn = self.draw(index)?;
        let (rules, fingerprint) = self.structure();
        Ok(patch::split(fingerprint, rules, index, &drawn))
    }

    /// What the scene's settings let a patch carry, and the hash structure keys start
    /// from; made on first use.
    fn structure(&self) -> &(crate::split::Rules, [u8; 32]) {
        self.structure.get_or_init(|| {
            let parts: Vec<&Document> = self
                .groups
                .iter()
                .flat_map(|g| g.pool.iter().map(|m| &m.doc))
                .collect();
            let mut h = blake3::Hasher::new();
            for d in std::iter::once(&self.template).chain(parts.iter().copied()) {
                let text = d.to_xml_string();
                h.update(&(text.len() as u64).to_le_bytes());
                h.update(text.as_bytes());
            }
            (
                crate::split::Rules::new(&self.template, &parts, self.discard_visual),
                *h.finalize().as_bytes(),
            )
        })
    }

    /// The `<statistic>` values the scene's model sets itself (`extent`, `center`...):
    /// MuJoCo keeps them over what it computes, so a patched model must too.
    ///
    /// ```
    /// let scene = mjcf_forge::scene::Scene::demo()?;
    /// assert!(scene.fixed_statistics().is_empty());
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn fixed_statistics(&self) -> Vec<&'static str> {
        crate::split::fixed_statistics(&self.template)
    }

    /// Variants `range`, made in parallel (rayon), in index order.
    pub fn variants(
        &self,
        range: Range<u64>,
    ) -> impl IndexedParallelIterator<Item = Result<Variant, Errors>> + '_ {
        // rayon indexes ranges of usize; variant indices beyond it are not a concern on
        // the 64-bit targets this runs on.
        (range.start as usize..range.end as usize)
            .into_par_iter()
            .map(move |i| self.variant(i as u64))
    }

    /// Pool model `m` of `group` prefixed for `slot`, made on first use and kept.
    fn instance<'s>(
        &'s self,
        group: &'s Group,
        slot: u32,
        m: usize,
    ) -> Result<&'s Instance, Errors> {
        let at = slot as usize * group.pool.len() + m;
        group.instances[at]
            .get_or_init(|| load::make_instance(self, group, slot, m))
            .as_ref()
            .map_err(Clone::clone)
    }
}
