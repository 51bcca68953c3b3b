//! The loading pipeline: a file (or text) read with its includes, then default classes
//! inlined, then file references made absolute, then repeated sections joined. Each pass
//! takes a [`Document`]; this module is the only one that calls them in order, so the
//! document stays the data structure alone and every pass uses only what is below it:
//!
//! ```text
//! load -> read (includes) -> defaults -> paths -> Document
//! ```

use std::path::Path;

use crate::document::Document;
use crate::document::limits::Limits;
use crate::document::read;
use crate::document::urdf::{self, UrdfOptions};
use crate::error::Errors;

impl Document {
    /// Loads an MJCF file: includes expanded, defaults inlined, file paths made absolute.
    ///
    /// ```no_run
    /// let doc = mjcf_forge::Document::load("robot.xml")?;
    /// println!("{}", doc.to_xml_string());
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn load(path: impl AsRef<Path>) -> Result<Document, Errors> {
        Document::load_with(path, &Limits::default())
    }

    /// [`Document::load`] within other [`Limits`] than the default ones.
    ///
    /// ```
    /// use mjcf_forge::{Document, Limits};
    /// let path = std::env::temp_dir().join("mjcf_forge_load_with_doc.xml");
    /// std::fs::write(&path, "<mujoco><worldbody/></mujoco>").unwrap();
    /// let tiny = Limits { max_file_size: 10, ..Limits::default() };
    /// let err = Document::load_with(&path, &tiny).unwrap_err().to_string();
    /// assert!(err.ends_with("29 bytes, more than the limit of 10 (Limits::max_file_size)"), "{err}");
    /// assert!(Document::load_with(&path, &Limits::default()).is_ok());
    /// # std::fs::remove_file(&path).unwrap();
    /// ```
    pub fn load_with(path: impl AsRef<Path>, limits: &Limits) -> Result<Document, Errors> {
        Document::load_full(path.as_ref(), limits, &UrdfOptions::default())
    }

    /// A file read within `limits`, URDF with `urdf` (MJCF ignores it).
    pub(crate) fn load_full(
        path: &Path,
        limits: &Limits,
        urdf: &UrdfOptions,
    ) -> Result<Document, Errors> {
        if let Some(xacro) = urdf::xacro_text(path, limits)? {
            return finish(
                read::read_str(&xacro, path.parent().unwrap_or(Path::new("")), limits)?,
                urdf,
            );
        }
        finish(read::read_file(path, limits)?, urdf)
    }

    /// [`Document::load_full`] of a file that must be URDF (or xacro): `None` when it is
    /// MJCF, for the caller to say where the URDF options were given.
    pub(crate) fn load_urdf_only(
        path: &Path,
        limits: &Limits,
        urdf: &UrdfOptions,
    ) -> Result<Option<Document>, Errors> {
        if let Some(xacro) = urdf::xacro_text(path, limits)? {
            let dir = path.parent().unwrap_or(Path::new(""));
            return finish(read::read_str(&xacro, dir, limits)?, urdf).map(Some);
        }
        let doc = read::read_file(path, limits)?;
        if !doc.is_urdf() {
            return Ok(None);
        }
        finish(doc, urdf).map(Some)
    }

    /// Loads MJCF text; `base_dir` plays the part of the main file's folder (includes and
    /// asset files are found from there). Positions are reported in `<string>`.
    ///
    /// ```
    /// let doc = mjcf_forge::Document::from_str("<mujoco/>", ".")?;
    /// assert_eq!(doc.to_xml_string(), "<mujoco/>");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    #[allow(clippy::should_implement_trait)]
    pub fn from_str(xml: &str, base_dir: impl AsRef<Path>) -> Result<Document, Errors> {
        Document::from_str_with(xml, base_dir, &Limits::default())
    }

    /// [`Document::from_str`] within other [`Limits`] than the default ones.
    ///
    /// ```
    /// use mjcf_forge::{Document, Limits};
    /// let few = Limits { max_attributes: 2, ..Limits::default() };
    /// let xml = r#"<mujoco><worldbody><geom size="1" rgba="1 0 0 1" name="g"/></worldbody></mujoco>"#;
    /// let err = Document::from_str_with(xml, ".", &few).unwrap_err();
    /// assert_eq!(
    ///     err.to_string(),
    ///     "<string>:1:50: more than 2 attributes on one element (Limits::max_attributes)"
    /// );
    /// ```
    pub fn from_str_with(
        xml: &str,
        base_dir: impl AsRef<Path>,
        limits: &Limits,
    ) -> Result<Document, Errors> {
        Document::from_str_full(xml, base_dir.as_ref(), limits, &UrdfOptions::default())
    }

