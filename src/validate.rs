//! The validation pass: duplicate names and dangling references, all reported at once.

use ahash::AHashMap;

use crate::document::Document;
use crate::error::{Error, ErrorKind, Errors};
use crate::prefix::{name_from_file, ns_of_objtype};
use crate::schema::Kind;
use crate::tree::Node;
use crate::vocab::{AttrKind, Ns};

/// A reference found in the document, checked once every name is known.
struct Reference {
    node: Node,
    attr: String,
    ns: Ns,
    name: String,
}

impl Document {
    /// Checks that no two objects of one namespace share a name and that every reference
    /// names an existing object (the world body is always there). Reports every problem,
    /// in document order, each at its element's `file:line:col`.
    ///
    /// ```
    /// use mjcf_forge::Document;
    /// let doc = Document::from_str(
    ///     r#"<mujoco><worldbody><body name="a"/><body name="a"/></worldbody>
    ///        <actuator><motor joint="nope"/></actuator></mujoco>"#,
    ///     ".",
    /// )?;
    /// let errors = doc.validate().unwrap_err();
    /// assert_eq!(errors.0.len(), 2);
    /// assert_eq!(errors.0[0].to_string(), "<string>:1:36: duplicate body name 'a' (first at <string>:1:20)");
    /// assert_eq!(errors.0[1].to_string(), "<string>:2:18: 'joint' names no joint 'nope'");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn validate(&self) -> Result<(), Errors> {
        let mut ids: AHashMap<(Ns, String), Node> = AHashMap::new();
        let mut refs: Vec<Reference> = Vec::new();
        let mut errors: Vec<(Node, Error)> = Vec::new();
        let mut stack: Vec<(Node, Kind)> = vec![(self.root, Kind::root())];
        while let Some((node, kind)) = stack.pop() {
            let mut declared = false;
            for (name, value) in self.attrs(node) {
                let Some(spec) = crate::names::known(name).and_then(|s| kind.attr(s)) else {
                    continue;
                };
                match spec.kind {
                    AttrKind::Id(ns) => {
                        declared = true;
                        self.declare(&mut ids, &mut errors, node, ns, value);
                    }
                    AttrKind::Ref(ns) => refs.push(Reference {
                        node,
                        attr: name.to_string(),
                        ns,
                        name: value.trim().to_string(),
                    }),
                    AttrKind::RefList(ns) => {
                        for t in value.split_ascii_whitespace() {
                            refs.push(Reference { node, attr: name.to_string(), ns, name: t.to_string() });
                        }
                    }
                    AttrKind::ObjType { name_attr } => {
                        if let (Some(ns), Some(target)) = (ns_of_objtype(value), self.attr(node, name_attr)) {
                            refs.push(Reference {
                                node,
                                attr: name_attr.to_string(),
                                ns,
                                name: target.trim().to_string(),
                            });
                        }
                    }
                    AttrKind::Plain | AttrKind::File | AttrKind::ObjName => {}
                }
            }
            if !declared {
                // Assets without a name are named after their file.
                if let Some(stem) = self.attr(node, "file").and_then(|f| name_from_file(self.tag(node), f)) {
                    let ns = match self.tag(node) {
                        "mesh" => Ns::Mesh,
                        "texture" => Ns::Texture,
                        "hfield" => Ns::Hfield,
                        _ => Ns::Skin,
                    };
                    self.declare(&mut ids, &mut errors, node, ns, &stem);
                }
            }
            let kids: Vec<(Node, Kind)> = self
                .elements(node)
                .filter_map(|k| self.tag_sym(k).and_then(|t| kind.child(t)).map(|c| (k, c)))
                .collect();
            stack.extend(kids.into_iter().rev());
        }
        for r in refs {
            if r.name.is_empty() || (r.ns == Ns::Body && r.name == "world") {
                continue;
            }
            if matches!(r.ns, Ns::Model) {
                continue;
            }
            if !ids.contains_key(&(r.ns, r.name.clone())) {
                let msg = format!("'{}' names no {} '{}'", r.attr, r.ns.as_str(), r.name);
                errors.push((r.node, self.error_at(r.node, ErrorKind::Invalid(msg))));
            }
        }
        if errors.is_empty() {
            return Ok(());
        }
        errors.sort_by_key(|(n, _)| {
            let s = self.spans[crate::tree::Tree::index(*n)];
            (s.file, s.line, s.col)
        });
        Err(Errors(errors.into_iter().map(|(_, e)| e).collect()))
    }

    fn declare(
        &self,
        ids: &mut AHashMap<(Ns, String), Node>,
        errors: &mut Vec<(Node, Error)>,
        node: Node,
        ns: Ns,
        name: &str,
    ) {
        let name = name.trim();
        if name.is_empty() {
            return;
        }
        match ids.get(&(ns, name.to_string())) {
            Some(&first) => {
                let msg = format!(
                    "duplicate {} name '{name}' (first at {})",
                    ns.as_str(),
                    self.location(first)
                );
                errors.push((node, self.error_at(node, ErrorKind::Invalid(msg))));
            }
            None => {
                ids.insert((ns, name.to_string()), node);
            }
        }
    }
}

