//! robosuite's element sort (`sort_elements` with `_element_filter`) and its naming of
//! unnamed geoms, once: each element of a model's kinematic tree, actuators and sensors
//! under the key of its role. [`XmlModel`](super::XmlModel)'s lists and the Python
//! package's `MujocoXMLModel` (through the extension) both run it, each with its rules
//! ([`SortRules`]) and its reading of a geom's group.
//!
//! Against robosuite 1.5.2's own filter, by MuJoCo's scopes (docs/model-hierarchy.md,
//! robosuite's classes, row 8): bodies, joints, sites and geoms count only as children of
//! `<worldbody>`, `<body>`, `<frame>` or `<replicate>` (a tendon's `<site>`/`<geom>` and an
//! equality's `<joint>` are references, `<default>`'s elements classes); a body is the
//! root body when no body encloses it (frames and replicates do not count); every child of
//! `<sensor>` is a sensor; a geom's group is read as a number (`" 1"` is group 1).

use crate::document::Document;
use crate::document::tree::Node;

/// The keys of the sort, robosuite's names.
///
/// ```
/// use mjcf_forge::sort::SortKey;
/// assert_eq!(SortKey::ContactGeoms.as_str(), "contact_geoms");
/// assert_eq!(SortKey::ALL.len(), 8);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SortKey {
    /// A body no body encloses (only with [`SortRules::root_body`]).
    RootBody,
    /// Every other body.
    Bodies,
    /// Joints (and `<freejoint>`s with [`SortRules::freejoints`]).
    Joints,
    /// The children of `<actuator>`.
    Actuators,
    /// Sites.
    Sites,
    /// The children of `<sensor>`.
    Sensors,
    /// Geoms of group 0 (MuJoCo's default group): collision geoms.
    ContactGeoms,
    /// Geoms of group 1: visual geoms.
    VisualGeoms,
}

impl SortKey {
    /// Every key, in robosuite's order.
    pub const ALL: [SortKey; 8] = [
        SortKey::RootBody,
        SortKey::Bodies,
        SortKey::Joints,
        SortKey::Actuators,
        SortKey::Sites,
        SortKey::Sensors,
        SortKey::ContactGeoms,
        SortKey::VisualGeoms,
    ];

    /// robosuite's name of the key: `root_body`, `bodies`, `joints`, `actuators`, `sites`,
    /// `sensors`, `contact_geoms`, `visual_geoms`.
    pub fn as_str(self) -> &'static str {
        match self {
            SortKey::RootBody => "root_body",
            SortKey::Bodies => "bodies",
            SortKey::Joints => "joints",
            SortKey::Actuators => "actuators",
            SortKey::Sites => "sites",
            SortKey::Sensors => "sensors",
            SortKey::ContactGeoms => "contact_geoms",
            SortKey::VisualGeoms => "visual_geoms",
        }
    }
}

/// What the sort's two clients differ in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SortRules {
    /// Top-level bodies under [`SortKey::RootBody`] (robosuite's keys), else every body
    /// under [`SortKey::Bodies`].
    pub root_body: bool,
    /// `<freejoint>` listed with the joints, as MuJoCo lists its joints (robosuite's
    /// filter does not list it).
    pub freejoints: bool,
}

impl SortRules {
    /// robosuite's keys: a root body, no `<freejoint>` (`mjcf_forge.base`).
    pub const ROBOSUITE: SortRules = SortRules {
        root_body: true,
        freejoints: false,
    };
    /// MuJoCo's lists: every body one list, free joints among the joints
    /// ([`XmlModel`](super::XmlModel)).
    pub const MUJOCO: SortRules = SortRules {
        root_body: false,
        freejoints: true,
    };
}

/// The elements of one key, in document order, with their names (`None`: unnamed).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sorted {
    /// The key.
    pub key: SortKey,
    /// Its elements.
    pub nodes: Vec<Node>,
    /// Their names.
    pub names: Vec<Option<String>>,
}

/// A geom's group as MuJoCo reads the attribute: 0 when absent, else the integer between
/// white space; `None` for anything else (which MuJoCo refuses: such a geom is in no
/// group the sort knows).
///
/// ```
/// use mjcf_forge::sort::geom_group;
/// assert_eq!((geom_group(None), geom_group(Some(" +1 ")), geom_group(Some("x"))), (Some(0), Some(1), None));
/// ```
pub fn geom_group(value: Option<&str>) -> Option<i64> {
    match value {
        None => Some(0),
        Some(v) => v.trim().parse().ok(),
    }
}

/// Where MuJoCo takes a `<body>`, `<geom>`, `<site>` or `<joint>` as part of the tree.
fn in_tree(tag: &str) -> bool {
    matches!(tag, "worldbody" | "body" | "frame" | "replicate")
}

/// The key of `node`, or `None`; `group` reads a geom's `group` attribute.
fn key_of<E>(
    doc: &Document,
    node: Node,
    rules: SortRules,
    group: &mut impl FnMut(Option<&str>) -> Result<Option<i64>, E>,
) -> Result<Option<SortKey>, E> {
    let Some(parent) = doc.parent(node) else {
        return Ok(None);
    };
    match doc.tag(parent) {
        "actuator" => return Ok(Some(SortKey::Actuators)),
        "sensor" => return Ok(Some(SortKey::Sensors)),
        t if in_tree(t) => {}
        _ => return Ok(None),
    }
    Ok(match doc.tag(node) {
        "joint" => Some(SortKey::Joints),
        "freejoint" if rules.freejoints => Some(SortKey::Joints),
        "body" if !rules.root_body => Some(SortKey::Bodies),
        "body" => {
            let mut above = Some(parent);
            while let Some(a) = above.filter(|&a| matches!(doc.tag(a), "frame" | "replicate")) {
                above = doc.parent(a);
            }
            if above.is_some_and(|a| doc.tag(a) == "body") {
                Some(SortKey::Bodies)
            } else {
                Some(SortKey::RootBody)
            }
        }
        "site" => Some(SortKey::Sites),
        "geom" => match group(doc.attr(node, "group"))? {
            Some(0) => Some(SortKey::ContactGeoms),
            Some(1) => Some(SortKey::VisualGeoms),
            _ => None,
        },
        _ => None,
    })
}

