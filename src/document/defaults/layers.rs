//! A material's textures by role: what a class's `<material>` row and its `<layer>` children
//! pass on, and the `<layer>` children a resolved material is written with.

use super::Resolver;
use super::classes::AttrSet;
use crate::document::names::Sym;
use crate::document::tree::{Node, StrRef};
use crate::error::ErrorKind;

/// The texture roles a `<layer role=...>` may name, in MuJoCo's `mjtTextureRole` order. The
/// first role there, `user`, is refused by the reader of MuJoCo 3.17.0 and 4.0.0 (`unknown
/// layer role 'user'`), as is any other word, even with white space around a known one.
const TEXTURE_ROLES: [&str; 9] = [
    "rgb",
    "occlusion",
    "roughness",
    "metallic",
    "normal",
    "opacity",
    "emissive",
    "rgba",
    "orm",
];
/// The role a material's `texture` attribute sets.
pub(super) const RGB: usize = 0;

/// A material's textures by role, as MuJoCo keeps them (one name per role) and as a class's
/// material passes them on. Checked with MuJoCo 3.17.0 and 4.0.0
/// (corpora/features/default_material_layers.xml):
/// - a material starts from its class's textures, a nested class from its parent's (taken
///   when the parent's own rows have been read, like every other default value);
/// - its `texture` attribute sets the `rgb` role, then each `<layer>` sets its role, a later
///   one replacing an earlier one; roles it does not name keep the class's textures, so its
///   own layers add to the class's, role by role;
/// - an empty name (`texture=""`) leaves that role without a texture;
/// - one element with both a `texture` attribute and `<layer>` children is refused (in a
///   class too), but a class's `texture` and an element's layers combine, and the reverse.
///
/// `None`: the role was never given.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Layers(pub(super) [Option<StrRef>; TEXTURE_ROLES.len()]);

impl Layers {
    pub(super) fn is_empty(&self) -> bool {
        self.0.iter().all(Option::is_none)
    }

    /// Whether no role but `rgb` was given (so the `texture` attribute can say it all).
    pub(super) fn only_rgb(&self) -> bool {
        self.0[RGB + 1..].iter().all(Option::is_none)
    }
}

impl Resolver<'_> {
    /// Moves the `texture` attribute out of a material's attribute set into its `rgb` role.
    pub(super) fn take_texture(&self, set: &mut AttrSet, layers: &mut Layers) {
        if let Some(t) = set.get(self.syms.texture) {
            set.remove(self.syms.texture);
            layers.0[RGB] = Some(t);
        }
    }

    /// Reads the `<layer>` children of a material (or of a class's material row) onto
    /// `layers`, in order; returns whether it has any. `own` are its attributes. What MuJoCo
    /// 3.17.0 and 4.0.0 refuse is reported (a `texture` attribute next to layers, an unknown
    /// or missing role, a missing texture): inlined into a material that is valid on its
    /// own, such a row would no longer be refused.
    pub(super) fn read_layers(
        &mut self,
        node: Node,
        own: &[(Sym, StrRef)],
        layers: &mut Layers,
    ) -> bool {
        let texture_attr = own.iter().any(|(n, _)| *n == self.syms.texture);
        let mut any = false;
        let kids: Vec<Node> = self
            .doc
            .elements(node)
            .filter(|&k| self.doc.tag_sym(k) == Some(self.syms.layer))
            .collect();
        for layer in kids {
            if texture_attr && !any {
                let e = self.doc.error_at(
                    layer,
                    ErrorKind::Invalid(
                        "a material with a 'texture' attribute cannot have <layer> children".into(),
                    ),
                );
                self.errors.push(e);
            }
            any = true;
            let role = self.doc.attr_sym(layer, self.syms.role);
            let texture = self
                .doc
                .attr_slice(layer)
                .iter()
                .find(|a| a.name == self.syms.texture)
                .map(|a| a.value);
            let problem = match (role, texture) {
                (None, _) => Some("<layer> needs a 'role'".to_string()),
                (_, None) => Some("<layer> needs a 'texture'".to_string()),
                (Some(r), Some(t)) => match TEXTURE_ROLES.iter().position(|k| *k == r) {
                    Some(i) => {
                        layers.0[i] = Some(t);
                        None
                    }
                    None => Some(format!("unknown layer role '{r}'")),
                },
            };
            if let Some(msg) = problem {
                let e = self.doc.error_at(layer, ErrorKind::Invalid(msg));
                self.errors.push(e);
            }
        }
        any
    }

    /// Replaces a material's `<layer>` children with one per role that has a texture, in
    /// role order (an empty name is no texture: nothing to write).
    pub(super) fn write_layers(&mut self, node: Node, layers: &Layers) {
        let old: Vec<Node> = self
            .doc
            .elements(node)
            .filter(|&k| self.doc.tag_sym(k) == Some(self.syms.layer))
            .collect();
        for k in old {
            self.doc.remove(k);
        }
        for (role, texture) in TEXTURE_ROLES.iter().zip(layers.0) {
            let Some(texture) = texture.filter(|t| !self.doc.str(*t).is_empty()) else {
                continue;
            };
            let layer = self.doc.new_element(self.syms.layer, Some(node));
            let role = self.doc.push_str(role);
            self.doc.replace_attrs(
                layer,
                &[
                    crate::document::tree::Attr {
                        name: self.syms.role,
                        value: role,
                    },
                    crate::document::tree::Attr {
                        name: self.syms.texture,
                        value: texture,
                    },
                ],
            );
            self.doc.tree.append(node, layer);
        }
    }
}
