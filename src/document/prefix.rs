//! Prefixing: every identifier and every reference to it renamed together, in every
//! section, as MuJoCo's schema marks them (`id<ns>` / `ref<ns>`, name lists, and the
//! polymorphic `objname`/`refname` typed by `objtype`/`reftype`).

use crate::document::Document;
use crate::document::names::Sym;
use crate::document::schema::Kind;
use crate::document::tree::{Node, StrRef};
use crate::document::vocab::{AttrKind, Ns};
use crate::error::Error;

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

/// The namespace of an element kind that MuJoCo names after its file when it has no
/// `name` (mesh, texture, height field, skin assets).
pub(crate) fn named_after_file(kind: Kind) -> Option<Ns> {
    // Asked for every element of every walk: a table, not a string match.
    static TABLE: std::sync::OnceLock<Vec<Option<Ns>>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        crate::document::vocab::elements()
            .iter()
            .map(|e| named_after_file_tag(e.name))
            .collect()
    });
    table.get(kind.0 as usize).copied().flatten()
}

/// [`named_after_file`] by tag, for the asset kinds (whose tag is their kind's name).
pub(crate) fn named_after_file_tag(tag: &str) -> Option<Ns> {
    match tag {
        "mesh" => Some(Ns::Mesh),
        "texture" => Some(Ns::Texture),
        "hfield" => Some(Ns::Hfield),
        "skin" => Some(Ns::Skin),
        _ => None,
    }
}

/// The file name without folder and extension: the name MuJoCo gives such an asset.
pub(crate) fn file_stem(file: &str) -> Option<&str> {
    let base = file.rsplit(['/', '\\']).next().unwrap_or(file);
    let stem = base.rfind('.').map_or(base, |i| &base[..i]);
    (!stem.is_empty()).then_some(stem)
}

/// One rename to apply.
enum Rename {
    /// One name (an identifier or a reference): `old` is its text, exactly as written.
    /// MuJoCo 3.17.0 and 4.0.0 read names as exact strings, in declarations and references
    /// alike: `" 0"`, `"0 "` and `"0"` are three names, and a reference `" 0"` finds only
    /// `" 0"` (corpora/features/names_exact_strings.xml). Trimming would merge them.
    One { node: Node, name: Sym, old: StrRef },
    /// A space-separated list of names of one namespace.
    List {
        node: Node,
        name: Sym,
        old: StrRef,
        ns: Ns,
    },
    /// An asset named after its file gets `prefix + stem` as its name.
    Named { node: Node, stem: String },
}

