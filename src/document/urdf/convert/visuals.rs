//! URDF materials and colours, and the visuals kept by `UrdfOptions::visuals`.

use ahash::AHashSet;

use super::super::robot::Robot;
use super::Writer;
use crate::document::tree::Node;

impl<'r> Writer<'r> {
    /// Every `<material>` with a name and a `<color>`, anywhere in the file (the first
    /// of a name wins), as the importer registers them before reading links.
    pub(super) fn register_materials(&mut self, root: Node) {
        let raw = self.raw;
        for m in raw.descendants(root) {
            if !raw.is_element(m) || raw.tag(m) != "material" {
                continue;
            }
            let Some(name) = raw.attr(m, "name") else {
                continue;
            };
            if self.materials.contains_key(name) {
                continue;
            }
            if let Some(rgba) = self
                .sub(m, "color")
                .and_then(|color| self.required(color, "rgba"))
            {
                self.materials.insert(name, rgba);
            }
        }
    }

    /// The colour a `<visual>`'s material gives, if any.
    pub(super) fn visual_rgba(&mut self, visual: Node) -> Option<&'r str> {
        let m = self.sub(visual, "material")?;
        if let Some(color) = self.sub(m, "color") {
            return self.required(color, "rgba");
        }
        let name = self.required(m, "name")?;
        self.materials.get(name).copied()
    }

    /// The names the collision geoms get when visuals are dropped.
    pub(super) fn names_without_visuals(&mut self, robot: &Robot<'r>) -> AHashSet<String> {
        let raw = self.raw;
        let mut used = AHashSet::new();
        for link in &robot.links {
            let mut name = "";
            for g in raw
                .elements(link.node)
                .filter(|&g| raw.tag(g) == "collision")
            {
                if let Some(n) = raw.attr(g, "name") {
                    name = n;
                }
                used.insert(name.to_string());
            }
        }
        used.remove("");
        used
    }

    /// The names the collision meshes get (the importer's naming by stem and scale, links
    /// in file order), so that no kept visual's mesh takes one.
    pub(super) fn collision_mesh_names(&mut self, robot: &Robot<'r>) -> AHashSet<String> {
        let raw = self.raw;
        let mut meshes = super::MeshNames::default();
        let mut names = AHashSet::new();
        for link in &robot.links {
            for g in raw
                .elements(link.node)
                .filter(|&g| raw.tag(g) == "collision")
            {
                let Some(mesh) = self
                    .sub(g, "geometry")
                    .and_then(|geo| self.sub(geo, "mesh"))
                    .filter(|&m| raw.attr(m, "filename").is_some())
                else {
                    continue;
                };
                let file = raw.attr(mesh, "filename").unwrap_or_default();
                let stem = super::strip_ext(super::strip_path(file)).to_string();
                let scale = raw
                    .attr(mesh, "scale")
                    .and_then(|t| {
                        let v: Vec<f64> = t
                            .split_ascii_whitespace()
                            .filter_map(|x| x.parse().ok())
                            .collect();
                        (v.len() == 3).then(|| [v[0], v[1], v[2]])
                    })
                    .unwrap_or([1.0; 3]);
                names.insert(meshes.name(&stem, scale).0);
            }
        }
        names
    }

    /// A visual kept by [`UrdfOptions::visuals`]: its own name if no collision geom and no
    /// earlier visual has it, its material as a MuJoCo material.
    pub(super) fn kept_visual(&mut self, visual: Node, body: Node) {
        let raw = self.raw;
        let Some(g) = self.geom(visual, body, false) else {
            return;
        };
        if let Some(n) = raw
            .attr(visual, "name")
            .filter(|n| !self.collision_names.contains(*n))
            && self.geom_names.insert(n.to_string())
        {
            self.set(g, "name", n);
        }
        let Some(m) = self.sub(visual, "material") else {
            return;
        };
        let color = self
            .sub(m, "color")
            .and_then(|c| raw.attr(c, "rgba"))
            .or_else(|| {
                raw.attr(m, "name")
                    .and_then(|n| self.materials.get(n).copied())
            });
        let texture = self
            .sub(m, "texture")
            .and_then(|t| raw.attr(t, "filename"))
            .and_then(|f| self.file_reference(m, f));
        match raw.attr(m, "name").filter(|n| !n.is_empty()) {
            Some(name) => {
                if self.made_materials.insert(name.to_string()) {
                    let mat = self.element("material", m);
                    self.set(mat, "name", name);
                    if let Some(c) = color {
                        self.set(mat, "rgba", c);
                    }
                    if let Some(file) = texture {
                        let tex = self.element("texture", m);
                        self.set(tex, "name", name);
                        self.set(tex, "type", "2d");
                        self.set(tex, "file", &file);
                        self.set(mat, "texture", name);
                        self.asset_visual.push(tex);
                    }
                    self.asset_visual.push(mat);
                }
                self.set(g, "material", name);
            }
            None => {
                if let Some(c) = color {
                    self.set(g, "rgba", c);
                }
            }
        }
    }
}
