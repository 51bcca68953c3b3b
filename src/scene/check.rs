//! Checking variants with MuJoCo (feature `mujoco`): each compiles, and no placed object
//! interpenetrates another object or a fixture at the initial pose.

use std::path::Path;

use crate::mujoco::{CompiledModel, ObjType, compile_str};

use super::Params;

/// Penetration MuJoCo may report for objects resting exactly on a surface (rounding).
pub const PENETRATION_TOLERANCE: f64 = 1e-6;

/// Compiles `xml` (the text of variant `index`, drawn with `params`; relative file names
/// resolved against `dir`) and checks its placed objects: `Err` with MuJoCo's message, or
/// the first pair of interpenetrating geoms that involves a placed object.
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
) -> Result<CompiledModel, String> {
    let model = compile_str(xml, dir).map_err(|e| format!("variant {index}: {e}"))?;
    check_model(index, params, &model)?;
    Ok(model)
}

/// [`check_variant`] on a model already compiled (or patched by a
/// [`crate::compiled::ModelCache`]) for variant `index`.
///
/// ```
/// use mjcf_forge::compiled::ModelCache;
/// let scene = mjcf_forge::scene::Scene::demo()?;
/// let mut cache = ModelCache::new(&scene, 4, None);
/// let params = scene.variant(2)?.params;
/// mjcf_forge::scene::check_model(2, &params, cache.model(2).unwrap()).unwrap();
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn check_model(index: u64, params: &Params, model: &CompiledModel) -> Result<(), String> {
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
            let label = |g: usize, body: usize| {
                let name = geoms.get(g).filter(|n| !n.is_empty()).cloned();
                format!(
                    "geom {} of '{}'",
                    name.unwrap_or_else(|| format!("#{g}")),
                    bodies[body]
                )
            };
            return Err(format!(
                "variant {index}: {} interpenetrates {} by {:.3} mm at the initial pose",
                label(c.geom1, a),
                label(c.geom2, b),
                -c.dist * 1e3
            ));
        }
    }
    Ok(())
}
