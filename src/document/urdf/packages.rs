//! `package://NAME/rest` and `file://path` mesh references resolved to files.
//!
//! MuJoCo opens neither (4.0.0 looks for `package:/NAME/rest` literally), so resolving
//! them changes no model MuJoCo builds. A package's folder is looked for, in order: in the
//! user's map, on `ROS_PACKAGE_PATH` (each entry a package folder, or a folder holding
//! packages), under `AMENT_PREFIX_PATH`'s `share/NAME`, then a folder `NAME` beside the
//! URDF, then by walking up from the URDF's folder to a folder named `NAME` or holding a
//! `package.xml` that names it, or holding a package folder `NAME` (with its `package.xml`).

use std::path::{Path, PathBuf};

/// Where one URDF file's packages are found.
pub(super) struct Packages<'a> {
    pub(super) map: &'a [(String, PathBuf)],
    /// The URDF's own folder, where the upward search starts.
    pub(super) start: &'a Path,
}

/// A mesh reference after resolution.
pub(super) enum Resolved {
    /// Not a URI: the path as the file gives it.
    Plain,
    /// A file found for a `package://` or `file://` URI.
    File(PathBuf),
    /// A `package://` whose package was found nowhere (the package's name).
    Unfound(String),
}

impl Packages<'_> {
    pub(super) fn resolve(&self, reference: &str) -> Resolved {
        if let Some(path) = reference.strip_prefix("file://") {
            return Resolved::File(PathBuf::from(path));
        }
        let Some(rest) = reference.strip_prefix("package://") else {
            return Resolved::Plain;
        };
        // `package:///NAME/...` (a slash too many) names the same package.
        let rest = rest.trim_start_matches('/');
        let (name, inner) = rest.split_once('/').unwrap_or((rest, ""));
        match self.package_dir(name) {
            Some(dir) => Resolved::File(dir.join(inner)),
            None => Resolved::Unfound(name.to_string()),
        }
    }

    fn package_dir(&self, name: &str) -> Option<PathBuf> {
        if let Some((_, dir)) = self.map.iter().find(|(n, _)| n == name) {
            return Some(dir.clone());
        }
        let env_dirs = |var: &str| -> Vec<PathBuf> {
            std::env::var_os(var)
                .map(|v| std::env::split_paths(&v).collect())
                .unwrap_or_default()
        };
        for dir in env_dirs("ROS_PACKAGE_PATH") {
            if names_package(&dir, name) {
                return Some(dir);
            }
            if dir.join(name).is_dir() {
                return Some(dir.join(name));
            }
        }
        for prefix in env_dirs("AMENT_PREFIX_PATH") {
            let dir = prefix.join("share").join(name);
            if dir.is_dir() {
                return Some(dir);
            }
        }
        let start = std::path::absolute(self.start).unwrap_or_else(|_| self.start.to_path_buf());
        // The URDF's own folder may hold the package as a plain folder (pybullet's
        // `package://meshes/...` beside the file); above it, a package has its manifest.
        if start.join(name).is_dir() {
            return Some(start.join(name));
        }
        for dir in start.ancestors() {
            if names_package(dir, name) {
                return Some(dir.to_path_buf());
            }
            if dir.join(name).join("package.xml").is_file() {
                return Some(dir.join(name));
            }
        }
        None
    }
}

/// Whether `dir` is the package `name`: named so and a package (or holding a `package.xml`
/// whose `<name>` is `name`).
fn names_package(dir: &Path, name: &str) -> bool {
    let manifest = dir.join("package.xml");
    match std::fs::read_to_string(&manifest) {
        Ok(text) => manifest_name(&text)
            .map_or_else(|| dir.file_name().is_some_and(|f| f == name), |n| n == name),
        Err(_) => dir.file_name().is_some_and(|f| f == name) && dir.is_dir(),
    }
}

/// The text of a `package.xml`'s first `<name>`.
fn manifest_name(text: &str) -> Option<&str> {
    let start = text.find("<name>")? + "<name>".len();
    let end = text[start..].find("</name>")?;
    Some(text[start..start + end].trim())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packages_are_found_by_map_manifest_and_folder_name() {
        let tmp = tempfile::tempdir().unwrap();
        let pkg = tmp.path().join("src/my_robot_description");
        std::fs::create_dir_all(pkg.join("urdf")).unwrap();
        std::fs::write(
            pkg.join("package.xml"),
            "<package><name>my_robot_description</name></package>",
        )
        .unwrap();
        let other = tmp.path().join("elsewhere");
        std::fs::create_dir_all(&other).unwrap();
        let map = [("given".to_string(), other.clone())];
        let p = Packages {
            map: &map,
            start: &pkg.join("urdf"),
        };
        match p.resolve("package://my_robot_description/meshes/a.stl") {
            Resolved::File(f) => assert_eq!(f, pkg.join("meshes/a.stl")),
            _ => panic!("not found by walking up"),
        }
        match p.resolve("package://given/b.obj") {
            Resolved::File(f) => assert_eq!(f, other.join("b.obj")),
            _ => panic!("not found in the map"),
        }
        assert!(matches!(p.resolve("meshes/a.stl"), Resolved::Plain));
        assert!(
            matches!(p.resolve("package://nowhere_pkg_x/a.stl"), Resolved::Unfound(n) if n == "nowhere_pkg_x")
        );
        match p.resolve("file:///abs/c.stl") {
            Resolved::File(f) => assert_eq!(f, PathBuf::from("/abs/c.stl")),
            _ => panic!("file:// not stripped"),
        }
    }
}