/// robosuite's `sort_elements(root)` with the filter above: every element of `doc` under
/// the key of its role, keys in the order they first appear, elements in document order.
/// `group` reads a geom's `group` attribute (`None` when absent) as [`geom_group`] does,
/// or as a face's own language reads a number (its error is returned as it is).
///
/// ```
/// use std::convert::Infallible;
/// use mjcf_forge::Document;
/// use mjcf_forge::sort::{SortKey, SortRules, geom_group, sort_elements};
///
/// let doc = Document::from_str(
///     r#"<mujoco><worldbody><body name="a"><freejoint/><geom size=".1"/>
///        <body name="b"><geom size=".1" group="1"/></body></body></worldbody></mujoco>"#, ".")?;
/// let ok = |v: Option<&str>| Ok::<_, Infallible>(geom_group(v));
/// let keys = |rules| -> Vec<SortKey> {
///     sort_elements(&doc, rules, ok).unwrap().iter().map(|s| s.key).collect()
/// };
/// use SortKey::*;
/// assert_eq!(keys(SortRules::ROBOSUITE), [RootBody, ContactGeoms, Bodies, VisualGeoms]);
/// assert_eq!(keys(SortRules::MUJOCO), [Bodies, Joints, ContactGeoms, VisualGeoms]);
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn sort_elements<E>(
    doc: &Document,
    rules: SortRules,
    group: impl FnMut(Option<&str>) -> Result<Option<i64>, E>,
) -> Result<Vec<Sorted>, E> {
    sort_elements_under(doc, doc.root(), rules, group)
}

/// [`sort_elements`] of the elements under `top` (itself included, keyed by its place in
/// `doc`): robosuite's `sort_elements(top, top's parent)`.
///
/// ```
/// use std::convert::Infallible;
/// use mjcf_forge::{Document, Section};
/// use mjcf_forge::sort::{SortKey, SortRules, geom_group, sort_elements_under};
///
/// let doc = Document::from_str(
///     r#"<mujoco><worldbody><site name="s"/></worldbody><actuator><motor joint="j"/></actuator></mujoco>"#, ".")?;
/// let world = doc.find_section(Section::Worldbody).unwrap();
/// let ok = |v: Option<&str>| Ok::<_, Infallible>(geom_group(v));
/// let sorted = sort_elements_under(&doc, world, SortRules::ROBOSUITE, ok).unwrap();
/// assert_eq!((sorted.len(), sorted[0].key), (1, SortKey::Sites));
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn sort_elements_under<E>(
    doc: &Document,
    top: Node,
    rules: SortRules,
    mut group: impl FnMut(Option<&str>) -> Result<Option<i64>, E>,
) -> Result<Vec<Sorted>, E> {
    let mut slots: [Option<usize>; 8] = [None; 8];
    let mut out: Vec<Sorted> = Vec::new();
    for node in doc.descendants(top) {
        let Some(key) = key_of(doc, node, rules, &mut group)? else {
            continue;
        };
        let slot = *slots[key as usize].get_or_insert_with(|| {
            out.push(Sorted {
                key,
                nodes: Vec::new(),
                names: Vec::new(),
            });
            out.len() - 1
        });
        out[slot].nodes.push(node);
        out[slot]
            .names
            .push(doc.attr(node, "name").map(str::to_owned));
    }
    Ok(out)
}

/// robosuite's naming of unnamed geoms: in document order, an unnamed geom of group 0 is
/// named `g{n}_col` and one of group 1 `g{n}_vis` (`n` counting each group from 0), in
/// `doc` and in `sorted` (what [`sort_elements`] gave for `doc`).
///
/// ```
/// use std::convert::Infallible;
/// use mjcf_forge::Document;
/// use mjcf_forge::sort::{SortRules, geom_group, name_unnamed_geoms, sort_elements};
///
/// let mut doc = Document::from_str(
///     r#"<mujoco><worldbody><body><geom size=".1"/><geom name="c" size=".1"/>
///        <geom size=".1"/></body></worldbody></mujoco>"#, ".")?;
/// let ok = |v: Option<&str>| Ok::<_, Infallible>(geom_group(v));
/// let mut sorted = sort_elements(&doc, SortRules::ROBOSUITE, ok).unwrap();
/// name_unnamed_geoms(&mut doc, &mut sorted);
/// let names: Vec<_> = sorted[1].names.iter().flatten().map(String::as_str).collect();
/// assert_eq!(names, ["g0_col", "c", "g1_col"]);
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub fn name_unnamed_geoms(doc: &mut Document, sorted: &mut [Sorted]) {
    for s in sorted {
        let suffix = match s.key {
            SortKey::ContactGeoms => "col",
            SortKey::VisualGeoms => "vis",
            _ => continue,
        };
        let mut n = 0;
        for (&node, name) in s.nodes.iter().zip(&mut s.names) {
            if name.is_none() {
                let made = format!("g{n}_{suffix}");
                doc.set_attr(node, "name", &made);
                *name = Some(made);
                n += 1;
            }
        }
    }
}
