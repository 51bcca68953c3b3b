//! Random MJCF documents for differential tests of the model caches against MuJoCo
//! (`tests/document_differential.rs`, `python/tests/test_differential.py`,
//! `scripts/differential.sh`): [`random_mjcf`]`(seed, variant)` draws a model's structure
//! from `seed` and its values from `(seed, variant)`, so the variants of one seed are
//! mostly one structure with other values (what a cache patches), and now and then another
//! structure (a geom more or less, another joint type: what it compiles).

use std::fmt::Write;

/// splitmix64: a small seeded generator (the same documents on every platform).
struct Rng(u64);

impl Rng {
    fn new(a: u64, b: u64) -> Rng {
        let mut r = Rng(a ^ b.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x5851_f42d_4c95_7f2d);
        r.next();
        r
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, n)`.
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }

    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A value in `[lo, hi)`, or now and then one of its limits exactly.
    fn value(&mut self, lo: f64, hi: f64) -> f64 {
        match self.below(12) {
            0 => lo,
            1 => hi,
            _ => lo + (hi - lo) * self.unit(),
        }
    }

    fn values(&mut self, n: usize, lo: f64, hi: f64) -> String {
        (0..n)
            .map(|_| format!("{}", self.value(lo, hi)))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// Both generators: `s` draws the structure and the values no patch carries (a joint's
/// axis and range, actuators, keyframes...: the same for every variant of a seed but a rare
/// structural change), `v` the values a patch may carry.
struct Gen {
    s: Rng,
    v: Rng,
    out: String,
    /// qpos widths of the joints written, in order (for keyframes).
    nq: usize,
    joints: Vec<String>,
    bodies: usize,
    geoms: usize,
    geometry: bool,
    /// Materials `m0`.. in the assets.
    materials: u64,
}

const GEOM_TYPES: [&str; 5] = ["sphere", "box", "capsule", "cylinder", "ellipsoid"];

impl Gen {
    /// The generator of geoms' sizes, frames, densities and masses: the values' for a seed
    /// that varies them (what body models carry, where a body qualifies), else the
    /// structure's (so the other values' patches are exercised too).
    fn geo(&mut self) -> &mut Rng {
        if self.geometry {
            &mut self.v
        } else {
            &mut self.s
        }
    }

    fn name(&mut self, prefix: &str, n: usize) -> String {
        // Some elements unnamed: only named ones are patched on an object of a scene, and
        // a document's unnamed ones by their index.
        if self.s.chance(0.85) {
            format!(r#" name="{prefix}{n}""#)
        } else {
            String::new()
        }
    }

    fn geom(&mut self, indent: &str, classes: bool) {
        self.geoms += 1;
        let kind = GEOM_TYPES[self.s.below(5) as usize];
        let name = self.name("g", self.geoms);
        let size = match kind {
            "sphere" => self.geo().values(1, 0.01, 0.2),
            "capsule" | "cylinder" => self.geo().values(2, 0.01, 0.2),
            _ => self.geo().values(3, 0.01, 0.2),
        };
        let mut attrs = format!(r#"{name} type="{kind}" size="{size}""#);
        if self.s.chance(0.5) {
            let _ = write!(attrs, r#" pos="{}""#, self.geo().values(3, -0.2, 0.2));
        }
        if self.s.chance(0.3) {
            let _ = write!(attrs, r#" euler="{}""#, self.geo().values(3, -1.5, 1.5));
        }
        if self.s.chance(0.6) {
            let _ = write!(attrs, r#" rgba="{} 1""#, self.v.values(3, 0.0, 1.0));
        }
        if self.s.chance(0.5) {
            let _ = write!(
                attrs,
                r#" friction="{} {} {}""#,
                self.v.value(0.1, 2.0),
                self.v.value(0.0, 0.1),
                self.v.value(0.0, 0.01)
            );
        }
        if self.s.chance(0.2) {
            let _ = write!(
                attrs,
                r#" solref="{} {}" solimp="{} {} {} 0.5 2""#,
                self.v.value(0.005, 0.05),
                self.v.value(0.5, 1.5),
                self.v.value(0.8, 0.9),
                self.v.value(0.91, 0.99),
                self.v.value(0.001, 0.01)
            );
        }
        if self.s.chance(0.2) {
            let _ = write!(
                attrs,
                r#" margin="{}" gap="{}""#,
                self.v.value(0.0, 0.01),
                self.v.value(0.0, 0.001)
            );
        }
        if self.materials > 0 && self.s.chance(0.3) {
            // Which material is a patch (the geom's matid).
            let _ = write!(attrs, r#" material="m{}""#, self.v.below(self.materials));
        }
        match self.s.below(3) {
            0 => {
                let _ = write!(attrs, r#" density="{}""#, self.geo().value(100.0, 5000.0));
            }
            1 => {
                let _ = write!(attrs, r#" mass="{}""#, self.geo().value(0.01, 5.0));
            }
            _ => {}
        }
        if self.s.chance(0.2) {
            let _ = write!(
                attrs,
                r#" contype="0" conaffinity="0" group="{}""#,
                1 + self.s.below(3)
            );
        }
        if classes && self.s.chance(0.3) {
            attrs.push_str(r#" class="soft""#);
        }
        let _ = writeln!(self.out, "{indent}<geom{attrs}/>");
    }

    /// A joint; `after_ball`: one of the body's joints before it is a ball, after which
    /// MuJoCo refuses a rotation (drawn anyway now and then: both must refuse it).
    fn joint(&mut self, indent: &str, free: bool, after_ball: bool) -> bool {
        let n = self.joints.len();
        let name = format!("j{n}");
        if free {
            let _ = writeln!(self.out, r#"{indent}<freejoint name="{name}"/>"#);
            self.nq += 7;
            self.joints.push(name);
            return false;
        }
        let mut kind = ["hinge", "slide", "ball", "hinge"][self.s.below(4) as usize];
        if after_ball && kind != "slide" && self.s.chance(0.9) {
            kind = "slide";
        }
        let mut attrs = format!(r#" name="{name}" type="{kind}""#);
        if kind != "ball" {
            let _ = write!(attrs, r#" axis="{}""#, self.s.values(3, 0.1, 1.0));
        }
        if self.s.chance(0.5) {
            let _ = write!(attrs, r#" damping="{}""#, self.v.value(0.0, 2.0));
        }
        if self.s.chance(0.4) {
            let _ = write!(attrs, r#" armature="{}""#, self.v.value(0.0, 0.1));
        }
        if self.s.chance(0.3) {
            let _ = write!(attrs, r#" stiffness="{}""#, self.v.value(0.0, 5.0));
        }
        if self.s.chance(0.3) {
            let _ = write!(attrs, r#" frictionloss="{}""#, self.v.value(0.0, 0.5));
        }
        if kind != "ball" && self.s.chance(0.4) {
            let lo = self.s.value(-1.0, 0.0);
            let _ = write!(
                attrs,
                r#" range="{lo} {}""#,
                lo + 0.1 + self.s.value(0.0, 1.0)
            );
        }
        let _ = writeln!(self.out, "{indent}<joint{attrs}/>");
        self.nq += if kind == "ball" { 4 } else { 1 };
        self.joints.push(name);
        kind == "ball"
    }

    fn body(&mut self, depth: usize, indent: &str, top: bool, classes: bool) {
        self.bodies += 1;
        let name = self.name("b", self.bodies);
        let pos = self.v.values(3, -0.5, 0.5);
        let mut attrs = format!(r#"{name} pos="{pos}""#);
        if self.s.chance(0.4) {
            let _ = write!(attrs, r#" quat="{}""#, self.v.values(4, 0.1, 1.0));
        }
        if classes && self.s.chance(0.2) {
            attrs.push_str(r#" childclass="soft""#);
        }
        let _ = writeln!(self.out, "{indent}<body{attrs}>");
        let inner = format!("{indent}  ");
        if top && self.s.chance(0.3) {
            self.joint(&inner, true, false);
        } else {
            let mut ball = false;
            for _ in 0..self.s.below(3) {
                ball |= self.joint(&inner, false, ball);
            }
        }
        if self.s.chance(0.2) {
            let _ = writeln!(
                self.out,
                r#"{inner}<inertial pos="{}" mass="{}" diaginertia="{}"/>"#,
                self.s.values(3, -0.05, 0.05),
                self.v.value(0.05, 3.0),
                self.v.values(3, 0.002, 0.004)
            );
        }
        for _ in 0..1 + self.s.below(3) {
            self.geom(&inner, classes);
        }
        if self.s.chance(0.3) {
            let _ = writeln!(
                self.out,
                r#"{inner}<site name="s{}" pos="{}" size="0.01" rgba="{} 1"/>"#,
                self.bodies,
                self.s.values(3, -0.1, 0.1),
                self.v.values(3, 0.0, 1.0)
            );
        }
        if self.s.chance(0.2) {
            let _ = writeln!(
                self.out,
                r#"{inner}<frame pos="{}" euler="{}">"#,
                self.s.values(3, -0.2, 0.2),
                self.s.values(3, -1.0, 1.0)
            );
            self.geom(&format!("{inner}  "), classes);
            let _ = writeln!(self.out, "{inner}</frame>");
        }
        if depth < 2 {
            for _ in 0..self.s.below(3) {
                self.body(depth + 1, &inner, false, classes);
            }
        }
        let _ = writeln!(self.out, "{indent}</body>");
    }
}

/// A random MJCF model: structure from `seed`, values from `(seed, variant)`; variants of a
/// seed share their structure but for about one in eight, which changes one thing.
///
/// Drawn: `<option>` values, materials, default classes with `class` and `childclass`, a
/// light and a camera, a tree of named and unnamed bodies (free, hinge, slide and ball
/// joints with their values, primitives of every kind with sizes, frames, colours,
/// frictions, solver parameters, margins, materials, densities or masses, visual geoms,
/// some explicit `<inertial>`s, coloured sites, `<frame>`s), motors and position actuators,
/// keyframes, and now and then a `<body>` directly under `<mujoco>` (a file meant to be
/// included, which MuJoCo compiles to the world alone). Values include their ranges'
/// limits. Not every document is one MuJoCo accepts: a cache must then refuse it too.
///
/// ```
/// use mjcf_forge::fuzzing::random_mjcf;
/// let (a, b) = (random_mjcf(7, 0), random_mjcf(7, 1));
/// assert!(a.starts_with("<mujoco") && a != b);
/// assert_eq!(random_mjcf(7, 0), a);
/// ```
pub fn random_mjcf(seed: u64, variant: u64) -> String {
    let mut s = Rng::new(seed, 0);
    // One structural change in some variants: the structure generator takes another turn.
    let changed = variant > 0 && Rng::new(seed, variant).below(8) == 0;
    if changed {
        s = Rng::new(seed, variant.wrapping_mul(31).wrapping_add(1));
    }
    let mut g = Gen {
        s,
        v: Rng::new(seed.wrapping_mul(0x2545_f491_4f6c_dd1d), variant),
        out: String::new(),
        nq: 0,
        joints: Vec::new(),
        bodies: 0,
        geoms: 0,
        geometry: false,
        materials: 0,
    };
    g.geometry = g.s.chance(0.3);
    let classes = g.s.chance(0.4);
    let _ = writeln!(g.out, r#"<mujoco model="random{seed}">"#);
    if g.s.chance(0.3) {
        g.out.push_str("  <compiler angle=\"radian\"/>\n");
    }
    let fluid = if g.s.chance(0.5) {
        format!(
            r#" impratio="{}" tolerance="{}" wind="{}" density="{}" viscosity="{}""#,
            g.v.value(1.0, 10.0),
            g.v.value(1e-10, 1e-6),
            g.v.values(3, -1.0, 1.0),
            g.v.value(0.0, 1.3),
            g.v.value(0.0, 2e-5)
        )
    } else {
        String::new()
    };
    let _ = writeln!(
        g.out,
        r#"  <option timestep="{}" gravity="0 0 {}"{fluid}/>"#,
        g.v.value(0.001, 0.01),
        g.v.value(-12.0, -1.0)
    );
    g.materials = g.s.below(4);
    if g.materials > 0 {
        g.out.push_str("  <asset>\n");
        for k in 0..g.materials {
            let _ = writeln!(
                g.out,
                r#"    <material name="m{k}" rgba="{} 1" specular="{}" shininess="{}" reflectance="{}" emission="{}"/>"#,
                g.v.values(3, 0.0, 1.0),
                g.v.value(0.0, 1.0),
                g.v.value(0.0, 1.0),
                g.v.value(0.0, 1.0),
                g.v.value(0.0, 1.0)
            );
        }
        g.out.push_str("  </asset>\n");
    }
    if classes {
        let _ = writeln!(
            g.out,
            r#"  <default><default class="soft"><geom rgba="{} 1" friction="{}"/><joint damping="{}"/></default></default>"#,
            g.s.values(3, 0.0, 1.0),
            g.s.value(0.2, 1.5),
            g.s.value(0.0, 1.0)
        );
    }
    g.out.push_str("  <worldbody>\n");
    if g.s.chance(0.6) {
        g.out
            .push_str("    <geom name=\"floor\" type=\"plane\" size=\"2 2 0.1\"/>\n");
        let _ = writeln!(
            g.out,
            r#"    <light name="sun" pos="0 0 3" diffuse="{}" specular="{}" ambient="{}" attenuation="1 {} 0"/>"#,
            g.v.values(3, 0.0, 1.0),
            g.v.values(3, 0.0, 0.5),
            g.v.values(3, 0.0, 0.3),
            g.v.value(0.0, 0.1)
        );
        let _ = writeln!(
            g.out,
            r#"    <camera name="eye" pos="1.5 0 1" xyaxes="0 1 0 -0.5 0 1" fovy="{}"/>"#,
            g.v.value(30.0, 90.0)
        );
    }
    for _ in 0..1 + g.s.below(3) {
        g.body(0, "    ", true, classes);
    }
    g.out.push_str("  </worldbody>\n");
    let hinges: Vec<String> = g.joints.clone();
    if !hinges.is_empty() && g.s.chance(0.5) {
        g.out.push_str("  <actuator>\n");
        for _ in 0..1 + g.s.below(2) {
            let j = &hinges[g.s.below(hinges.len() as u64) as usize];
            if g.s.chance(0.5) {
                let _ = writeln!(
                    g.out,
                    r#"    <motor joint="{j}" gear="{}" ctrlrange="-1 1"/>"#,
                    g.s.value(0.5, 50.0)
                );
            } else {
                let _ = writeln!(
                    g.out,
                    r#"    <position joint="{j}" kp="{}"/>"#,
                    g.v.value(1.0, 100.0)
                );
            }
        }
        g.out.push_str("  </actuator>\n");
    }
    if g.nq > 0 && g.s.chance(0.3) {
        let qpos = g.s.values(g.nq, -0.1, 0.1);
        let _ = writeln!(
            g.out,
            r#"  <keyframe><key name="k" time="{}" qpos="{qpos}"/></keyframe>"#,
            g.s.value(0.0, 1.0)
        );
    }
    if g.s.chance(0.15) {
        // A file meant to be included into a <worldbody>: MuJoCo leaves this out.
        let _ = writeln!(
            g.out,
            r#"  <body name="loose" pos="{}"><geom size="0.05"/></body>"#,
            g.s.values(3, -1.0, 1.0)
        );
    }
    g.out.push_str("</mujoco>\n");
    g.out
}

/// [`random_mjcf`] as files to write into one folder, `(file name, text)`, the model
/// `model.xml` first: for some seeds its first top-level body moved into `part.xml`, which
/// the model's `<worldbody>` includes where the body was (MuJoCo's `<include>`).
///
/// ```
/// use mjcf_forge::fuzzing::random_mjcf_files;
/// let with_include = (0..40).find(|&s| random_mjcf_files(s, 0).len() == 2).unwrap();
/// let files = random_mjcf_files(with_include, 0);
/// assert!(files[0].1.contains(r#"<include file="part.xml"/>"#));
/// ```
pub fn random_mjcf_files(seed: u64, variant: u64) -> Vec<(String, String)> {
    let text = random_mjcf(seed, variant);
    let lines: Vec<&str> = text.lines().collect();
    let start = lines.iter().position(|l| l.starts_with("    <body"));
    let end = lines.iter().position(|l| *l == "    </body>");
    match (start, end) {
        (Some(a), Some(b)) if a < b && Rng::new(seed, 0x1c1d).chance(0.3) => {
            let mut model: Vec<&str> = lines[..a].to_vec();
            model.push(r#"    <include file="part.xml"/>"#);
            model.extend(&lines[b + 1..]);
            let part = format!("<mujoco>\n{}\n</mujoco>\n", lines[a..=b].join("\n"));
            vec![
                ("model.xml".to_string(), model.join("\n") + "\n"),
                ("part.xml".to_string(), part),
            ]
        }
        _ => vec![("model.xml".to_string(), text)],
    }
}

/// A random scene description and the model files it names (file name, MJCF text), to be
/// written into one folder: see [`random_scene`].
#[derive(Debug, Clone)]
pub struct RandomScene {
    /// The scene file's TOML.
    pub toml: String,
    /// The model files it names, each `(file name, text)`.
    pub files: Vec<(String, String)>,
}

/// A random scene (the differential tests' scenes): an arena with a table, one to three
/// object groups whose pools hold random objects (named and unnamed geoms of every
/// primitive kind, densities or masses, some with an inner body or an `<inertial>`),
/// counts fixed or drawn, placements, and randomizers of random kinds over them (colours,
/// frictions, solver parameters, masses scaled or set, sizes, the light and the camera),
/// sometimes with `discard_visual`.
///
/// ```
/// use mjcf_forge::fuzzing::random_scene;
/// let scene = random_scene(5);
/// assert!(scene.toml.contains("[[objects]]"));
/// assert!(scene.files.iter().any(|(name, _)| name == "arena.xml"));
/// ```
pub fn random_scene(seed: u64) -> RandomScene {
    let mut r = Rng::new(seed, 0x5ce4e);
    let mut files = vec![(
        "arena.xml".to_string(),
        format!(
            r#"<mujoco model="arena">
  <worldbody>
    <light name="sun" pos="0 0 3" dir="0 0 -1" diffuse="0.8 0.8 0.8"/>
    <camera name="front" pos="1.6 0 1.4" xyaxes="0 1 0 -0.6 0 0.8" fovy="45"/>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <body name="table" pos="0 0 0.4">
      <geom name="top" type="box" size="0.5 0.6 0.025" pos="0 0 0.375" friction="{} 0.005 0.0001"/>
      <site name="table_top" pos="0 0 0.4" size="0.01"/>
    </body>
  </worldbody>
</mujoco>
"#,
            r.value(0.5, 1.5)
        ),
    )];
    let mut toml = format!("seed = {}\nbase = \"arena.xml\"\n", r.below(1000));
    if r.chance(0.2) {
        toml.push_str("discard_visual = true\n");
    }
    let groups = 1 + r.below(3) as usize;
    for g in 0..groups {
        let mut pool = Vec::new();
        for k in 0..1 + r.below(3) {
            let name = format!("object_{g}_{k}.xml");
            let mut body = String::new();
            for n in 0..1 + r.below(3) {
                let kind = GEOM_TYPES[r.below(5) as usize];
                let size = match kind {
                    "sphere" => r.values(1, 0.01, 0.05),
                    "capsule" | "cylinder" => r.values(2, 0.01, 0.05),
                    _ => r.values(3, 0.01, 0.05),
                };
                let named = if r.chance(0.8) {
                    format!(r#" name="g{n}""#)
                } else {
                    String::new()
                };
                let weight = if r.chance(0.7) {
                    format!(r#" density="{}""#, r.value(200.0, 2000.0))
                } else {
                    format!(r#" mass="{}""#, r.value(0.05, 1.0))
                };
                let _ = writeln!(
                    body,
                    r#"      <geom{named} type="{kind}" size="{size}" pos="{}" rgba="{} 1"{weight}/>"#,
                    r.values(3, -0.02, 0.02),
                    r.values(3, 0.0, 1.0)
                );
            }
            if r.chance(0.2) {
                let _ = writeln!(
                    body,
                    r#"      <body name="inner" pos="0 0 0.03"><geom name="cap" type="sphere" size="{}"/></body>"#,
                    r.value(0.01, 0.03)
                );
            }
            let inertial = if r.chance(0.2) {
                format!(
                    "      <inertial pos=\"0 0 0\" mass=\"{}\" diaginertia=\"0.001 0.001 0.001\"/>\n",
                    r.value(0.1, 1.0)
                )
            } else {
                String::new()
            };
            files.push((
                name.clone(),
                format!(
                    "<mujoco model=\"object\">\n  <worldbody>\n    <body name=\"obj\">\n{inertial}{body}    </body>\n  </worldbody>\n</mujoco>\n"
                ),
            ));
            pool.push(format!("\"{name}\""));
        }
        let count = if r.chance(0.5) {
            format!("{}", 1 + r.below(2))
        } else {
            "[0, 2]".to_string()
        };
        let _ = write!(
            toml,
            "\n[[objects]]\nname = \"group{g}\"\npool = [{}]\ncount = {count}\nprefix = \"group{g}_{{i}}_\"\n",
            pool.join(", ")
        );
        match r.below(3) {
            0 => toml.push_str("write_inertials = false\n"),
            1 => toml.push_str("name_unnamed_geoms = true\n"),
            _ => {}
        }
        let _ = write!(
            toml,
            "[objects.placement]\non = \"table_top\"\nx = [-0.4, 0.4]\ny = [-0.5, 0.5]\ngap = 0.005\nrotation = {{ axis = \"z\", range_deg = [0, 360] }}\n"
        );
    }
    let randomizers: [&str; 9] = [
        "kind = \"geom\"\nattribute = \"rgba\"\ncomponents = [0, 1, 2]\nuniform = [[0, 0, 0], [1, 1, 1]]",
        "kind = \"geom\"\nattribute = \"friction\"\nscale = true\ncomponents = [0]\nuniform = [0.5, 1.5]",
        "kind = \"geom\"\nattribute = \"solref\"\nuniform = [[0.01, 0.8], [0.03, 1.2]]",
        "kind = \"geom\"\nattribute = \"margin\"\nuniform = [0, 0.002]",
        "kind = \"body\"\nattribute = \"mass\"\nscale = true\nlog_uniform = [0.5, 2.0]",
        "kind = \"geom\"\nattribute = \"size\"\nscale = true\nuniform = [0.8, 1.2]",
        "kind = \"light\"\nattribute = \"diffuse\"\nuniform = [[0.3, 0.3, 0.3], [1, 1, 1]]",
        "kind = \"camera\"\nattribute = \"fovy\"\nuniform = [40, 60]",
        "kind = \"geom\"\nattribute = \"density\"\nscale = true\nuniform = [0.5, 2.0]",
    ];
    for (k, body) in randomizers.iter().enumerate() {
        if !r.chance(0.35) {
            continue;
        }
        let part = if (6..8).contains(&k) {
            String::new()
        } else {
            format!("part = \"group{}\"\n", r.below(groups as u64))
        };
        let _ = write!(toml, "\n[[randomize]]\n{part}{body}\n");
    }
    RandomScene { toml, files }
}
