//! One randomizer of a scene file checked: the element and attribute it changes (against
//! MuJoCo's vocabulary), what it selects, and a distribution whose values MuJoCo can read.

use std::path::Path;

use crate::document::vocab::{self, AttrKind};
use crate::error::{Error, ErrorKind};
use crate::scene::randomize::{self, Dist, Randomizer};
use crate::scene::spec;

use super::Source;

/// Checks randomizer number `index` against MuJoCo's vocabulary and what the scene holds
/// (`fixtures`, `groups`), at the scene file's keys.
pub(super) fn load(
    src: &Source<'_>,
    dir: &Path,
    index: usize,
    r: &spec::RandomizerSpec,
    fixtures: &[&str],
    groups: &[&str],
) -> Result<Randomizer, Error> {
    let kind = r.kind.as_ref().as_str();
    let attribute = r.attribute.as_ref().as_str();
    let specs: Vec<&vocab::ElementSpec> = vocab::elements()
        .iter()
        .filter(|e| e.tag == kind && !e.name.starts_with("default"))
        .collect();
    if specs.is_empty() {
        return Err(src.error(&r.kind, format!("MJCF has no element <{kind}>")));
    }
    let attr_on = if kind == "body" && attribute == "mass" {
        "inertial"
    } else {
        kind
    };
    let attr_spec = vocab::elements()
        .iter()
        .filter(|e| e.tag == attr_on && !e.name.starts_with("default"))
        .find_map(|e| e.attrs.iter().find(|a| a.name == attribute));
    let Some(attr_spec) = attr_spec else {
        return Err(src.error(
            &r.attribute,
            format!("<{kind}> has no attribute '{attribute}'"),
        ));
    };
    if matches!(attr_spec.kind, AttrKind::Id(_)) || attribute == "class" {
        return Err(src.error(
            &r.attribute,
            format!("'{attribute}' is a name, which randomizers do not change"),
        ));
    }
    if let Some(p) = &r.part {
        let p = p.as_ref().as_str();
        if p != "base" && !fixtures.contains(&p) && !groups.contains(&p) {
            return Err(src.error(
                r.part.as_ref().expect("checked"),
                format!("no part '{p}': a part is \"base\", a fixture's prefix or an object group's name"),
            ));
        }
    }
    let given = [
        r.uniform.is_some(),
        r.log_uniform.is_some(),
        r.normal.is_some(),
        r.choice.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(src.error(
            &r.attribute,
            "a randomizer needs exactly one of uniform, log_uniform, normal, choice",
        ));
    }
    let numbers = |v: &spec::Values| v.as_slice().to_vec();
    let check = |at: std::ops::Range<usize>, ok: bool, msg: &str| -> Result<(), Error> {
        if ok {
            Ok(())
        } else {
            Err(Error::at(
                src.location(at),
                ErrorKind::Invalid(msg.to_string()),
            ))
        }
    };
    let finite = |v: &[f64]| !v.is_empty() && v.iter().all(|x| x.is_finite());
    let dist = if let Some(u) = &r.uniform {
        let [lo, hi] = u.as_ref();
        let (lo, hi) = (numbers(lo), numbers(hi));
        check(
            u.span(),
            finite(&lo) && finite(&hi) && pairwise(&lo, &hi, |a, b| a <= b),
            "uniform needs [low, high] with low <= high (numbers or lists of one length)",
        )?;
        Dist::Uniform { lo, hi }
    } else if let Some(u) = &r.log_uniform {
        let [lo, hi] = u.as_ref();
        let (lo, hi) = (numbers(lo), numbers(hi));
        check(
            u.span(),
            finite(&lo)
                && finite(&hi)
                && lo.iter().all(|&x| x > 0.0)
                && pairwise(&lo, &hi, |a, b| a <= b),
            "log_uniform needs [low, high] with 0 < low <= high",
        )?;
        Dist::LogUniform { lo, hi }
    } else if let Some(n) = &r.normal {
        let s = n.as_ref();
        let (mean, std, min, max) = (
            numbers(&s.mean),
            numbers(&s.std),
            numbers(&s.min),
            numbers(&s.max),
        );
        check(
            n.span(),
            [&mean, &std, &min, &max].iter().all(|v| finite(v))
                && std.iter().all(|&x| x >= 0.0)
                && pairwise(&min, &max, |a, b| a <= b),
            "normal needs finite mean, std >= 0, and min <= max",
        )?;
        Dist::Normal {
            mean,
            std,
            min,
            max,
        }
    } else {
        let c = r.choice.as_ref().expect("one distribution is given");
        let entries = c.as_ref();
        check(
            c.span(),
            !entries.is_empty()
                && entries
                    .iter()
                    .all(|e| e.weight().is_finite() && e.weight() >= 0.0)
                && entries.iter().any(|e| e.weight() > 0.0),
            "choice needs a non-empty list with weights >= 0, one of them positive",
        )?;
        // Chosen strings are written into the XML as they are: refuse what XML 1.0 cannot
        // carry (a TOML escape such as \e gives one).
        if let Some(bad) = entries
            .iter()
            .find_map(|e| e.value().chars().find(|&ch| !is_xml_char(ch)))
        {
            return Err(Error::at(
                src.location(c.span()),
                ErrorKind::Invalid(format!(
                    "choice holds the character U+{:04X}, which XML cannot carry",
                    bad as u32
                )),
            ));
        }
        let file = matches!(attr_spec.kind, AttrKind::File);
        let values = entries
            .iter()
            .map(|e| {
                if file {
                    dir.join(e.value()).to_string_lossy().into_owned()
                } else {
                    e.value().to_string()
                }
            })
            .collect();
        Dist::Choice {
            values,
            weights: entries.iter().map(|e| e.weight()).collect(),
            prefixed: matches!(attr_spec.kind, AttrKind::Ref(_)),
        }
    };
    let numeric = !matches!(dist, Dist::Choice { .. });
    // A mass or density (or a factor of one) drawn at zero or below is no body MuJoCo
    // simulates: refused when the scene loads, not at the variant that draws it.
    let lowest = match &dist {
        Dist::Uniform { lo, .. } | Dist::LogUniform { lo, .. } => lo.clone(),
        Dist::Normal { min, .. } => min.clone(),
        Dist::Choice { .. } => Vec::new(),
    };
    if matches!(attribute, "mass" | "density") && lowest.iter().any(|&x| x <= 0.0) {
        let what = if r.scale { "factor of a" } else { "" };
        return Err(src.error(
            &r.attribute,
            format!(
                "a {what}{}{attribute} must be drawn above 0: give bounds > 0 (a normal needs min > 0)",
                if r.scale { " " } else { "" }
            ),
        ));
    }
    if r.scale && !numeric {
        return Err(src.error(&r.attribute, "scale needs numbers, not a choice"));
    }
    let unit_to_rad = match &r.unit {
        None => None,
        Some(u) => {
            if randomize::angle_components(kind, attribute).is_none() {
                return Err(src.error(u, format!("'{attribute}' of <{kind}> is not an angle in compiler units (MuJoCo reads it as written); drop the unit")));
            }
            if r.scale {
                return Err(src.error(u, "a scale has no unit"));
            }
            match u.as_ref().as_str() {
                "deg" => Some(std::f64::consts::PI / 180.0),
                "rad" => Some(1.0),
                _ => return Err(src.error(u, "unit must be \"deg\" or \"rad\"")),
            }
        }
    };
    if let Some(c) = &r.components {
        let n = match &dist {
            Dist::Uniform { lo, hi } | Dist::LogUniform { lo, hi } => lo.len().max(hi.len()),
            Dist::Normal {
                mean,
                std,
                min,
                max,
            } => mean.len().max(std.len()).max(min.len()).max(max.len()),
            Dist::Choice { .. } => {
                return Err(src.error(c, "components need numbers, not a choice"));
            }
        };
        if c.as_ref().is_empty() || (n > 1 && n != c.as_ref().len()) {
            return Err(src.error(
                c,
                "give one bound per component listed (or one bound for all)",
            ));
        }
    }
    Ok(Randomizer {
        kind: kind.to_string(),
        attribute: attribute.to_string(),
        name: r.name.as_ref().map(|n| n.as_ref().clone()),
        part: r.part.as_ref().map(|p| p.as_ref().clone()),
        dist,
        scale: r.scale,
        unit_to_rad,
        components: r.components.as_ref().map(|c| c.as_ref().clone()),
        shared: r.shared,
        location: src.location(r.kind.span()),
        index,
        file: matches!(attr_spec.kind, AttrKind::File),
    })
}

/// Whether XML 1.0 allows `c` in text (its `Char` production).
fn is_xml_char(c: char) -> bool {
    matches!(c, '\t' | '\n' | '\r' | '\u{20}'..='\u{D7FF}' | '\u{E000}'..='\u{FFFD}' | '\u{10000}'..)
}

/// Lists of bounds of one length (or a single value), each pair satisfying `ok`.
fn pairwise(a: &[f64], b: &[f64], ok: impl Fn(f64, f64) -> bool) -> bool {
    let n = a.len().max(b.len());
    (a.len() == n || a.len() == 1)
        && (b.len() == n || b.len() == 1)
        && (0..n).all(|i| ok(a[i.min(a.len() - 1)], b[i.min(b.len() - 1)]))
}