    /// Text read within `limits`, URDF with `urdf` (MJCF ignores it).
    pub(crate) fn from_str_full(
        xml: &str,
        base_dir: &Path,
        limits: &Limits,
        urdf: &UrdfOptions,
    ) -> Result<Document, Errors> {
        finish(read::read_str(xml, base_dir, limits)?, urdf)
    }
}

/// The passes after reading, in order: a URDF model converted to MJCF, default classes
/// inlined (the classes are gone after it), every file reference made absolute (on the
/// elements as they now are), then repeated sections joined.
fn finish(doc: Document, urdf: &UrdfOptions) -> Result<Document, Errors> {
    let mut doc = if doc.is_urdf() {
        urdf::convert(&doc, urdf)?
    } else {
        doc
    };
    crate::document::defaults::inline_defaults(&mut doc)?;
    crate::document::paths::absolutize_paths(&mut doc)?;
    doc.merge_repeated_sections();
    Ok(doc)
}

/// What a load of `bytes` (as `<string>`, from `dir`) gives, as text: the document (compact,
/// pretty, every node's position) or the errors. With `fast`, the fast reader is tried
/// first (as every load does); without, only quick-xml's path is used. The tests and the
/// `readers` fuzz target hold the two to the same outcome.
pub(crate) fn describe_load(bytes: &[u8], dir: &Path, fast: bool) -> String {
    match read::read_bytes_as_text(bytes, dir, &Limits::default(), fast)
        .and_then(|d| finish(d, &UrdfOptions::default()))
    {
        Ok(d) => {
            let mut out = format!("{}\n{}", d.to_xml_string(), d.to_pretty_string());
            for n in d.descendants(d.root()) {
                let l = d.location(n);
                out.push_str(&format!(" {}:{}", l.line, l.col));
            }
            out
        }
        Err(e) => format!("error: {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(xml: &str, fast: bool) -> String {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpora/features");
        describe_load(xml.as_bytes(), &dir, fast)
    }

    #[test]
    fn both_readers_build_the_same_document() {
        let cases = [
            "<mujoco/>",
            "<?xml version=\"1.0\"?>\n<!-- c\n -->\n<mujoco model='m'>\n <worldbody>\n  <geom size=\"1\"\n    rgba=\"1 0 0 1\"/>\n </worldbody>\n</mujoco>",
            "<mujoco><default><geom size=\"1 2\"/></default><worldbody><body name=\"b\" pos='0 0 0'><geom size=\"3\"/></body></worldbody></mujoco>",
            "<mujoco><worldbody><body>some text<geom/>  <!-- c -->more\ntext<?pi x?><geom/></body></worldbody></mujoco>",
            "<mujoco><custom><text name=\"t\" data=\"a&amp;b\nc\"/></custom></mujoco>",
            "<mujoco><worldbody><body>a &amp; b<![CDATA[x]]></body></worldbody></mujoco>",
            "<mujoco><worldbody><geom a=\"1\"b=\"2\" c = '3' /></worldbody ></mujoco>",
            "<mujoco><worldbody><geom a=\"1\" a=\"2\"/></worldbody></mujoco>",
            "<mujoco><worldbody><geom a=\"1/></worldbody></mujoco>",
            "<mujoco><worldbody></body></mujoco>",
            "<mujoco><worldbody><geom/ ></worldbody></mujoco>",
            "<mujoco><worldbody><geom size=\"1\">></geom></worldbody></mujoco>",
            "<mujoco><!--></mujoco>--></mujoco>",
            "<mujoco><?></mujoco>",
            "\u{feff}<mujoco/>",
            "<robot/>",
            "",
            "<mujoco><include file=\"parts/defaults.xml\"/><worldbody><include file=\"parts/arm.xml\"/></worldbody></mujoco>",
            "<mujoco><worldbody><include file=\"parts/arm.xml\"/><include file=\"parts/arm.xml\"/></worldbody></mujoco>",
            "<mujoco><worldbody><include file=\"parts/missing.xml\"/></worldbody></mujoco>",
        ];
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpora/features");
        let mut files: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "xml"))
            .map(|p| std::fs::read_to_string(p).unwrap())
            .collect();
        files.sort();
        for xml in cases
            .iter()
            .copied()
            .chain(files.iter().map(String::as_str))
        {
            assert_eq!(outcome(xml, true), outcome(xml, false), "{xml:?}");
            // And every prefix of it, which cuts markup at every place.
            for cut in (0..xml.len()).filter(|&i| xml.is_char_boundary(i)) {
                let part = &xml[..cut];
                assert_eq!(outcome(part, true), outcome(part, false), "{part:?}");
            }
        }
    }
}