impl Document {
    /// The names `part` declares that this document declares too, each reported at the
    /// part's element with the position of ours (what a merge of the two would break).
    ///
    /// Assets and default classes are left out: a merge shares identical ones and reports
    /// the others with both contents' positions.
    pub(crate) fn name_clashes(&self, part: &Document) -> Vec<Error> {
        let shared = |ns: Ns| {
            matches!(ns, Ns::Mesh | Ns::Texture | Ns::Material | Ns::Hfield | Ns::Skin | Ns::Default)
        };
        let mut theirs = part.declared_names();
        theirs.retain(|(ns, _, _)| !shared(*ns));
        if theirs.is_empty() {
            return Vec::new();
        }
        let wanted: ahash::AHashSet<(Ns, &str)> = theirs.iter().map(|(ns, name, _)| (*ns, *name)).collect();
        let mut ours: AHashMap<(Ns, &str), Node> = AHashMap::new();
        for (ns, name, node) in self.declared_names() {
            if wanted.contains(&(ns, name)) {
                ours.entry((ns, name)).or_insert(node);
            }
        }
        theirs
            .iter()
            .filter_map(|&(ns, name, node)| {
                ours.get(&(ns, name)).map(|&first| {
                    let msg = format!("duplicate {} name '{name}' (first at {})", ns.as_str(), self.location(first));
                    part.error_at(node, ErrorKind::Invalid(msg))
                })
            })
            .collect()
    }

    /// Every name the document declares (its `id` attributes, and assets named after their
    /// file), with the declaring element, in document order.
    pub(crate) fn declared_names(&self) -> Vec<(Ns, &str, Node)> {
        let mut out = Vec::new();
        let mut stack: Vec<(Node, Kind)> = vec![(self.root, Kind::root())];
        while let Some((node, kind)) = stack.pop() {
            let mut declared = false;
            for a in self.attr_slice(node) {
                if let Some(spec) = kind.attr(a.name) {
                    if let AttrKind::Id(ns) = spec.kind {
                        declared = true;
                        let v = self.str(a.value).trim();
                        if !v.is_empty() {
                            out.push((ns, v, node));
                        }
                    }
                }
            }
            if !declared && matches!(self.tag(node), "mesh" | "texture" | "hfield" | "skin") {
                if let Some(file) = self.attr(node, "file") {
                    if name_from_file(self.tag(node), file).is_some() {
                        let base = file.rsplit(['/', '\\']).next().unwrap_or(file);
                        let stem = base.rfind('.').map_or(base, |i| &base[..i]);
                        let ns = match self.tag(node) {
                            "mesh" => Ns::Mesh,
                            "texture" => Ns::Texture,
                            "hfield" => Ns::Hfield,
                            _ => Ns::Skin,
                        };
                        out.push((ns, stem, node));
                    }
                }
            }
            let n = stack.len();
            for k in self.elements(node) {
                if let Some(c) = self.tag_sym(k).and_then(|t| kind.child(t)) {
                    stack.push((k, c));
                }
            }
            stack[n..].reverse();
        }
        out
    }
}