/// Refuses a prefix that would make names MuJoCo reads differently, or output no XML 1.0
/// parser reads: white space splits the name lists some attributes hold (a flex's `body`),
/// and control characters are not XML characters.
///
/// ```
/// let mut doc = mjcf_forge::Document::from_str("<mujoco/>", ".")?;
/// let err = doc.apply_prefix("robot 0_").unwrap_err();
/// assert_eq!(
///     err.to_string(),
///     "prefix 'robot 0_' holds white space (U+0020), which would split name lists"
/// );
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
pub(crate) fn check_prefix(prefix: &str) -> Result<(), Error> {
    let shown = crate::document::read::clip(prefix, 60);
    let refuse = |why: String| {
        Err(Error::bare(crate::error::ErrorKind::Invalid(format!(
            "prefix '{shown}' {why}"
        ))))
    };
    for c in prefix.chars() {
        if c.is_whitespace() {
            return refuse(format!(
                "holds white space (U+{:04X}), which would split name lists",
                c as u32
            ));
        }
        if c.is_control() || matches!(c, '\u{FFFE}' | '\u{FFFF}') {
            let what = format!(
                "holds U+{:04X}, which is not a character XML allows",
                c as u32
            );
            return refuse(what);
        }
    }
    Ok(())
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
        check_prefix(prefix)?;
        self.inline_skin_files()?;
        // First find what to rename (no allocation per name), then write every new value
        // straight into the string buffer.
        let mut edits: Vec<Rename> = Vec::new();
        let mut stack: Vec<(Node, Kind)> = vec![(self.root, Kind::root())];
        let renamed = |ns: Ns, v: &str| -> bool {
            !(v.is_empty() || (ns == Ns::Body && v == "world") || keep(ns, v))
        };
        while let Some((node, kind)) = stack.pop() {
            let mut has_name = false;
            let naming = name_attrs(kind);
            let attach = kind.spec().name == "attach";
            if attach {
                self.prefix_attach(node, prefix, &renamed, &mut edits)?;
                continue;
            }
            let file_named = named_after_file(kind);
            if naming.is_empty() && file_named.is_none() {
                for kid in self.elements(node) {
                    if let Some(k) = self.tag_sym(kid).and_then(|t| kind.child(t)) {
                        stack.push((kid, k));
                    }
                }
                continue;
            }
            for a in self.attr_slice(node) {
                let Some(&(_, attr_kind)) = naming.iter().find(|(s, _)| *s == a.name) else {
                    continue;
                };
                match attr_kind {
                    AttrKind::Id(ns) | AttrKind::Ref(ns) => {
                        // An empty name is no name: MuJoCo names such an asset after its
                        // file all the same.
                        has_name |=
                            matches!(attr_kind, AttrKind::Id(_)) && !self.str(a.value).is_empty();
                        if renamed(ns, self.str(a.value)) {
                            edits.push(Rename::One {
                                node,
                                name: a.name,
                                old: a.value,
                            });
                        }
                    }
                    AttrKind::RefList(ns) => edits.push(Rename::List {
                        node,
                        name: a.name,
                        old: a.value,
                        ns,
                    }),
                    AttrKind::ObjType { name_attr } => {
                        if let (Some(t), Some(ns)) = (
                            crate::document::names::known(name_attr),
                            ns_of_objtype(self.str(a.value)),
                        ) && let Some(r) = self.attr_ref(node, t)
                            && renamed(ns, self.str(r))
                        {
                            edits.push(Rename::One {
                                node,
                                name: t,
                                old: r,
                            });
                        }
                    }
                    AttrKind::Plain | AttrKind::File | AttrKind::ObjName => {}
                }
            }
            if kind.spec().name == "model"
                && self.attr(node, "name").is_none()
                && let Some(stem) = self.child_model_name(node)?
                && renamed(Ns::Model, &stem)
            {
                // MuJoCo names a `<model>` asset without `name` after the model it holds
                // (`name=""` stays no name): the `<attach model>` that uses it needs that
                // name, prefixed.
                edits.push(Rename::Named { node, stem });
            }
            if let Some(ns) = file_named.filter(|_| !has_name) {
                // An asset named after its file gets that name explicitly, prefixed.
                if let Some(stem) = self.attr(node, "file").and_then(file_stem)
                    && renamed(ns, stem)
                {
                    edits.push(Rename::Named {
                        node,
                        stem: stem.to_string(),
                    });
                }
            }
            for kid in self.elements(node) {
                if let Some(k) = self.tag_sym(kid).and_then(|t| kind.child(t)) {
                    stack.push((kid, k));
                }
            }
        }
        let name_sym = crate::document::names::sym("name");
        self.strings.reserve(edits.len() * (prefix.len() + 24));
        for e in edits {
            let start = self.strings.len();
            let (node, name) = match e {
                Rename::One { node, name, old } => {
                    self.strings.push_str(prefix);
                    self.strings
                        .extend_from_within(old.start as usize..(old.start + old.len) as usize);
                    (node, name)
                }
                Rename::List {
                    node,
                    name,
                    old,
                    ns,
                } => {
                    let text = self.str(old).to_string();
                    for (i, t) in text.split_ascii_whitespace().enumerate() {
                        if i > 0 {
                            self.strings.push(' ');
                        }
                        if renamed(ns, t) {
                            self.strings.push_str(prefix);
                        }
                        self.strings.push_str(t);
                    }
                    (node, name)
                }
                Rename::Named { node, stem } => {
                    self.strings.push_str(prefix);
                    self.strings.push_str(&stem);
                    (node, name_sym)
                }
            };
            let value = StrRef {
                start: start as u32,
                len: (self.strings.len() - start) as u32,
            };
            self.set_attr_ref(node, name, value);
        }
        Ok(())
    }
}

