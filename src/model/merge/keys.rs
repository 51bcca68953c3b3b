//! Keyframes across a merge: each key rewritten onto the merged model's joints, actuators and
//! mocap bodies, a part's values landing on its own objects and everything else taking its
//! default, and keys of the same name fused when asked.

use ahash::AHashMap;

use super::MergeOptions;
use super::angles::angles_checked;
use super::fmt_num;
use super::layout::{Layout, Offsets, actuator_states, joint_widths};
use crate::document::import::NodeMap;
use crate::document::tree::{Node, Tree};
use crate::document::{Document, Section};
use crate::error::{ErrorKind, Errors};
use crate::model::geometry::{self, Angles};

/// One keyframe: its element and its vectors as written (number tokens kept as text).
pub(super) struct Key {
    node: Node,
    name: Option<String>,
    vectors: [Option<Vec<String>>; 6],
}

const KEY_VECTORS: [&str; 6] = ["qpos", "qvel", "act", "ctrl", "mpos", "mquat"];

pub(super) fn keys_of(doc: &Document) -> Vec<Key> {
    let Some(section) = doc.find_section(Section::Keyframe) else {
        return Vec::new();
    };
    doc.elements(section)
        .filter(|&k| doc.tag(k) == "key")
        .map(|k| Key {
            node: k,
            name: doc.attr(k, "name").map(str::to_string),
            vectors: KEY_VECTORS.map(|v| {
                doc.attr(k, v)
                    .map(|s| s.split_ascii_whitespace().map(str::to_string).collect())
            }),
        })
        .collect()
}

/// How many keys `<size nkey="N">` adds to the `<key>` elements written: MuJoCo allocates
/// the larger of N and their number, the ones added coming after the written ones, each
/// holding the model's defaults as an empty `<key/>` does (checked with MuJoCo 3.17.0 and
/// 4.0.0; Gymnasium's humanoid has `nkey="5"` and no `<key>`).
pub(super) fn implicit_keys(doc: &Document) -> usize {
    let nkey = doc
        .elements(doc.root)
        .filter(|&n| doc.tag(n) == "size")
        .filter_map(|n| doc.attr(n, "nkey"))
        .last()
        .and_then(|v| v.trim().parse::<usize>().ok())
        .unwrap_or(0);
    nkey.saturating_sub(keys_of(doc).len())
}

/// Which document a state-vector item came from, and its index in that document's layout.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Origin {
    Base(usize),
    Part(usize),
}

/// `qpos0` of a free joint whose body MuJoCo aligns with its inertial frame, as MuJoCo
/// compiles `doc` alone (a free body is in the world, where merging does not move it).
#[cfg(mjcf_mujoco)]
fn aligned_free_qpos0(doc: &Document, joint: Node) -> Result<Vec<String>, String> {
    crate::mujoco::free_joint_qpos0(doc, joint)
        .map(|q| q.iter().map(|&x| format!("{x:?}")).collect())
        .map_err(|e| format!("the initial pose of an aligned free body: {e}"))
}

/// Without MuJoCo the inertial frame a free body is aligned with is not known exactly.
#[cfg(not(mjcf_mujoco))]
fn aligned_free_qpos0(_: &Document, _: Node) -> Result<Vec<String>, String> {
    Err(
        "MuJoCo aligns this free body with its inertial frame (alignfree, or the \
         <freejoint>'s align), so its initial pose in the keyframes is known only to MuJoCo's \
         compiler: remapping keyframes over it needs a build with the `mujoco` feature"
            .to_string(),
    )
}

impl Document {
    /// Writes the keys that `<size nkey>` adds ([`implicit_keys`]) as empty `<key/>`s and
    /// drops `nkey`: a merge keeps the base's `<size>` only, and adds keys of its own.
    pub(super) fn write_implicit_keys(&mut self) {
        let n = implicit_keys(self);
        if n == 0 {
            return;
        }
        let section = self.section(Section::Keyframe);
        for _ in 0..n {
            self.append_element(section, "key", &[]);
        }
        let sizes: Vec<Node> = self
            .elements(self.root)
            .filter(|&n| self.tag(n) == "size")
            .collect();
        for s in sizes {
            self.remove_attr(s, "nkey");
        }
    }

    /// The world pose of a body as written (through enclosing frames), quaternion normalized.
    fn written_world_pose(
        &self,
        body: Node,
        angles: &Angles,
    ) -> Result<([f64; 3], [f64; 4]), String> {
        let mut chain = vec![body];
        let mut p = self.parent(body);
        while let Some(n) = p {
            match self.tag(n) {
                "frame" => chain.push(n),
                "worldbody" => break,
                other => return Err(format!("a free or mocap body inside <{other}>")),
            }
            p = self.parent(n);
        }
        let mut world = geometry::Pose::default();
        for &n in chain.iter().rev() {
            let pose = geometry::element_pose(self, n, angles).map_err(|e| e.to_string())?;
            world = world.compose(&pose);
        }
        let q = world.quat;
        let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        Ok((world.pos, q.map(|x| x / norm)))
    }

