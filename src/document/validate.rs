//! The validation pass: duplicate names and dangling references, all reported at once.

use ahash::AHashMap;

use crate::document::Document;
use crate::document::names::Sym;
use crate::document::prefix::{
    file_stem, name_attrs, named_after_file, named_after_file_tag, ns_of_objtype,
};
use crate::document::schema::Kind;
use crate::document::tree::Node;
use crate::document::vocab::{AttrKind, MANY, Ns, Value};
use crate::error::{Error, ErrorKind, Errors};

/// A reference found in the document, checked once every name is known.
struct Reference {
    node: Node,
    attr: String,
    ns: Ns,
    name: String,
}

impl Document {
    /// Checks that no two objects of one namespace share a name, that every reference
    /// names an existing object (the world body is always there), and that every value has
    /// the count and form MuJoCo's schema gives it (`pos` three numbers, `group` an integer,
    /// `type` one of its keywords). Reports every problem, in document order, each at its
    /// element's `file:line:col`.
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
                let Some(spec) = crate::document::names::known(name).and_then(|s| kind.attr(s))
                else {
                    continue;
                };
                if let Some(problem) = value_problem(value, spec.value) {
                    let msg = format!("element {} attribute '{name}': {problem}", self.tag(node));
                    errors.push((node, self.error_at(node, ErrorKind::Invalid(msg))));
                }
                match spec.kind {
                    AttrKind::Id(ns) => {
                        // An empty name is no name (an asset is then named after its file).
                        declared |= !value.is_empty();
                        self.declare(&mut ids, &mut errors, node, ns, value);
                    }
                    AttrKind::Ref(ns) => refs.push(Reference {
                        node,
                        attr: name.to_string(),
                        ns,
                        name: value.to_string(),
                    }),
                    AttrKind::RefList(ns) => {
                        for t in value.split_ascii_whitespace() {
                            refs.push(Reference {
                                node,
                                attr: name.to_string(),
                                ns,
                                name: t.to_string(),
                            });
                        }
                    }
                    AttrKind::ObjType { name_attr } => {
                        if let (Some(ns), Some(target)) =
                            (ns_of_objtype(value), self.attr(node, name_attr))
                        {
                            refs.push(Reference {
                                node,
                                attr: name_attr.to_string(),
                                ns,
                                name: target.to_string(),
                            });
                        }
                    }
                    AttrKind::Plain | AttrKind::File | AttrKind::ObjName => {}
                }
            }
            if !declared {
                // Assets without a name are named after their file.
                if let (Some(ns), Some(stem)) = (
                    named_after_file_tag(self.tag(node)),
                    self.attr(node, "file").and_then(file_stem),
                ) {
                    self.declare(&mut ids, &mut errors, node, ns, stem);
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
            let s = self.spans[crate::document::tree::Tree::index(*n)];
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
        // Names are exact strings (see `prefix::Rename::One`): `" a"` and `"a"` are two.
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

/// What is wrong with `value` for an attribute of type `ty`, as MuJoCo 3.17.0 and 4.0.0
/// read it; `None` if they accept it. Numbers: white-space separated, each as `strtod`
/// takes it (`inf`, `nan` and hexadecimal included), none out of range; no value at all is
/// accepted. Keywords: exact, without trimming.
fn value_problem(value: &str, ty: Value) -> Option<String> {
    let (min, max, ints) = match ty {
        Value::Text => return None,
        Value::Keyword(keys) => {
            if keys.contains(&value) {
                return None;
            }
            let list = match keys.split_last() {
                Some((last, [])) => format!("'{last}'"),
                Some((last, rest)) => format!(
                    "{} or '{last}'",
                    rest.iter()
                        .map(|k| format!("'{k}'"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                None => String::new(),
            };
            return Some(format!("unknown keyword '{value}' (expected {list})"));
        }
        Value::Reals(min, max) => (min, max, false),
        Value::Ints(min, max) => (min, max, true),
    };
    let mut count = 0usize;
    for token in value.split_ascii_whitespace() {
        count += 1;
        if let Some(problem) = number_problem(token, ints) {
            return Some(problem);
        }
    }
    // MuJoCo leaves an attribute with no values at its default.
    let max = if max == MANY {
        usize::MAX
    } else {
        usize::from(max)
    };
    if count == 0 || (usize::from(min)..=max).contains(&count) {
        return None;
    }
    let what = if ints { "integer" } else { "number" };
    let expected = match (usize::from(min), max) {
        (lo, usize::MAX) => format!("at least {lo} {what}s"),
        (lo, hi) if lo == hi && lo == 1 => format!("1 {what}"),
        (lo, hi) if lo == hi => format!("{lo} {what}s"),
        (lo, hi) => format!("{lo} to {hi} {what}s"),
    };
    Some(format!("expected {expected}, found {count}"))
}

/// What is wrong with one number token, if anything.
fn number_problem(token: &str, int: bool) -> Option<String> {
    let digits = token.trim_start_matches(['+', '-']);
    if int {
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return Some(format!("'{token}' is not an integer"));
        }
        return match token.parse::<i64>() {
            Ok(n) if i32::try_from(n).is_ok() => None,
            _ => Some(format!("'{token}' is out of range")),
        };
    }
    let lower = digits.to_ascii_lowercase();
    if let Some(hex) = lower.strip_prefix("0x") {
        // strtod's hexadecimal form: rare, taken as MuJoCo takes it, without a range check.
        let ok = !hex.is_empty()
            && hex
                .bytes()
                .all(|b| b.is_ascii_hexdigit() || matches!(b, b'.' | b'p' | b'+' | b'-'));
        return (!ok).then(|| format!("'{token}' is not a number"));
    }
    let Ok(x) = token.parse::<f64>() else {
        return Some(format!("'{token}' is not a number"));
    };
    let literal_inf = lower.starts_with("inf");
    // strtod reports overflow (and underflow to zero) as a range error, which MuJoCo refuses.
    let mantissa = lower.split('e').next().unwrap_or("");
    let underflow = x == 0.0 && mantissa.bytes().any(|b| (b'1'..=b'9').contains(&b));
    if (x.is_infinite() && !literal_inf) || underflow {
        return Some(format!("'{token}' is out of range"));
    }
    None
}

impl Document {
    /// The names the parts declare that this document or an earlier part declares too,
    /// each reported at the later element with the position of the first. This document is
    /// walked once; nothing is allocated per name.
    ///
    /// Assets and default classes are left out: a merge shares identical ones and reports
    /// the others with both contents' positions.
    pub(crate) fn name_clashes(&self, parts: &[&Document]) -> Vec<Error> {
        self.name_clash_list(parts)
            .into_iter()
            .map(|c| {
                let msg = format!(
                    "duplicate {} name '{}' (first at {})",
                    c.ns.as_str(),
                    c.name,
                    c.first
                );
                parts[c.part].error_at(c.node, ErrorKind::Invalid(msg))
            })
            .collect()
    }

    /// What [`Document::name_clashes`] reports, as data: each clash with its part, in
    /// part order then document order, and how many names each part declares (those a
    /// clash can concern).
    pub(crate) fn name_clash_list<'p>(&self, parts: &[&'p Document]) -> Vec<NameClash<'p>> {
        let shared = |ns: Ns| {
            matches!(
                ns,
                Ns::Mesh | Ns::Texture | Ns::Material | Ns::Hfield | Ns::Skin | Ns::Default
            )
        };
        let theirs: Vec<Vec<(Ns, &str, Node)>> = parts
            .iter()
            .map(|p| {
                let mut names = p.declared_names();
                names.retain(|(ns, _, _)| !shared(*ns));
                names
            })
            .collect();
        if theirs.iter().all(Vec::is_empty) {
            return Vec::new();
        }
        // Only the names some part declares matter: index those, then walk ourselves.
        let total: usize = theirs.iter().map(Vec::len).sum();
        let mut seen: std::collections::HashMap<(Ns, &str), (usize, Option<Node>), NameHash> =
            std::collections::HashMap::with_capacity_and_hasher(total, NameHash);
        for names in &theirs {
            for &(ns, name, _) in names {
                seen.entry((ns, name)).or_insert((usize::MAX, None));
            }
        }
        for (ns, name, node) in self.declared_names() {
            if let Some(e) = seen.get_mut(&(ns, name))
                && e.0 == usize::MAX
            {
                *e = (0, Some(node));
            }
        }
        let mut errors = Vec::new();
        for (i, names) in theirs.iter().enumerate() {
            for &(ns, name, node) in names {
                let e = seen.get_mut(&(ns, name)).expect("indexed above");
                let Some(at) = e.1.filter(|_| e.0 != usize::MAX) else {
                    *e = (i + 1, Some(node));
                    continue;
                };
                let first = if e.0 == 0 {
                    self.location(at)
                } else {
                    parts[e.0 - 1].location(at)
                };
                errors.push(NameClash {
                    part: i,
                    ns,
                    name,
                    node,
                    first,
                    declared: names.len(),
                });
            }
        }
        errors
    }

    /// Every name the document declares (its `id` attributes, and assets named after their
    /// file), with the declaring element, in document order.
    pub(crate) fn declared_names(&self) -> Vec<(Ns, &str, Node)> {
        let mut out = Vec::new();
        let mut stack: Vec<(Node, Kind)> = vec![(self.root, Kind::root())];
        while let Some((node, kind)) = stack.pop() {
            let mut declared = false;
            if let Some((id, ns)) = id_attr(kind)
                && let Some(a) = self.attr_slice(node).iter().find(|a| a.name == id)
            {
                let v = self.str(a.value);
                if !v.is_empty() {
                    declared = true;
                    out.push((ns, v, node));
                }
            }
            if !declared && let Some(ns) = named_after_file(kind) {
                static FILE: std::sync::OnceLock<Sym> = std::sync::OnceLock::new();
                let file = *FILE.get_or_init(|| crate::document::names::sym("file"));
                if let Some(stem) = self.attr_sym(node, file).and_then(file_stem) {
                    out.push((ns, stem, node));
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

/// One name a merged part declares that the base or an earlier part declares too.
pub(crate) struct NameClash<'p> {
    /// The part's index.
    pub(crate) part: usize,
    pub(crate) ns: Ns,
    pub(crate) name: &'p str,
    /// The part's element that declares it.
    pub(crate) node: Node,
    /// Where it was declared first.
    pub(crate) first: crate::error::Location,
    /// How many names the part declares (outside the shared namespaces).
    pub(crate) declared: usize,
}

/// The attribute that declares a kind's name, and its namespace (read off the
/// name-attribute table once per kind: the walks here run for every merge).
fn id_attr(kind: Kind) -> Option<(Sym, Ns)> {
    static TABLE: std::sync::OnceLock<Vec<Option<(Sym, Ns)>>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..crate::document::vocab::elements().len())
            .map(|i| {
                name_attrs(Kind(i as u16))
                    .iter()
                    .find_map(|&(s, k)| match k {
                        AttrKind::Id(ns) => Some((s, ns)),
                        _ => None,
                    })
            })
            .collect()
    });
    table.get(kind.0 as usize).copied().flatten()
}

/// A hasher for short names: one multiply per 8 bytes. The keys are model names, not
/// attacker-chosen input, and nothing that reaches output depends on map order.
#[derive(Clone, Copy, Default)]
struct NameHash;

impl std::hash::BuildHasher for NameHash {
    type Hasher = NameHasher;
    fn build_hasher(&self) -> NameHasher {
        NameHasher(0)
    }
}

struct NameHasher(u64);

impl std::hash::Hasher for NameHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        const K: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let w = u64::from_le_bytes(c.try_into().expect("8 bytes"));
            self.0 = (self.0.rotate_left(5) ^ w).wrapping_mul(K);
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            let mut w = [0u8; 8];
            w[..rest.len()].copy_from_slice(rest);
            self.0 = (self.0.rotate_left(5) ^ u64::from_le_bytes(w)).wrapping_mul(K);
        }
    }

    fn write_u8(&mut self, b: u8) {
        self.0 = (self.0.rotate_left(5) ^ u64::from(b)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }

    fn write_usize(&mut self, n: usize) {
        self.0 = (self.0.rotate_left(5) ^ n as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}
