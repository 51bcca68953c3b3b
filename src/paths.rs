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
use crate::names::{Sym, sym};
use crate::schema::Kind;
use crate::tree::Node;
use crate::vocab::AttrKind;

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
    let compiler = Some(sym("compiler"));
    let compilers: Vec<Node> = doc
        .elements(root)
        .filter(|&n| doc.tag_sym(n) == compiler)
        .collect();
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
    if kind.has_file_attrs() {
        for a in doc.attr_slice(node) {
            if kind
                .attr(a.name)
                .is_none_or(|spec| spec.kind != AttrKind::File)
            {
                continue;
            }
            let value = doc.str(a.value);
            let folder = match kind.spec().tag {
                "texture" => dirs.texture.as_deref(),
                "mesh" | "hfield" | "skin" | "flexcomp" => dirs.mesh.as_deref(),
                _ => None,
            };
            resolve_into(&mut found.path, value, folder, dirs.strip, model_dir);
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
}
