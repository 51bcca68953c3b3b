//! Relocating a document's files: every file reference rewritten to the content-derived
//! name an [`AssetStore`] gives it (`assets/<hash>.<ext>`), so that the output folder can be
//! moved or copied to another machine and still compile.
//!
//! MuJoCo resolves a relative file name against the folder of the model file it loads
//! (checked with MuJoCo 3.17.0: `assets/a.stl` in `/m/x.xml`, loaded from another working
//! folder, opens `/m/assets/a.stl`), but first prepends `compiler` `meshdir` /
//! `texturedir` / `assetdir` when set (`meshdir="sub"` made it open `sub/assets/a.stl`).
//! Loading left those settings in the document (every file was absolute, so they did not
//! matter); relocation removes them.

use std::path::Path;

use rayon::prelude::*;

use crate::document::Document;
use crate::document::names::{Sym, sym};
use crate::document::prefix::{file_stem, named_after_file};
use crate::document::schema::Kind;
use crate::document::tree::Node;
use crate::document::vocab::AttrKind;
use crate::error::{Error, ErrorKind, Errors};
use crate::output::AssetStore;

/// One file attribute found in a document.
struct FileRef {
    node: Node,
    attr: Sym,
    /// MuJoCo names this asset after this file (it has no `name`).
    named_after_it: bool,
}

impl Document {
    /// Rewrites every file reference of the document (meshes, height fields, skins, flexcomp
    /// files, every texture file including cube faces) into `assets/<hash>.<ext>`,
    /// relative to the folder the document will be written to, and records each source to
    /// copy in `store`. Assets that MuJoCo names after their file get that name explicitly, and the
    /// `compiler` folder settings (`meshdir`, `texturedir`, `assetdir`) are removed so they
    /// cannot redirect the relative names.
    ///
    /// Every problem is reported, each at its element; on error the document is
    /// unchanged. An `<asset><model file>` (a whole MJCF file to attach) is refused: its
    /// own file references would break once it is copied alone.
    pub fn relocate_assets(&mut self, store: &AssetStore) -> Result<(), Errors> {
        let doc = self;
        let refs = file_refs(doc);
        // Files are read and hashed in parallel (a robot's meshes are tens of megabytes);
        // a file two references share may be hashed twice, to the same name.
        let results: Vec<Result<String, Error>> = refs
            .par_iter()
            .map(|r| {
                let value = doc.attr_sym(r.node, r.attr).unwrap_or_default();
                if doc.tag(r.node) == "model" {
                    return Err(doc.error_at(
                        r.node,
                        ErrorKind::Invalid(format!(
                            "cannot relocate the model asset '{value}': its own file \
                             references would break (load it and merge it instead)"
                        )),
                    ));
                }
                store
                    .relocate_file(Path::new(value))
                    .map_err(|e| doc.error_at(r.node, e.kind))
            })
            .collect();
        let mut errors = Vec::new();
        let mut names = Vec::with_capacity(refs.len());
        for r in results {
            match r {
                Ok(name) => names.push(name),
                Err(e) => errors.push(e),
            }
        }
        if !errors.is_empty() {
            return Err(Errors(errors));
        }
        for (r, name) in refs.iter().zip(names) {
            if r.named_after_it {
                let old = doc.attr_sym(r.node, r.attr).unwrap_or_default();
                if let Some(stem) = file_stem(old).map(str::to_owned) {
                    doc.set_attr(r.node, "name", &stem);
                }
            }
            let value = doc.push_str(&name);
            doc.set_attr_ref(r.node, r.attr, value);
        }
        let compiler = Some(sym("compiler"));
        let compilers: Vec<Node> = doc
            .elements(doc.root())
            .filter(|&n| doc.tag_sym(n) == compiler)
            .collect();
        for c in compilers {
            for setting in ["meshdir", "texturedir", "assetdir"] {
                doc.remove_attr(c, setting);
            }
        }
        Ok(())
    }
}

impl Document {
    /// Every file the model reads when MuJoCo compiles it (meshes, textures, height
    /// fields, skins), as its file attributes name them (absolute once loaded), each once,
    /// in document order: what the model store keys a compiled structure by
    /// ([`crate::split::StoreKey::file`]).
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let dir = tempfile::tempdir()?;
    /// std::fs::write(dir.path().join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n")?;
    /// let xml = r#"<mujoco><asset><mesh file="m.obj"/><mesh name="b" file="m.obj"/></asset></mujoco>"#;
    /// let doc = Document::from_str(xml, dir.path())?;
    /// assert_eq!(doc.files(), vec![dir.path().join("m.obj")]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn files(&self) -> Vec<std::path::PathBuf> {
        self.files_where(|_| true)
    }

    /// The files of [`Document::files`] that elements named `tag` read (`"mesh"`: the
    /// mesh files, what MuJoCo's asset cache keeps).
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let xml = r#"<mujoco><asset><mesh file="/m/a.obj"/><texture type="2d" file="/m/t.png"/></asset></mujoco>"#;
    /// let doc = Document::from_str(xml, "/")?;
    /// assert_eq!(doc.files_of("mesh"), vec![std::path::PathBuf::from("/m/a.obj")]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn files_of(&self, tag: &str) -> Vec<std::path::PathBuf> {
        self.files_where(|node| self.tag(node) == tag)
    }

    fn files_where(&self, keep: impl Fn(Node) -> bool) -> Vec<std::path::PathBuf> {
        let mut out: Vec<std::path::PathBuf> = Vec::new();
        for r in file_refs(self).into_iter().filter(|r| keep(r.node)) {
            let value = self.attr_sym(r.node, r.attr).unwrap_or_default();
            let path = std::path::PathBuf::from(value);
            if !out.contains(&path) {
                out.push(path);
            }
        }
        out
    }
}

