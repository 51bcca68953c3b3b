//! Where a body's mass and inertia come from, its `<inertial>` or its geoms: what the
//! compiler's inertia settings act on, and so what converting them must rewrite.

use crate::document::Document;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind};

impl Document {
    /// Whether `body` has a geom (directly or in a `<frame>` inside it) in the compiler's
    /// `inertiagrouprange` ("lo hi") whose mass is not zero (`mass="0"`, or `density="0"`
    /// without `mass`). Under inertiafromgeom="true" such a body takes its inertia from its
    /// geoms; a body without one keeps its `<inertial>` (MuJoCo 3.17.0 and 4.0.0: a body with
    /// no geom, only geoms of other groups, or only massless ones).
    pub(crate) fn has_massive_geom_in_range(&self, body: Node, range: &str) -> bool {
        let bounds: Vec<i64> = range
            .split_ascii_whitespace()
            .filter_map(|t| t.parse().ok())
            .collect();
        let (lo, hi) = match bounds[..] {
            [lo, hi] => (lo, hi),
            _ => (0, 5),
        };
        let zero = |n: Node, k: &str| {
            self.attr(n, k)
                .and_then(|v| v.trim().parse::<f64>().ok())
                .is_some_and(|x| x == 0.0)
        };
        let mut stack: Vec<Node> = self.elements(body).collect();
        while let Some(n) = stack.pop() {
            match self.tag(n) {
                "geom" => {
                    let group = self
                        .attr(n, "group")
                        .and_then(|v| v.trim().parse::<i64>().ok())
                        .unwrap_or(0);
                    let massless = match self.attr(n, "mass") {
                        Some(_) => zero(n, "mass"),
                        None => zero(n, "density"),
                    };
                    if (lo..=hi).contains(&group) && !massless {
                        return true;
                    }
                }
                "frame" => stack.extend(self.elements(n)),
                _ => {}
            }
        }
        false
    }

    /// The bodies whose mass and inertia MuJoCo infers from their geoms (under
    /// `inertiafromgeom="auto"`): those without an `<inertial>` that have a geom, directly or
    /// in a `<frame>` (or `<replicate>`) inside them.
    pub(crate) fn bodies_inferring_inertia(&self) -> Vec<Node> {
        let has_geom = |body: Node| {
            let mut stack: Vec<Node> = self.elements(body).collect();
            while let Some(n) = stack.pop() {
                match self.tag(n) {
                    "geom" => return true,
                    "frame" | "replicate" => stack.extend(self.elements(n)),
                    _ => {}
                }
            }
            false
        };
        self.descendants(self.root)
            .filter(|&n| self.tag(n) == "body")
            .filter(|&b| !self.elements(b).any(|c| self.tag(c) == "inertial"))
            .filter(|&b| has_geom(b))
            .collect()
    }
}

/// The masses and inertias of a document's bodies as MuJoCo compiled the document alone:
/// `mjModel`'s `body_mass` (one number a body), `body_ipos` (3), `body_iquat` (4) and
/// `body_inertia` (3), by body id (the world body first, then the `<body>` elements depth
/// first in document order), with each body's name (`""` for an unnamed one).
///
/// What [`Document::write_compiled_inertials`] writes back. It comes from our MuJoCo FFI
/// (the `mujoco` feature) or from a caller's own MuJoCo: the Python package passes the
/// arrays of the user's `mujoco` through an [`InertiaCompiler`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CompiledInertia {
    /// Each body's name, the world body (`"world"`) first.
    pub body_names: Vec<String>,
    /// `body_mass`: one number a body.
    pub mass: Vec<f64>,
    /// `body_ipos`: three numbers a body.
    pub ipos: Vec<f64>,
    /// `body_iquat`: four numbers a body.
    pub iquat: Vec<f64>,
    /// `body_inertia`: three numbers a body (the diagonal in the inertial frame).
    pub inertia: Vec<f64>,
}