impl Document {
    /// The renames of an `<attach>` (it has no children).
    ///
    /// With `model`, it attaches a model asset: `model` names the asset (our namespace),
    /// `body` and `frame` name elements of the attached model (its namespace, not ours:
    /// they stay), and MuJoCo 3.17.0 and 4.0.0 name every attached element `prefix` + its
    /// name, so our prefix goes in front of the attach's own (`prefix="a_"` becomes
    /// `"p_a_"`, and the attached `x` compiles to `p_a_x`; nested attaches inside the
    /// asset follow, `p_a_c_y`).
    ///
    /// Without `model` it copies a body or frame of this same model (self-attach), naming
    /// the copies `prefix` + the copied names. Those names are ours, so they are prefixed,
    /// and the copies would come out as `top_p_belt` where `p_top_belt` is wanted: no
    /// value of the attach's `prefix` gives that, so we refuse.
    fn prefix_attach(
        &self,
        node: Node,
        prefix: &str,
        renamed: &impl Fn(Ns, &str) -> bool,
        edits: &mut Vec<Rename>,
    ) -> Result<(), Error> {
        let syms = [
            crate::document::names::sym("model"),
            crate::document::names::sym("prefix"),
        ];
        let model = self.attr_ref(node, syms[0]);
        let Some(model) = model.filter(|m| !self.str(*m).is_empty()) else {
            let theirs = self.attr(node, "prefix").unwrap_or_default();
            let what = self.attr(node, "body").map_or_else(
                || self.attr(node, "frame").map(|f| format!("frame '{f}'")),
                |b| Some(format!("body '{b}'")),
            );
            let what = what.unwrap_or_else(|| "the world body".to_string());
            let ours = crate::document::read::clip(prefix, 60);
            return Err(self.error_at(
                node,
                crate::error::ErrorKind::Invalid(format!(
                    "cannot prefix a self-attach (<attach> of {what} without 'model'): \
                     MuJoCo names the copies '{theirs}' + the copied names, which prefixing \
                     renames, so they would compile to '{theirs}{ours}...', not \
                     '{ours}{theirs}...'"
                )),
            ));
        };
        if renamed(Ns::Model, self.str(model)) {
            edits.push(Rename::One {
                node,
                name: syms[0],
                old: model,
            });
        }
        if let Some(theirs) = self.attr_ref(node, syms[1]) {
            edits.push(Rename::One {
                node,
                name: syms[1],
                old: theirs,
            });
        }
        Ok(())
    }

    /// The name MuJoCo gives a `<model>` asset without `name`: the `model` attribute of
    /// the file it names (`MuJoCo Model` when that has none, as in 3.17.0 and 4.0.0).
    fn child_model_name(&self, node: Node) -> Result<Option<String>, Error> {
        let Some(file) = self.attr(node, "file") else {
            return Ok(None);
        };
        let child = crate::document::read::read_file(std::path::Path::new(file), &self.limits)
            .map_err(|e| {
                self.error_at(
                    node,
                    crate::error::ErrorKind::Invalid(format!("model file '{file}': {e}")),
                )
            })?;
        Ok(Some(
            child.model_name().unwrap_or("MuJoCo Model").to_string(),
        ))
    }

    /// The value of an attribute, as a range of the string buffer.
    fn attr_ref(&self, node: Node, name: Sym) -> Option<StrRef> {
        self.attr_slice(node)
            .iter()
            .find(|a| a.name == name)
            .map(|a| a.value)
    }
}

/// The attributes of a kind that hold names (identifiers, references, name lists, object
/// types), computed once per kind.
pub(crate) fn name_attrs(kind: Kind) -> &'static [(Sym, AttrKind)] {
    static TABLE: std::sync::OnceLock<Vec<Vec<(Sym, AttrKind)>>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..crate::document::vocab::elements().len())
            .map(|i| {
                Kind(i as u16)
                    .spec()
                    .attrs
                    .iter()
                    .filter(|a| {
                        !matches!(a.kind, AttrKind::Plain | AttrKind::File | AttrKind::ObjName)
                    })
                    .filter_map(|a| crate::document::names::known(a.name).map(|s| (s, a.kind)))
                    .collect()
            })
            .collect()
    });
    table.get(kind.0 as usize).map_or(&[], Vec::as_slice)
}
