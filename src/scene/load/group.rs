//! One object group of a scene file checked and loaded: its pool of models, where its
//! objects go (region, surface, fixture they stand on), how they turn, how many per variant.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use toml::Spanned;

use crate::document::Document;
use crate::document::inertia::InertiaCompiler;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind, Errors};
use crate::model::geometry::{self, Angles, Pose};
use crate::model::instance::name_unnamed_root;
use crate::scene::place::{self, Placement, Rotation};
use crate::scene::spec;
use crate::scene::{Group, PoolModel};

use super::{MAX_COUNT, ModelSource, Source, model_options, root_body};

/// Whether a group's models get MuJoCo's own `<inertial>`s written out when they load.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum WriteInertials {
    /// No (`write_inertials = false`, or nothing asks for it).
    No,
    /// Yes (`write_inertials = true`): a model whose inertials cannot be written is an error.
    Yes,
    /// Where they can be written (a body mass randomizer applies to the group): a model
    /// whose inertials cannot be written keeps its geoms' densities, the slower patch.
    Where,
}

/// Checks and loads group `g` (its models read once, their files recorded in `files`,
/// their inertials written out with `inertias` as `write` says), against the template
/// and the groups before it; every problem at its key.
#[allow(clippy::too_many_arguments)]
pub(super) fn load(
    src: &Source<'_>,
    dir: &Path,
    g: &spec::GroupSpec,
    earlier: &[Group],
    template: &Document,
    angles: &Angles,
    models: &dyn ModelSource,
    mut inertias: Option<&mut InertiaCompiler<'_>>,
    write: WriteInertials,
    files: &mut Vec<PathBuf>,
) -> Result<Group, Errors> {
    let mut errors = Vec::new();
    let name = g.name.as_ref().clone();
    if earlier.iter().any(|e| e.name == name) {
        errors.push(src.error(&g.name, format!("group '{name}' is defined twice")));
    }
    let count = match *g.count.as_ref() {
        spec::Count::Fixed(n) => (n, n),
        spec::Count::Range([a, b]) => (a, b),
    };
    if count.0 > count.1 || count.1 > MAX_COUNT {
        errors.push(src.error(
            &g.count,
            format!("count must be n or [min, max] with min <= max <= {MAX_COUNT}"),
        ));
    } else {
        // All groups together: placement compares every object with the ones before it.
        let before: u64 = earlier.iter().map(|e| u64::from(e.count.1)).sum();
        if before + u64::from(count.1) > u64::from(MAX_COUNT) {
            errors.push(src.error(
                &g.count,
                format!(
                    "the groups would place up to {} objects per variant; at most {MAX_COUNT} \
                     in all",
                    before + u64::from(count.1)
                ),
            ));
        }
    }
    let prefix_pattern = match &g.prefix {
        Some(p) if !p.as_ref().contains("{i}") => {
            errors.push(src.error(
                p,
                "the prefix must contain {i} (the slot index), so that instances differ",
            ));
            String::new()
        }
        Some(p) => p.as_ref().clone(),
        None => format!("{name}{{i}}_"),
    };
    if let Some(e) = earlier.iter().find(|e| e.prefix_pattern == prefix_pattern) {
        let at = g.prefix.as_ref().map_or(g.name.span(), |p| p.span());
        errors.push(Error::at(
            src.location(at),
            ErrorKind::Invalid(format!(
                "group '{}' already uses the prefix '{prefix_pattern}'",
                e.name
            )),
        ));
    }
    if g.pool.as_ref().is_empty() {
        errors.push(src.error(&g.pool, "the pool is empty"));
    }
    let mut pool = Vec::new();
    let mut weights = Vec::new();
    let urdf = g
        .urdf
        .as_ref()
        .map(|t| super::urdf_options(t.as_ref(), dir));
    let mut any_urdf = false;
    for entry in g.pool.as_ref() {
        let w = entry.as_ref().weight();
        if !(w.is_finite() && w >= 0.0) {
            errors.push(src.error(entry, "a weight must be a finite number >= 0"));
        }
        weights.push(w);
        let file = entry.as_ref().model().to_string();
        let at = Spanned::new(entry.span(), file.clone());
        // With the group's `urdf` table, its URDF models are read with those options.
        let loaded = match &urdf {
            Some(options) => match models.load_urdf(dir, &file, options) {
                Ok(Some(x)) => {
                    any_urdf = true;
                    Ok(x)
                }
                Ok(None) => models.load(dir, &file),
                Err(e) => Err(e),
            },
            None => models.load(dir, &file),
        };
        let (mut doc, path) = match loaded {
            Ok(x) => x,
            Err(e) => {
                errors.extend(src.model_errors(&at, e).0);
                continue;
            }
        };
        files.extend(path);
        if write != WriteInertials::No {
            // MuJoCo's own masses and inertias of the file alone, written out: a mass
            // randomizer then scales an <inertial> (a patch) instead of the geoms' densities
            // (which only MuJoCo can turn into masses). Written into a copy, so a model
            // whose inertials cannot be written stays as it was.
            let mut written_doc = doc.clone();
            let written = match inertias.as_deref_mut() {
                Some(compile) => written_doc.write_compiled_inertials(false, true, compile),
                None => Err(crate::Error::bare(crate::ErrorKind::Invalid(
                    "write_inertials needs MuJoCo: load the scene from Python, or \
                     build mjcf-forge with the `mujoco` feature"
                        .to_string(),
                ))),
            };
            match written {
                Ok(_) => doc = written_doc,
                Err(_) if write == WriteInertials::Where => {}
                Err(e) => {
                    errors.push(
                        src.error(&at, format!("cannot write the inertials of '{file}': {e}")),
                    );
                    continue;
                }
            }
        }
        let Some(root) = root_body(&doc) else {
            errors.push(src.error(
                &at,
                format!("'{file}' must have exactly one top-level body to be placed"),
            ));
            continue;
        };
        // The manifest names each object by its root body: an unnamed one is named as a
        // model names it (robosuite's objects wrap a body named "object" in an unnamed one).
        name_unnamed_root(&mut doc, root);
        let has_joint = doc
            .elements(root)
            .any(|k| matches!(doc.tag(k), "joint" | "freejoint"));
        if g.free_joint && !has_joint {
            // Named joint0 as robosuite names an object's first joint, or the first free
            // jointN when the model already uses that name.
            let taken: Vec<&str> = doc
                .descendants(doc.root())
                .filter(|&n| matches!(doc.tag(n), "joint" | "freejoint"))
                .filter_map(|n| doc.attr(n, "name"))
                .collect();
            let name = (0..)
                .map(|k| format!("joint{k}"))
                .find(|n| !taken.contains(&n.as_str()))
                .expect("a free name exists");
            doc.append_element(root, "freejoint", &[("name", &name)]);
        }
        let bounds = match geometry::subtree_bounds(&doc, root, |_, _| true) {
            Ok(b) if b.min.iter().chain(&b.max).all(|x| x.is_finite()) => b,
            Ok(_) => {
                errors.push(src.error(
                    &at,
                    format!("'{file}' has no geometry with a finite extent to place"),
                ));
                continue;
            }
            Err(e) => {
                errors.push(src.error(&at, format!("cannot measure '{file}': {e}")));
                continue;
            }
        };
        pool.push(PoolModel { file, doc, bounds });
    }
    if let Some(table) = g.urdf.as_ref().filter(|_| !any_urdf && errors.is_empty()) {
        errors.push(src.error(
            table,
            format!("urdf options are given for group '{name}', whose pool holds no URDF file"),
        ));
    }
    if !weights.is_empty() && weights.iter().all(|&w| w == 0.0) {
        errors.push(src.error(&g.pool, "at least one weight must be positive"));
    }
    let p = &g.placement;
    let mut frame = Pose::IDENTITY;
    let mut frame_label = String::new();
    if let Some(on) = &p.on {
        let found = template.descendants(template.root()).find(|&n| {
            matches!(template.tag(n), "body" | "site")
                && template.attr(n, "name") == Some(on.as_ref())
        });
        match found {
            Some(n) => match world_pose(template, n, angles) {
                Ok(f) => {
                    frame = f;
                    frame_label = format!(" on '{}'", on.as_ref());
                }
                Err(e) => errors.push(src.error(on, e)),
            },
            None => errors.push(src.error(
                on,
                format!(
                    "no body or site '{}' in the base or the fixtures",
                    on.as_ref()
                ),
            )),
        }
    }
    let on_top_of = match &p.on_top_of {
        None => None,
        Some(t) => match earlier.iter().position(|e| e.name == *t.as_ref()) {
            Some(i) => Some(i),
            None => {
                errors.push(src.error(
                    t,
                    format!("no group '{}' above this one to stack on", t.as_ref()),
                ));
                None
            }
        },
    };
    for (axis, range) in [("x", &p.x), ("y", &p.y)] {
        let [lo, hi] = *range.as_ref();
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            errors.push(src.error(range, format!("{axis} must be [min, max] with min <= max")));
        }
    }
    let rotation = match &p.rotation {
        None => Rotation {
            axis: [0.0, 0.0, 1.0],
            angles: place::Angles::None,
        },
        Some(r) => match rotation(src, &g.name, r) {
            Ok(r) => r,
            Err(e) => {
                errors.push(e);
                Rotation {
                    axis: [0.0, 0.0, 1.0],
                    angles: place::Angles::None,
                }
            }
        },
    };
    if p.max_tries == 0 {
        errors.push(src.error(&g.name, "max_tries must be at least 1"));
    }
    if !errors.is_empty() {
        return Err(Errors(errors));
    }
    // Slot 0 exists even for a group that may place nothing: it is made once at load to
    // check the pool models.
    let slots = count.1.max(1) as usize;
    let instances = (0..slots * pool.len()).map(|_| OnceLock::new()).collect();
    Ok(Group {
        name,
        location: src.location(g.name.span()),
        count,
        prefix_pattern,
        pool,
        weights,
        placement: Placement {
            frame,
            frame_label,
            x: *p.x.as_ref(),
            y: *p.y.as_ref(),
            z: p.z,
            gap: p.gap,
            rotation,
            check_overlap: p.overlap == spec::Overlap::Radius,
            max_tries: p.max_tries,
        },
        on_top_of,
        instances,
        options: model_options(g.collision_rgba, g.name_unnamed_geoms),
    })
}

