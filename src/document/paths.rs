//! File references made absolute, as MuJoCo resolves them.
//!
//! MuJoCo's rule (XMLreference, compiler/meshdir): with `strippath` the directory part of
//! the file name is dropped first (not for `<model file>`, which MuJoCo never strips);
//! then (1) an absolute file name is used as is; (2) else, if the asset folder (`meshdir`
//! for meshes, height fields, skins and flexcomp files; `texturedir` for textures; both
//! default to `assetdir`; none for `<model file>`) is absolute, folder + name; (3) else
//! main-file folder + folder + name. `<compiler>` elements are read in order, each
//! overriding the last.
//!
//! An element that came from an included file has a second place, found by experiment
//! with MuJoCo 3.17.0 and 4.0.0 (the same in both, the main file named by an absolute
//! path): when a relative name is not found "beside the main file", it is read beside the
//! included file instead (that file's folder + name, no asset folder), and then
//! `strippath` still applies to the whole. What "beside the main file" means differs by
//! element, and is not always where the file is then read ([`main_side_probe`]).
//!
//! After this pass every file attribute is absolute and `strippath` is switched off, so
//! the document compiles to the same model from any folder.

use std::path::{Component, Path, PathBuf};

use crate::document::Document;
use crate::document::names::{Sym, sym};
use crate::document::schema::Kind;
use crate::document::tree::{Node, Tree};
use crate::document::vocab::AttrKind;
use crate::error::Errors;

#[derive(Default)]
struct Dirs {
    asset: Option<String>,
    mesh: Option<String>,
    texture: Option<String>,
    strip: bool,
}

/// Makes every file reference of the document absolute.
pub(crate) fn absolutize_paths(doc: &mut Document) -> Result<(), Errors> {
    let root = doc.root;
    let mut dirs = Dirs::default();
    let compiler = Some(sym("compiler"));
    let compilers: Vec<Node> = doc
        .elements(root)
        .filter(|&n| doc.tag_sym(n) == compiler)
        .collect();
    for &c in &compilers {
        if let Some(a) = doc.attr(c, "assetdir") {
            dirs.asset = Some(a.to_string());
            dirs.mesh = Some(a.to_string());
            dirs.texture = Some(a.to_string());
        }
        if let Some(m) = doc.attr(c, "meshdir") {
            dirs.mesh = Some(m.to_string());
        }
        if let Some(t) = doc.attr(c, "texturedir") {
            dirs.texture = Some(t.to_string());
        }
        if let Some(s) = doc.attr(c, "strippath") {
            dirs.strip = s.trim() == "true";
        }
    }
    let model_dir = doc.model_dir.clone();
    let mut found = Found::default();
    // Depth first in document order from an explicit stack (no recursion on input depth).
    let mut stack = vec![(root, Kind::root())];
    while let Some((node, kind)) = stack.pop() {
        collect(doc, node, kind, &dirs, &model_dir, &mut found);
        let at = stack.len();
        for kid in doc.children(node) {
            if let Some(kkind) = doc.tag_sym(kid).and_then(|t| kind.child(t)) {
                // Sections like <sensor> or <actuator> cannot hold a file reference.
                if kkind.reaches_file_attrs() {
                    stack.push((kid, kkind));
                }
            }
        }
        stack[at..].reverse();
    }
    for &(node, name, start, end) in &found.edits {
        let value = doc.push_str(&found.text[start as usize..end as usize]);
        doc.set_attr_ref(node, name, value);
    }
    if dirs.strip {
        // The names are absolute now; stripping them again would undo that.
        for &c in &compilers {
            doc.remove_attr(c, "strippath");
        }
    }
    Ok(())
}

/// The new values `collect` finds, in one buffer (no allocation per file reference).
#[derive(Default)]
struct Found {
    /// (element, attribute, value range in `text`).
    edits: Vec<(Node, Sym, u32, u32)>,
    text: String,
    /// Reused for resolving each reference.
    path: PathBuf,
}

fn collect(
    doc: &Document,
    node: Node,
    kind: Kind,
    dirs: &Dirs,
    model_dir: &Path,
    found: &mut Found,
) {
    if !kind.has_file_attrs() {
        return;
    }
    let tag = kind.spec().tag;
    let source = &doc.files[doc.spans[Tree::index(node)].file as usize];
    for a in doc.attr_slice(node) {
        if kind
            .attr(a.name)
            .is_none_or(|spec| spec.kind != AttrKind::File)
        {
            continue;
        }
        let value = doc.str(a.value);
        let folder = match tag {
            "texture" => dirs.texture.as_deref(),
            "mesh" | "hfield" | "skin" | "flexcomp" => dirs.mesh.as_deref(),
            _ => None,
        };
        let strip = dirs.strip && tag != "model";
        let beside_include = source.included_at.is_some()
            && !strip
            && Path::new(value).is_relative()
            && std::fs::metadata(main_side_probe(tag, value, dirs, model_dir)).is_err();
        if beside_include {
            found.path = join_by_name(&source.dir, value);
        } else {
            resolve_into(&mut found.path, value, folder, strip, model_dir);
        }
        if found.path.as_os_str() != value {
            let start = found.text.len() as u32;
            match found.path.to_str() {
                Some(s) => found.text.push_str(s),
                None => found.text.push_str(&found.path.to_string_lossy()),
            }
            found
                .edits
                .push((node, a.name, start, found.text.len() as u32));
        }
    }
}