    /// What a state-vector item holds when no key gives it: `qpos0` for joints (the joint's
    /// `ref`, the unit quaternion, or a free body's written pose), zero velocities, controls
    /// and activations, and a mocap body's written pose.
    fn default_tokens(
        &self,
        v: usize,
        item: Node,
        width: usize,
        angles: &Angles,
    ) -> Result<Vec<String>, String> {
        let zeros = || vec!["0".to_string(); width];
        match v {
            0 => {
                let (w, _) = joint_widths(self, item);
                match w {
                    7 if self.aligns_free_body(item) => aligned_free_qpos0(self, item),
                    7 => {
                        let body = self.parent(item).ok_or("joint without a body")?;
                        let (p, q) = self.written_world_pose(body, angles)?;
                        Ok(p.iter().chain(q.iter()).map(|&x| fmt_num(x)).collect())
                    }
                    4 => Ok(["1", "0", "0", "0"].map(String::from).to_vec()),
                    _ => {
                        let r: f64 = self
                            .attr(item, "ref")
                            .and_then(|r| r.trim().parse().ok())
                            .unwrap_or(0.0);
                        let hinge =
                            self.attr(item, "type").map(str::trim).unwrap_or("hinge") == "hinge";
                        let r = if hinge && angles.degrees {
                            r * std::f64::consts::PI / 180.0
                        } else {
                            r
                        };
                        Ok(vec![fmt_num(r)])
                    }
                }
            }
            4 | 5 => {
                let (p, q) = self.written_world_pose(item, angles)?;
                Ok(if v == 4 {
                    p.iter().map(|&x| fmt_num(x)).collect()
                } else {
                    q.iter().map(|&x| fmt_num(x)).collect()
                })
            }
            _ => Ok(zeros()),
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn remap_keys(
        &mut self,
        base_layout: &Layout,
        base_keys: &[Key],
        part: &Document,
        part_layout: &Layout,
        part_keys: &[Key],
        map: &NodeMap,
        options: &MergeOptions,
    ) -> Result<(), Errors> {
        for (doc, layout) in [(&*self, base_layout), (part, part_layout)] {
            if let Some((n, why)) = &layout.opaque {
                return Err(doc
                    .error_at(
                        *n,
                        ErrorKind::Invalid(format!("cannot remap keyframes: {why}")),
                    )
                    .into());
            }
        }
        let need_act = base_keys
            .iter()
            .chain(part_keys)
            .any(|k| k.vectors[2].is_some());
        let located = |doc: &Document, n: Node, e: String| -> Errors {
            doc.error_at(n, ErrorKind::Invalid(e)).into()
        };
        let base_off =
            Offsets::of(self, base_layout, need_act).map_err(|e| located(self, self.root, e))?;
        let part_off =
            Offsets::of(part, part_layout, need_act).map_err(|e| located(part, part.root, e))?;
        // Keys must fit their own model, as MuJoCo requires.
        let mut errors = Vec::new();
        for (doc, keys, off) in [(&*self, base_keys, &base_off), (part, part_keys, &part_off)] {
            for k in keys {
                // MuJoCo 4.0.0's plastic state (one block per plastic joint, tendon and flex)
                // has a layout we do not model: refused rather than copied onto the wrong slots.
                if doc.attr(k.node, "plastic").is_some() {
                    errors.push(
                        doc.error_at(
                            k.node,
                            ErrorKind::Invalid(
                                "key plastic (MuJoCo 4.0's plastic state) cannot be remapped onto \
                             the merged model; remove it before merging"
                                    .to_string(),
                            ),
                        ),
                    );
                }
                for (v, vec) in k.vectors.iter().enumerate() {
                    if let Some(vec) = vec
                        && vec.len() != off.len(v)
                    {
                        errors.push(doc.error_at(
                            k.node,
                            ErrorKind::Invalid(format!(
                                "key {} has {} values, the model needs {}",
                                KEY_VECTORS[v],
                                vec.len(),
                                off.len(v)
                            )),
                        ));
                    }
                }
            }
        }
        if !errors.is_empty() {
            return Err(Errors(errors));
        }

        // Where each item of the merged model comes from.
        let merged = Layout::of(self);
        let angles = angles_checked(self)?;
        let mut from_part: AHashMap<Node, usize> = AHashMap::new();
        let mut from_base: AHashMap<Node, usize> = AHashMap::new();
        for items in [
            &part_layout.joints,
            &part_layout.actuators,
            &part_layout.mocap,
        ] {
            for (j, n) in items.iter().enumerate() {
                if let Some(m) = map.get(*n) {
                    from_part.insert(m, j);
                }
            }
        }
        for items in [
            &base_layout.joints,
            &base_layout.actuators,
            &base_layout.mocap,
        ] {
            for (j, n) in items.iter().enumerate() {
                from_base.insert(*n, j);
            }
        }
        let origin = |n: Node| -> Option<Origin> {
            from_base
                .get(&n)
                .map(|&i| Origin::Base(i))
                .or_else(|| from_part.get(&n).map(|&i| Origin::Part(i)))
        };

        // Which keys become one: each base key, with the part key fused into it if asked.
        let mut groups: Vec<(Option<&Key>, Option<&Key>)> =
            base_keys.iter().map(|k| (Some(k), None)).collect();
        for pk in part_keys {
            let fused = options.fuse_keys
                && pk.name.as_deref().is_some_and(|n| {
                    let stripped = n.strip_prefix(options.part_prefix.as_str()).unwrap_or(n);
                    groups.iter().any(|(b, p)| {
                        p.is_none() && b.and_then(|b| b.name.as_deref()) == Some(stripped)
                    })
                });
            if fused {
                let n = pk.name.as_deref().unwrap_or_default();
                let stripped = n.strip_prefix(options.part_prefix.as_str()).unwrap_or(n);
                if let Some(g) = groups.iter_mut().find(|(b, p)| {
                    p.is_none() && b.and_then(|b| b.name.as_deref()) == Some(stripped)
                }) {
                    g.1 = Some(pk);
                }
            } else {
                groups.push((None, Some(pk)));
            }
        }

        let mut new_keys: Vec<Vec<(String, String)>> = Vec::new();
        for (bk, pk) in &groups {
            let mut attrs: Vec<(String, String)> = Vec::new();
            let first = bk.or(*pk).expect("a group has a key");
            let first_doc: &Document = if bk.is_some() { self } else { part };
            for (k, v) in first_doc.attrs(first.node) {
                if !KEY_VECTORS.contains(&k) {
                    attrs.push((k.to_string(), v.to_string()));
                }
            }
            for (v, vector_name) in KEY_VECTORS.iter().enumerate() {
                if bk.and_then(|k| k.vectors[v].as_ref()).is_none()
                    && pk.and_then(|k| k.vectors[v].as_ref()).is_none()
                {
                    continue;
                }
                let items: &[Node] = match v {
                    0 | 1 => &merged.joints,
                    2 | 3 => &merged.actuators,
                    _ => &merged.mocap,
                };
                let mut tokens: Vec<String> = Vec::new();
                for &item in items {
                    let given = match origin(item) {
                        Some(Origin::Base(i)) => {
                            bk.and_then(|k| k.vectors[v].as_ref()).map(|vec| {
                                let (at, w) = base_off.vector(v)[i];
                                vec[at..at + w].to_vec()
                            })
                        }
                        Some(Origin::Part(i)) => {
                            pk.and_then(|k| k.vectors[v].as_ref()).map(|vec| {
                                let (at, w) = part_off.vector(v)[i];
                                vec[at..at + w].to_vec()
                            })
                        }
                        None => None,
                    };
                    match given {
                        Some(t) => tokens.extend(t),
                        None => {
                            let width = match v {
                                0 => joint_widths(self, item).0,
                                1 => joint_widths(self, item).1,
                                2 => actuator_states(self, item)
                                    .map_err(|e| located(self, item, e))?,
                                3 => 1,
                                4 => 3,
                                _ => 4,
                            };
                            let d = self
                                .default_tokens(v, item, width, &angles)
                                .map_err(|e| located(self, item, e))?;
                            tokens.extend(d);
                        }
                    }
                }
                attrs.push((vector_name.to_string(), tokens.join(" ")));
            }
            new_keys.push(attrs);
        }

        // Replace the keys: the base's in place of the old ones, the part's after them.
        let section = self.section(Section::Keyframe);
        let origins: Vec<Option<Node>> = groups.iter().map(|(b, _)| b.map(|k| k.node)).collect();
        let old: Vec<Node> = self
            .elements(section)
            .filter(|&k| self.tag(k) == "key")
            .collect();
        for (attrs, base_node) in new_keys.iter().zip(origins) {
            let refs: Vec<(&str, &str)> = attrs
                .iter()
                .map(|(k, v)| (k.as_str(), v.as_str()))
                .collect();
            let key = self.append_element(section, "key", &refs);
            if let Some(b) = base_node {
                let span = self.spans[Tree::index(b)];
                self.set_span(key, span);
            }
        }
        for k in old {
            self.remove(k);
        }
        Ok(())
    }
}
