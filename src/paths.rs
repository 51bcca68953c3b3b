//! File references made absolute, as MuJoCo resolves them.
//!
//! MuJoCo's rule (XMLreference, compiler/meshdir): with `strippath` the directory part of
//! the file name is dropped first; then (1) an absolute file name is used as is; (2) else,
//! if the asset folder (`meshdir` for meshes, height fields, skins and flexcomp files;
//! `texturedir` for textures; both default to `assetdir`) is absolute, folder + name;
//! (3) else main-file folder + folder + name. `<compiler>` elements are read in order,
//! each overriding the last. Everything here is relative to the *main* file's folder,
//! also for elements that came from included files.
//!
//! After this pass every file attribute is absolute and `strippath` is switched off, so
//! the document compiles to the same model from any folder.

use std::path::{Path, PathBuf};

use crate::document::Document;
use crate::error::Errors;
use crate::tree::Node;
use crate::vocab::{self, AttrKind, ElementSpec};

#[derive(Default)]
struct Dirs {
    mesh: Option<String>,
    texture: Option<String>,
    strip: bool,
}

/// Makes every file reference of the document absolute.
pub(crate) fn absolutize_paths(doc: &mut Document) -> Result<(), Errors> {
    let root = doc.root;
    let mut dirs = Dirs::default();
    let compilers: Vec<Node> = doc.elements(root).filter(|&n| doc.tag(n) == "compiler").collect();
    for &c in &compilers {
        if let Some(a) = doc.attr(c, "assetdir") {
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
    let model_dir = doc.base_dir();
    let mut edits: Vec<(Node, String, String)> = Vec::new();
    let spec = vocab::root();
    collect(doc, root, spec, &dirs, &model_dir, &mut edits);
    for (node, name, value) in edits {
        doc.set_attr(node, &name, &value);
    }
    if dirs.strip {
        // The names are absolute now; stripping them again would undo that.
        for &c in &compilers {
            doc.remove_attr(c, "strippath");
        }
    }
    Ok(())
}

fn collect(
    doc: &Document,
    node: Node,
    spec: &'static ElementSpec,
    dirs: &Dirs,
    model_dir: &Path,
    edits: &mut Vec<(Node, String, String)>,
) {
    for (name, value) in doc.attrs(node) {
        let Some(a) = spec.attr(name) else { continue };
        if a.kind != AttrKind::File {
            continue;
        }
        let folder = match spec.tag {
            "texture" => dirs.texture.as_deref(),
            "mesh" | "hfield" | "skin" | "flexcomp" => dirs.mesh.as_deref(),
            _ => None,
        };
        let resolved = resolve(value, folder, dirs.strip, model_dir);
        if resolved.as_os_str() != value {
            edits.push((node, name.to_string(), resolved.to_string_lossy().into_owned()));
        }
    }
    for kid in doc.elements(node) {
        if let Some(kspec) = vocab::child(spec, doc.tag(kid)) {
            collect(doc, kid, kspec, dirs, model_dir, edits);
        }
    }
}

fn resolve(file: &str, folder: Option<&str>, strip: bool, model_dir: &Path) -> PathBuf {
    let file = if strip {
        // MuJoCo strips both separators, whatever the platform.
        file.rsplit(['/', '\\']).next().unwrap_or(file)
    } else {
        file
    };
    let file_path = Path::new(file);
    if file_path.is_absolute() {
        return file_path.to_path_buf();
    }
    match folder {
        Some(f) if Path::new(f).is_absolute() => Path::new(f).join(file),
        Some(f) => model_dir.join(f).join(file),
        None => model_dir.join(file),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolves_like_mujoco() {
        let m = Path::new("/models");
        assert_eq!(resolve("a.stl", Some("meshes"), false, m), Path::new("/models/meshes/a.stl"));
        assert_eq!(resolve("a.stl", Some("/abs"), false, m), Path::new("/abs/a.stl"));
        assert_eq!(resolve("/x/a.stl", Some("meshes"), false, m), Path::new("/x/a.stl"));
        assert_eq!(resolve("sub/a.stl", Some("m"), true, m), Path::new("/models/m/a.stl"));
        assert_eq!(resolve("a.png", None, false, m), Path::new("/models/a.png"));
    }
}
