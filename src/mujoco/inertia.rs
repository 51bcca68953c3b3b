//! Inertias as MuJoCo compiles them, written back into a document: what lets the merge (in
//! the model tier, which calls these) join a part whose compiler settings for masses and
//! inertias differ from the base's, and place a free body exactly where MuJoCo does.

use crate::document::inertia::CompiledInertia;
use crate::document::tree::Node;
use crate::document::{Document, Section};

use super::compile::{CompileError, compile_str};
use super::model::ObjType;

/// Writes an explicit `<inertial>` (mass, pos, quat, diaginertia, at full precision, as
/// MuJoCo compiles `doc` alone) into every body that infers its inertia from its geoms, so
/// that the document compiles to the same masses and inertias whatever the compiler's
/// `inertiagrouprange`: what lets [`Document::merge`](crate::Document::merge) take a part
/// whose range differs from the base's. Returns how many bodies got one.
///
/// Refuses documents whose compiled bodies are not their `<body>` elements one to one
/// (`<replicate>`, `<attach>`, `<composite>`, `<flexcomp>`, `fusestatic`), and documents
/// with `inertiafromgeom="true"` (which ignores `<inertial>`).
///
/// ```
/// use mjcf_forge::Document;
/// use mjcf_forge::mujoco::write_inertials;
///
/// let mut doc = Document::from_str(r#"<mujoco><compiler inertiagrouprange="1 5"/><worldbody>
///   <body name="b"><freejoint/><geom size="0.1" group="1"/><geom size="0.5" group="0"/></body>
///   </worldbody></mujoco>"#, ".")?;
/// assert_eq!(write_inertials(&mut doc)?, 1);
/// assert!(doc.to_xml_string().contains("<inertial "));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_inertials(doc: &mut Document) -> Result<usize, CompileError> {
    write_inertials_of(doc, false)
}

/// Like [`write_inertials`], but for every body whose compiled mass or inertia is not zero or
/// that has geoms or an `<inertial>` of its own (which is replaced): afterwards the compiler's
/// mass settings (`settotalmass`, `boundmass`, `boundinertia`, `balanceinertia`,
/// `inertiafromgeom="false"`) have nothing left to change when left at MuJoCo's defaults, so
/// a part authored with them merges exactly into a base without them.
///
/// ```
/// use mjcf_forge::Document;
/// use mjcf_forge::mujoco::write_all_inertials;
///
/// let mut doc = Document::from_str(r#"<mujoco><compiler settotalmass="3"/><worldbody>
///   <body name="b"><freejoint/><geom size="0.1"/></body></worldbody></mujoco>"#, ".")?;
/// assert_eq!(write_all_inertials(&mut doc)?, 1);
/// assert!(doc.to_xml_string().contains(r#"mass="3.0""#));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_all_inertials(doc: &mut Document) -> Result<usize, CompileError> {
    write_inertials_of(doc, true)
}

/// `qpos0` of the free joint `joint` of `doc` (7 numbers) as MuJoCo compiles `doc` alone:
/// for a free body MuJoCo aligns with its inertial frame, the only exact source. Joints
/// are matched to `doc`'s joint elements in document order, which must be one to one.
pub(crate) fn free_joint_qpos0(doc: &Document, joint: Node) -> Result<[f64; 7], CompileError> {
    let joints: Vec<Node> = doc
        .find_section(Section::Worldbody)
        .map(|w| {
            doc.descendants(w)
                .filter(|&n| matches!(doc.tag(n), "joint" | "freejoint"))
                .collect()
        })
        .unwrap_or_default();
    let model = compile_str(&doc.to_xml_string(), doc.model_dir())?;
    let types = model.jnt_type();
    if types.len() != joints.len() {
        return Err(CompileError::local(format!(
            "MuJoCo compiled {} joints from {} joint elements",
            types.len(),
            joints.len()
        )));
    }
    let k = joints
        .iter()
        .position(|&n| n == joint)
        .ok_or_else(|| CompileError::local("not a joint of the model's bodies".to_string()))?;
    if types[k] != 0 {
        return Err(CompileError::local("not a free joint".to_string()));
    }
    // qpos widths by joint type: free 7, ball 4, slide and hinge 1.
    let at: usize = types[..k]
        .iter()
        .map(|&t| match t {
            0 => 7,
            1 => 4,
            _ => 1,
        })
        .sum();
    let mut q = [0.0; 7];
    q.copy_from_slice(&model.qpos0()[at..at + 7]);
    Ok(q)
}

fn write_inertials_of(doc: &mut Document, all: bool) -> Result<usize, CompileError> {
    write_inertials_checked(doc, all, true)
}

/// `from_geoms_refused`: refuse inertiafromgeom="true", under which the written inertials
/// would be ignored (callers that then make the setting "auto" pass false).
fn write_inertials_checked(
    doc: &mut Document,
    all: bool,
    from_geoms_refused: bool,
) -> Result<usize, CompileError> {
    doc.write_compiled_inertials(all, from_geoms_refused, &mut compiled_inertia)
}

/// The bodies' masses and inertias as MuJoCo compiles `doc` alone: what the merge writes
/// back into a part (through [`Document::write_compiled_inertials`]) in builds with MuJoCo.
pub(crate) fn compiled_inertia(doc: &Document) -> Result<CompiledInertia, CompileError> {
    let model = compile_str(&doc.to_xml_string(), doc.model_dir())?;
    Ok(CompiledInertia {
        body_names: model.names(ObjType::Body),
        mass: model.body_mass().to_vec(),
        ipos: model.body_ipos().to_vec(),
        iquat: model.body_iquat().to_vec(),
        inertia: model.body_inertia().to_vec(),
    })
}