/// Every file attribute of the document, in document order. A walk with its own stack:
/// nesting depth comes from the input and must not become recursion depth.
fn file_refs(doc: &Document) -> Vec<FileRef> {
    let file = sym("file");
    let mut refs = Vec::new();
    let mut stack: Vec<(Node, Kind)> = vec![(doc.root(), Kind::root())];
    let mut kids = Vec::new();
    while let Some((node, kind)) = stack.pop() {
        if kind.has_file_attrs() {
            let has_name = doc.attr_sym(node, sym("name")).is_some();
            let file_named = named_after_file(kind).is_some() && !has_name;
            for a in doc.attr_slice(node) {
                let is_file = kind
                    .attr(a.name)
                    .is_some_and(|spec| spec.kind == AttrKind::File);
                if is_file && !doc.str(a.value).trim().is_empty() {
                    refs.push(FileRef {
                        node,
                        attr: a.name,
                        named_after_it: file_named && a.name == file,
                    });
                }
            }
        }
        kids.clear();
        kids.extend(doc.elements(node).filter_map(|kid| {
            let k = doc.tag_sym(kid).and_then(|t| kind.child(t))?;
            // Sections like <sensor> or <actuator> cannot hold a file reference.
            k.reaches_file_attrs().then_some((kid, k))
        }));
        // Reversed onto the stack, so they come off in document order.
        stack.extend(kids.drain(..).rev());
    }
    refs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_file_attribute_is_relocated_and_named_files_keep_their_names() {
        let tmp = tempfile::tempdir().unwrap();
        for (f, body) in [
            ("a.obj", "v 1"),
            ("b.png", "png"),
            ("c.png", "png"),
            ("h.bin", "h"),
        ] {
            std::fs::write(tmp.path().join(f), body).unwrap();
        }
        let xml = r#"<mujoco><compiler meshdir="." texturedir="." assetdir="."/>
            <asset><mesh file="a.obj"/><mesh name="m2" file="a.obj"/>
            <texture name="sky" type="skybox" fileright="b.png" fileleft="c.png" fileup="b.png"
               filedown="b.png" filefront="b.png" fileback="b.png"/>
            <texture type="2d" file="c.png"/><hfield file="h.bin"/></asset></mujoco>"#;
        let mut doc = Document::from_str(xml, tmp.path()).unwrap();
        let store = AssetStore::new();
        doc.relocate_assets(&store).unwrap();
        // b.png and c.png have the same bytes: one file.
        assert_eq!(store.len(), 3);
        let out = doc.to_xml_string();
        let name = |f: &str| store.relocate_file(&tmp.path().join(f)).unwrap();
        assert!(
            out.contains(&format!(r#"<mesh file="{}" name="a"/>"#, name("a.obj"))),
            "{out}"
        );
        assert!(out.contains(&format!(r#"<mesh name="m2" file="{}"/>"#, name("a.obj"))));
        assert!(out.contains(&format!(r#"fileleft="{}""#, name("b.png"))));
        assert!(out.contains(&format!(r#"<hfield file="{}" name="h"/>"#, name("h.bin"))));
        assert!(out.contains("<compiler/>"), "{out}");
        assert!(!out.contains(&tmp.path().display().to_string()), "{out}");
    }

    #[test]
    fn problems_are_reported_at_their_elements_and_leave_the_document_as_it_was() {
        let tmp = tempfile::tempdir().unwrap();
        let xml = "<mujoco><asset>\n<mesh file=\"missing.stl\"/>\n<model name=\"m\" file=\"x.xml\"/>\n\
                   <texture type=\"2d\" file=\"/dev/null\"/></asset></mujoco>";
        let mut doc = Document::from_str(xml, tmp.path()).unwrap();
        let before = doc.to_xml_string();
        let err = doc
            .relocate_assets(&AssetStore::new())
            .unwrap_err()
            .to_string();
        let missing = tmp.path().join("missing.stl");
        assert_eq!(
            err,
            format!(
                "<string>:2:1: cannot read '{}': No such file or directory (os error 2)\n\
                 <string>:3:1: cannot relocate the model asset '{}': its own file references \
                 would break (load it and merge it instead)\n\
                 <string>:4:1: cannot read '/dev/null': not a regular file",
                missing.display(),
                tmp.path().join("x.xml").display()
            )
        );
        assert_eq!(doc.to_xml_string(), before);
    }
}
