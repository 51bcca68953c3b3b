//! Prefixing: every identifier and every reference to it renamed together, in every
//! section, as MuJoCo's schema marks them (`id<ns>` / `ref<ns>`, name lists, and the
//! polymorphic `objname`/`refname` typed by `objtype`/`reftype`).

use crate::document::Document;
use crate::error::Error;
use crate::names::Sym;
use crate::schema::Kind;
use crate::tree::{Node, StrRef};
use crate::vocab::{AttrKind, Ns};

/// The namespace an `objtype`/`reftype` keyword names (MuJoCo's `mjtObj` names).
pub(crate) fn ns_of_objtype(keyword: &str) -> Option<Ns> {
    Some(match keyword.trim() {
        "body" | "xbody" => Ns::Body,
        "joint" => Ns::Joint,
        "geom" => Ns::Geom,
        "site" => Ns::Site,
        "camera" => Ns::Camera,
        "light" => Ns::Light,
        "frame" => Ns::Frame,
        "mesh" => Ns::Mesh,
        "hfield" => Ns::Hfield,
        "skin" => Ns::Skin,
        "texture" => Ns::Texture,
        "material" => Ns::Material,
        "tendon" => Ns::Tendon,
        "actuator" => Ns::Actuator,
        "sensor" => Ns::Sensor,
        "equality" => Ns::Equality,
        "pair" => Ns::Pair,
        "exclude" => Ns::Exclude,
        "flex" => Ns::Flex,
        "key" => Ns::Key,
        "numeric" => Ns::Numeric,
        "text" => Ns::Text,
        "tuple" => Ns::Tuple,
        _ => return None,
    })
}

/// The name MuJoCo gives an asset that has a `file` but no `name`: the file name without
/// its folder and extension. `None` for kinds MuJoCo does not name that way.
pub(crate) fn name_from_file(tag: &str, file: &str) -> Option<String> {
    if !matches!(tag, "mesh" | "texture" | "hfield" | "skin") {
        return None;
    }
    let base = file.rsplit(['/', '\\']).next().unwrap_or(file);
    let stem = match base.rfind('.') {
        Some(i) => &base[..i],
        None => base,
    };
    (!stem.is_empty()).then(|| stem.to_string())
}

/// One rename to apply: which node, which attribute, the new value.
struct Edit {
    node: Node,
    name: Sym,
    value: String,
}

impl Document {
    /// Gives every name in the document the prefix `prefix`: identifiers and every
    /// reference to them, in every section. References to the world body (`world`) stay.
    /// Assets that MuJoCo would name after their file get that name, prefixed.
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let mut doc = Document::from_str(
    ///     r#"<mujoco><worldbody><body name="b"><joint name="j"/><geom size="1"/></body></worldbody>
    ///        <actuator><motor joint="j"/></actuator></mujoco>"#,
    ///     ".",
    /// )?;
    /// doc.apply_prefix("r0_")?;
    /// let xml = doc.to_xml_string();
    /// assert!(xml.contains(r#"<body name="r0_b">"#) && xml.contains(r#"<motor joint="r0_j"/>"#));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn apply_prefix(&mut self, prefix: &str) -> Result<(), Error> {
        self.apply_prefix_except(prefix, |_, _| false)
    }

    /// [`Document::apply_prefix`], except for names for which `keep(namespace, name)` is
    /// true: those stay as they are, both where declared and where referenced.
    ///
    /// Skin files name their bone bodies inside the file; their content is written into the
    /// `<skin>` element first so those names can be renamed too (an unreadable skin file is
    /// the one error).
    pub fn apply_prefix_except(
        &mut self,
        prefix: &str,
        keep: impl Fn(Ns, &str) -> bool,
    ) -> Result<(), Error> {
        if prefix.is_empty() {
            return Ok(());
        }
        self.inline_skin_files()?;
        let mut edits: Vec<Edit> = Vec::new();
        let mut stack: Vec<(Node, Kind)> = vec![(self.root, Kind::root())];
        let rename = |ns: Ns, v: &str| -> Option<String> {
            let v = v.trim();
            if v.is_empty() || (ns == Ns::Body && v == "world") || keep(ns, v) {
                None
            } else {
                Some(format!("{prefix}{v}"))
            }
        };
        while let Some((node, kind)) = stack.pop() {
            let mut has_name = false;
            for a in self.attr_slice(node) {
                let Some(spec) = kind.attr(a.name) else { continue };
                let value = self.str(a.value);
                let new = match spec.kind {
                    AttrKind::Id(ns) => {
                        has_name = true;
                        rename(ns, value)
                    }
                    AttrKind::Ref(ns) => rename(ns, value),
                    AttrKind::RefList(ns) => {
                        let tokens: Vec<String> = value
                            .split_ascii_whitespace()
                            .map(|t| rename(ns, t).unwrap_or_else(|| t.to_string()))
                            .collect();
                        Some(tokens.join(" "))
                    }
                    AttrKind::ObjType { name_attr } => {
                        let target = crate::names::known(name_attr);
                        let ns = ns_of_objtype(value);
                        match (target, ns) {
                            (Some(t), Some(ns)) => {
                                if let Some(v) = self.attr_sym(node, t) {
                                    if let Some(nv) = rename(ns, v) {
                                        edits.push(Edit { node, name: t, value: nv });
                                    }
                                }
                            }
                            _ => {}
                        }
                        None
                    }
                    AttrKind::Plain | AttrKind::File | AttrKind::ObjName => None,
                };
                if let Some(value) = new {
                    edits.push(Edit { node, name: a.name, value });
                }
            }
            if !has_name {
                // An asset named after its file gets that name explicitly, prefixed.
                let tag = self.tag(node);
                if let Some(file) = self.attr(node, "file") {
                    if let Some(stem) = name_from_file(tag, file) {
                        let ns = match tag {
                            "mesh" => Ns::Mesh,
                            "texture" => Ns::Texture,
                            "hfield" => Ns::Hfield,
                            _ => Ns::Skin,
                        };
                        if let (Some(value), Some(name)) = (rename(ns, &stem), crate::names::known("name")) {
                            edits.push(Edit { node, name, value });
                        }
                    }
                }
            }
            for kid in self.elements(node) {
                if let Some(k) = self.tag_sym(kid).and_then(|t| kind.child(t)) {
                    stack.push((kid, k));
                }
            }
        }
        for e in edits {
            let value: StrRef = self.push_str(&e.value);
            self.set_attr_ref(e.node, e.name, value);
        }
        Ok(())
    }
}