/// Where MuJoCo looks to decide whether a relative file named in an included file is
/// beside the main file (else it reads it beside the included file): the mesh or texture
/// folder for meshes and textures, where they are then read; `assetdir` for height
/// fields and skins, and the main file's folder for flexcomp files, although both are
/// then read from `meshdir`; for `<model file>`, the name as it stands, which the
/// operating system takes from the working directory (of this process, as MuJoCo run
/// here would). 3.17.0 and 4.0.0 agree on each (experiments in `docs/fidelity.md`).
fn main_side_probe(tag: &str, file: &str, dirs: &Dirs, model_dir: &Path) -> PathBuf {
    let folder = match tag {
        "mesh" => dirs.mesh.as_deref(),
        "texture" => dirs.texture.as_deref(),
        "hfield" | "skin" => dirs.asset.as_deref(),
        "model" => return join_by_name(Path::new(""), file),
        _ => None,
    };
    let mut probe = PathBuf::new();
    resolve_into(&mut probe, file, folder, false, model_dir);
    by_name(&probe)
}

/// `base` joined with `file` (an absolute `file` stands alone), `.` and `..` resolved by
/// name: MuJoCo does so before the file system sees a path, so a `..` after a folder that
/// is a symbolic link leads back to the link's parent, not to the target's.
pub(crate) fn join_by_name(base: &Path, file: &str) -> PathBuf {
    by_name(&base.join(file))
}

/// `path` with `.` and `..` resolved by name (see [`join_by_name`]).
fn by_name(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => match out.components().next_back() {
                Some(Component::Normal(_)) => {
                    out.pop();
                }
                // Above the root is the root.
                Some(Component::RootDir | Component::Prefix(_)) => {}
                _ => out.push(".."),
            },
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
fn resolve(file: &str, folder: Option<&str>, strip: bool, model_dir: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    resolve_into(&mut out, file, folder, strip, model_dir);
    out
}

/// The absolute path of `file` into `out` (cleared first; reused across references).
fn resolve_into(
    out: &mut PathBuf,
    file: &str,
    folder: Option<&str>,
    strip: bool,
    model_dir: &Path,
) {
    out.as_mut_os_string().clear();
    let file = if strip {
        // MuJoCo strips both separators, whatever the platform.
        file.rsplit(['/', '\\']).next().unwrap_or(file)
    } else {
        file
    };
    if Path::new(file).is_absolute() {
        out.push(file);
        return;
    }
    match folder {
        Some(f) if Path::new(f).is_absolute() => out.push(f),
        Some(f) => {
            out.push(model_dir);
            out.push(f);
        }
        None => out.push(model_dir),
    }
    out.push(file);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolves_like_mujoco() {
        let m = Path::new("/models");
        assert_eq!(
            resolve("a.stl", Some("meshes"), false, m),
            Path::new("/models/meshes/a.stl")
        );
        assert_eq!(
            resolve("a.stl", Some("/abs"), false, m),
            Path::new("/abs/a.stl")
        );
        assert_eq!(
            resolve("/x/a.stl", Some("meshes"), false, m),
            Path::new("/x/a.stl")
        );
        assert_eq!(
            resolve("sub/a.stl", Some("m"), true, m),
            Path::new("/models/m/a.stl")
        );
        assert_eq!(resolve("a.png", None, false, m), Path::new("/models/a.png"));
    }

    #[test]
    fn joins_by_name_as_mujoco_does() {
        let j = |base: &str, file: &str| join_by_name(Path::new(base), file);
        assert_eq!(j("/a/b", "../c.xml"), Path::new("/a/c.xml"));
        assert_eq!(j("/a/b", "./x/../c.xml"), Path::new("/a/b/c.xml"));
        assert_eq!(j("/a", "../../c.xml"), Path::new("/c.xml"));
        assert_eq!(j("/a", "/abs/./c.xml"), Path::new("/abs/c.xml"));
        assert_eq!(j("", "../c.xml"), Path::new("../c.xml"));
        assert_eq!(j("", "x/../../c.xml"), Path::new("../c.xml"));
    }
}