fn rotation(
    src: &Source<'_>,
    group: &Spanned<String>,
    r: &spec::RotationSpec,
) -> Result<Rotation, Error> {
    let axis = match r.axis.as_ref().map(|a| (a, a.as_ref())) {
        None => [0.0, 0.0, 1.0],
        Some((_, spec::Axis::Named(n))) if n == "x" => [1.0, 0.0, 0.0],
        Some((_, spec::Axis::Named(n))) if n == "y" => [0.0, 1.0, 0.0],
        Some((_, spec::Axis::Named(n))) if n == "z" => [0.0, 0.0, 1.0],
        Some((at, spec::Axis::Vector(v))) => {
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !(n > 0.0 && n.is_finite()) {
                return Err(src.error(at, "the axis must be a non-zero vector"));
            }
            v.map(|x| x / n)
        }
        Some((at, _)) => return Err(src.error(at, "axis must be \"x\", \"y\", \"z\" or [x, y, z]")),
    };
    let given = [
        r.range_deg.is_some(),
        r.range_rad.is_some(),
        r.values_deg.is_some(),
        r.values_rad.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(src.error(
            group,
            "rotation needs exactly one of range_deg, range_rad, values_deg, values_rad",
        ));
    }
    let angles = if let Some([a, b]) = r.range_deg {
        place::Angles::Range(a.to_radians(), b.to_radians())
    } else if let Some([a, b]) = r.range_rad {
        place::Angles::Range(a, b)
    } else if let Some(v) = &r.values_deg {
        place::Angles::Values(v.iter().map(|x| x.to_radians()).collect())
    } else {
        place::Angles::Values(r.values_rad.clone().unwrap_or_default())
    };
    let ok = match &angles {
        place::Angles::Range(a, b) => a.is_finite() && b.is_finite() && a <= b,
        place::Angles::Values(v) => !v.is_empty() && v.iter().all(|x| x.is_finite()),
        place::Angles::None => true,
    };
    if !ok {
        return Err(src.error(group, "rotation angles must be finite, a range [min, max] with min <= max or a non-empty list"));
    }
    Ok(Rotation { axis, angles })
}

/// The pose of a body or site in the world: its pose in its body, composed up the tree.
fn world_pose(doc: &Document, node: Node, angles: &Angles) -> Result<Pose, String> {
    let mut pose = geometry::body_relative_pose(doc, node, angles).map_err(|e| e.to_string())?;
    let mut up = enclosing_body(doc, node);
    while let Some(body) = up {
        pose = geometry::body_relative_pose(doc, body, angles)
            .map_err(|e| e.to_string())?
            .compose(&pose);
        up = enclosing_body(doc, body);
    }
    Ok(pose)
}

/// The body holding `node` (through frames); `None` at the world body.
fn enclosing_body(doc: &Document, node: Node) -> Option<Node> {
    let mut up = doc.parent(node);
    while let Some(p) = up {
        match doc.tag(p) {
            "body" => return Some(p),
            "worldbody" => return None,
            _ => up = doc.parent(p),
        }
    }
    None
}