/// Compiles a document alone with MuJoCo and tells its bodies' inertias, or why it could
/// not (the text goes into the merge's error). The merge calls one when a part's compiler
/// settings for masses and inertias differ from the base's
/// ([`Document::merge_all_mapped_with`]).
pub type InertiaCompiler<'a> = dyn FnMut(&Document) -> Result<CompiledInertia, Error> + 'a;

impl Document {
    /// Writes an explicit `<inertial>` (mass, pos, quat, diaginertia, at full precision, as
    /// `compile` says MuJoCo compiles this document alone) into every body that infers its
    /// inertia from its geoms, or, with `all`, into every body whose compiled mass or
    /// inertia is not zero or that has geoms or an `<inertial>` of its own (which is
    /// replaced). Returns how many bodies got one; `compile` is not called when none needs
    /// one.
    ///
    /// Refuses documents whose compiled bodies are not their `<body>` elements one to one
    /// (`<replicate>`, `<attach>`, `<composite>`, `<flexcomp>`, `fusestatic`), and, when
    /// `from_geoms_refused`, documents with `inertiafromgeom="true"` (which ignores
    /// `<inertial>`).
    ///
    /// ```
    /// use mjcf_forge::{CompiledInertia, Document};
    ///
    /// let mut doc = Document::from_str(
    ///     r#"<mujoco><worldbody><body name="b"><geom size="0.1"/></body></worldbody></mujoco>"#,
    ///     ".",
    /// )?;
    /// // What MuJoCo says of this model (a sphere of radius 0.1 and density 1000).
    /// let compiled = CompiledInertia {
    ///     body_names: vec!["world".into(), "b".into()],
    ///     mass: vec![0.0, 4.1887902047863905],
    ///     ipos: vec![0.0; 6],
    ///     iquat: vec![1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
    ///     inertia: vec![0.0, 0.0, 0.0, 0.016755160819145562, 0.016755160819145562, 0.016755160819145562],
    /// };
    /// let written = doc.write_compiled_inertials(false, true, &mut |_: &Document| {
    ///     Ok::<_, mjcf_forge::Error>(compiled.clone())
    /// })?;
    /// assert_eq!(written, 1);
    /// assert!(doc.to_xml_string().contains(r#"<inertial pos="0.0 0.0 0.0" quat="1.0 0.0 0.0 0.0" mass="4.1887902047863905""#));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn write_compiled_inertials<E: From<Error>>(
        &mut self,
        all: bool,
        from_geoms_refused: bool,
        compile: &mut dyn FnMut(&Document) -> Result<CompiledInertia, E>,
    ) -> Result<usize, E> {
        let refused = ["replicate", "attach", "composite", "flexcomp"];
        if let Some(n) = self
            .descendants(self.root)
            .find(|&n| refused.contains(&self.tag(n)))
        {
            return Err(E::from(Error::bare(ErrorKind::Invalid(format!(
                "{}: <{}> makes bodies when MuJoCo compiles; explicit inertials are written for \
                 plain <body> elements only",
                self.location(n),
                self.tag(n)
            )))));
        }
        for c in self
            .elements(self.root)
            .filter(|&c| self.tag(c) == "compiler")
        {
            let setting = |k: &str, bad: &str| self.attr(c, k).is_some_and(|v| v.trim() == bad);
            if (from_geoms_refused && setting("inertiafromgeom", "true"))
                || setting("fusestatic", "true")
            {
                return Err(E::from(Error::bare(ErrorKind::Invalid(format!(
                    "{}: compiler inertiafromgeom=\"true\" or fusestatic=\"true\": explicit \
                     inertials would not carry the compiled inertia",
                    self.location(c)
                )))));
            }
        }
        let inferring = self.bodies_inferring_inertia();
        if inferring.is_empty() && !all {
            return Ok(0);
        }
        let compiled = compile(self)?;
        // MuJoCo numbers bodies depth first in document order, the world body first.
        let bodies: Vec<Node> = self
            .descendants(self.root)
            .filter(|&n| self.tag(n) == "body")
            .collect();
        let names = &compiled.body_names;
        let n = bodies.len() + 1;
        if names.len() != n {
            return Err(E::from(Error::bare(ErrorKind::Invalid(format!(
                "MuJoCo compiled {} bodies from {} <body> elements",
                names.len().saturating_sub(1),
                bodies.len()
            )))));
        }
        let sizes = [
            ("body_mass", compiled.mass.len(), n),
            ("body_ipos", compiled.ipos.len(), 3 * n),
            ("body_iquat", compiled.iquat.len(), 4 * n),
            ("body_inertia", compiled.inertia.len(), 3 * n),
        ];
        if let Some((array, got, want)) = sizes.iter().find(|(_, got, want)| got != want) {
            return Err(E::from(Error::bare(ErrorKind::Invalid(format!(
                "{array} holds {got} numbers, not {want} for {n} bodies"
            )))));
        }
        for (i, &b) in bodies.iter().enumerate() {
            if self.attr(b, "name").is_some_and(|n| n != names[i + 1]) {
                return Err(E::from(Error::bare(ErrorKind::Invalid(format!(
                    "{}: body {:?} compiled as {:?}: bodies do not match one to one",
                    self.location(b),
                    self.attr(b, "name").unwrap_or(""),
                    names[i + 1]
                )))));
            }
        }
        let (mass, ipos, iquat, inertia) = (
            &compiled.mass,
            &compiled.ipos,
            &compiled.iquat,
            &compiled.inertia,
        );
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let own_inertial = |doc: &Document, b| doc.elements(b).find(|&c| doc.tag(c) == "inertial");
        let targets: Vec<Node> = if all {
            bodies
                .iter()
                .enumerate()
                .filter(|&(i, &b)| {
                    let id = i + 1;
                    let nonzero =
                        mass[id] != 0.0 || inertia[3 * id..3 * id + 3].iter().any(|&x| x != 0.0);
                    nonzero || inferring.contains(&b) || own_inertial(self, b).is_some()
                })
                .map(|(_, &b)| b)
                .collect()
        } else {
            inferring
        };
        for &b in &targets {
            if let Some(old) = own_inertial(self, b) {
                self.remove(old);
            }
            let id = 1 + bodies
                .iter()
                .position(|&n| n == b)
                .expect("a body of the document");
            let attrs = [
                ("pos", list(&ipos[3 * id..3 * id + 3])),
                ("quat", list(&iquat[4 * id..4 * id + 4])),
                ("mass", list(&mass[id..id + 1])),
                ("diaginertia", list(&inertia[3 * id..3 * id + 3])),
            ];
            let attrs: Vec<(&str, &str)> = attrs.iter().map(|(k, v)| (*k, v.as_str())).collect();
            self.append_element(b, "inertial", &attrs);
        }
        Ok(targets.len())
    }

    /// For a document with `compiler inertiafromgeom="true"`: every body's compiled inertia
    /// written out as [`Document::write_compiled_inertials`] does with `all` (compiled under
    /// "true", whatever the body's `<inertial>` says), then the setting made `"auto"`, under
    /// which every written `<inertial>` counts: the same masses and inertias, and no mass
    /// setting left with anything to change.
    pub(crate) fn write_compiled_inertials_from_geoms(
        &mut self,
        compile: &mut InertiaCompiler<'_>,
    ) -> Result<usize, Error> {
        let n = self.write_compiled_inertials(true, false, compile)?;
        let compilers: Vec<Node> = self
            .elements(self.root())
            .filter(|&c| self.tag(c) == "compiler" && self.attr(c, "inertiafromgeom").is_some())
            .collect();
        for c in compilers {
            self.set_attr(c, "inertiafromgeom", "auto");
        }
        Ok(n)
    }
}
