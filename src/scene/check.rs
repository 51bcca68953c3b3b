//! Checking variants with MuJoCo (feature `mujoco`): each compiles, and no placed object
//! interpenetrates another object or a fixture at the initial pose.

use std::path::Path;

use crate::error::{Error, ErrorKind, Interpenetration};
use crate::mujoco::{CompiledModel, ObjType, compile_str};

use super::Params;

/// Penetration MuJoCo may report for objects resting exactly on a surface (rounding).
pub const PENETRATION_TOLERANCE: f64 = 1e-6;

/// Compiles `xml` (the text of variant `index`, drawn with `params`; relative file names
/// resolved against `dir`) and checks its placed objects: `Err` with MuJoCo's message
/// ([`ErrorKind::CheckCompile`]), or the first pair of interpenetrating geoms that involves
/// a placed object ([`ErrorKind::Interpenetration`]).
///
/// ```
/// let scene = mjcf_forge::scene::Scene::demo()?;
/// let (xml, params) = scene.variant_xml(0)?;
/// mjcf_forge::scene::check_variant(0, &params, &xml, std::path::Path::new(".")).unwrap();
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn check_variant(
    index: u64,
    params: &Params,
    xml: &str,
    dir: &Path,
) -> Result<CompiledModel, Error> {
    let model = compile_str(xml, dir).map_err(|e| {
        Error::bare(ErrorKind::CheckCompile {
            variant: index,
            message: e.message,
        })
    })?;
    check_model(index, params, &model)?;
    Ok(model)
}

/// [`check_variant`] on a model already compiled (or patched by a
/// [`crate::compiled::ModelCache`]) for variant `index`. The first interpenetration found
/// is an [`ErrorKind::Interpenetration`] naming both geoms and their root bodies.
///
/// ```
/// use mjcf_forge::compiled::ModelCache;
/// let scene = mjcf_forge::scene::Scene::demo()?;
/// let mut cache = ModelCache::new(&scene, 4, None);
/// let params = scene.variant(2)?.params;
/// mjcf_forge::scene::check_model(2, &params, cache.model(2).unwrap()).unwrap();
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn check_model(index: u64, params: &Params, model: &CompiledModel) -> Result<(), Error> {
    let bodies = model.names(ObjType::Body);
    let placed: Vec<usize> = params
        .objects
        .iter()
        .filter_map(|o| bodies.iter().position(|b| *b == o.body))
        .collect();
    let root = model.body_rootid();
    let geom_body = model.geom_bodyid();
    let geoms = model.names(ObjType::Geom);
    let owner = |g: usize| root[geom_body[g] as usize] as usize;
    for c in model.initial_contacts() {
        if c.dist >= -PENETRATION_TOLERANCE {
            continue;
        }
        let (a, b) = (owner(c.geom1), owner(c.geom2));
        if placed.contains(&a) || placed.contains(&b) {
            let geom = |g: usize| {
                let name = geoms.get(g).filter(|n| !n.is_empty()).cloned();
                name.unwrap_or_else(|| format!("#{g}"))
            };
            return Err(Error::bare(ErrorKind::Interpenetration(Box::new(
                Interpenetration {
                    variant: index,
                    geoms: [geom(c.geom1), geom(c.geom2)],
                    bodies: [bodies[a].clone(), bodies[b].clone()],
                    depth_mm: format!("{:.3}", -c.dist * 1e3),
                },
            ))));
        }
    }
    Ok(())
}
