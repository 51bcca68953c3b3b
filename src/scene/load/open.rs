//! A [`Scene`]'s constructors: from a scene file, TOML or JSON text, or the built-in demo;
//! each also with the caller's MuJoCo for the inertials object groups write out
//! (`write_inertials`), else the build's own.

use std::path::Path;
use std::sync::Arc;

use crate::document::inertia::InertiaCompiler;
use crate::error::{Error, ErrorKind, Errors, Location};
use crate::scene::{Scene, demo};

/// The key paths of the nulls in `value` (`path` is its own).
fn find_nulls(value: &serde_json::Value, path: &str, out: &mut Vec<String>) {
    match value {
        serde_json::Value::Null => out.push(path.to_string()),
        serde_json::Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                find_nulls(item, &format!("{path}[{i}]"), out);
            }
        }
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                find_nulls(v, &super::join_key(path, k), out);
            }
        }
        _ => {}
    }
}

impl Scene {
    /// Loads a scene file (TOML); model paths in it are relative to its folder.
    ///
    /// ```no_run
    /// let scene = mjcf_forge::scene::Scene::load("corpora/scenes/demo/demo.toml")?;
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn load(path: impl AsRef<Path>) -> Result<Scene, Errors> {
        Scene::open(path.as_ref(), None)
    }

    /// [`Scene::load`] with the caller's MuJoCo (`compile`) for the inertials an object
    /// group writes out (`write_inertials = true`) instead of the build's own (feature
    /// `mujoco`): what the Python package passes its `mujoco` through.
    ///
    /// ```
    /// use mjcf_forge::{CompiledInertia, Document, scene::Scene};
    ///
    /// // A MuJoCo of the caller's that cannot compile: each pool model says so, at its place.
    /// let mut compile = |_: &Document| -> Result<CompiledInertia, mjcf_forge::Error> {
    ///     Err(mjcf_forge::Error::new(mjcf_forge::ErrorKind::InertiaCompile("no MuJoCo here".into())))
    /// };
    /// let err = Scene::load_with("corpora/scenes/patch/inertials.toml", &mut compile).unwrap_err();
    /// assert_eq!(err.0.len(), 3);
    /// assert!(err.to_string().contains("cannot write the inertials of '../demo/box.xml': no MuJoCo here"));
    /// ```
    pub fn load_with(
        path: impl AsRef<Path>,
        compile: &mut InertiaCompiler<'_>,
    ) -> Result<Scene, Errors> {
        Scene::open(path.as_ref(), Some(compile))
    }

    fn open(path: &Path, compile: Option<&mut InertiaCompiler<'_>>) -> Result<Scene, Errors> {
        // Only a regular file within the size limit (a FIFO would block, a device never end).
        let max = crate::Limits::default().max_file_size;
        let bytes = crate::document::limits::read_regular_file(path, max).map_err(|reason| {
            Error::bare(ErrorKind::Io {
                path: path.to_path_buf(),
                reason,
            })
        })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            Error::bare(ErrorKind::Io {
                path: path.to_path_buf(),
                reason: e.to_string(),
            })
        })?;
        super::from_toml(&text, Arc::from(path), &super::Files, compile)
    }

    /// A scene from TOML text; model paths are relative to `base_dir`.
    ///
    /// ```
    /// let scene = mjcf_forge::scene::Scene::from_toml_str(
    ///     "seed = 1\nbase = \"arena.xml\"\n",
    ///     "corpora/scenes/demo",
    /// )?;
    /// assert_eq!(scene.seed(), 1);
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn from_toml_str(text: &str, base_dir: impl AsRef<Path>) -> Result<Scene, Errors> {
        let label: Arc<Path> = Arc::from(base_dir.as_ref().join("<scene>").as_path());
        super::from_toml(text, label, &super::Files, None)
    }

    /// [`Scene::from_toml_str`] with the caller's MuJoCo, as [`Scene::load_with`].
    pub fn from_toml_str_with(
        text: &str,
        base_dir: impl AsRef<Path>,
        compile: &mut InertiaCompiler<'_>,
    ) -> Result<Scene, Errors> {
        let label: Arc<Path> = Arc::from(base_dir.as_ref().join("<scene>").as_path());
        super::from_toml(text, label, &super::Files, Some(compile))
    }

    /// A scene from the same description as JSON (what a Python dictionary dumps to);
    /// model paths are relative to `base_dir`. A problem is told by the key path of the
    /// value it is about, after the label `<scene dict>` (the description has no lines of
    /// its own).
    ///
    /// ```
    /// use mjcf_forge::scene::Scene;
    /// let scene = Scene::from_json_str(r#"{"seed": 2, "base": "arena.xml"}"#, "corpora/scenes/demo")?;
    /// assert_eq!(scene.seed(), 2);
    /// let err = Scene::from_json_str(r#"{"base": "arena.xml", "seed": "2"}"#, "corpora/scenes/demo")
    ///     .unwrap_err();
    /// assert_eq!(err.to_string(), "<scene dict>: seed: invalid type: string \"2\", expected u64");
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn from_json_str(json: &str, base_dir: impl AsRef<Path>) -> Result<Scene, Errors> {
        Scene::from_json(json, base_dir.as_ref(), None)
    }

    /// [`Scene::from_json_str`] with the caller's MuJoCo, as [`Scene::load_with`].
    pub fn from_json_str_with(
        json: &str,
        base_dir: impl AsRef<Path>,
        compile: &mut InertiaCompiler<'_>,
    ) -> Result<Scene, Errors> {
        Scene::from_json(json, base_dir.as_ref(), Some(compile))
    }

    fn from_json(
        json: &str,
        base_dir: &Path,
        compile: Option<&mut InertiaCompiler<'_>>,
    ) -> Result<Scene, Errors> {
        let label: Arc<Path> = Arc::from(Path::new("<scene dict>"));
        let value: serde_json::Value = serde_json::from_str(json).map_err(|e| {
            Error::at(
                Location::new(label.clone(), e.line() as u32, e.column() as u32),
                ErrorKind::Invalid(format!("invalid JSON: {e}")),
            )
        })?;
        // TOML has no null: a key with no value is named here, before the TOML text
        // (which would only say that something somewhere is unsupported).
        let mut nulls = Vec::new();
        find_nulls(&value, "", &mut nulls);
        if !value.is_object() {
            nulls.push(String::new());
        }
        if !nulls.is_empty() {
            return Err(Errors(
                nulls
                    .iter()
                    .map(|key| {
                        let what = if key.is_empty() {
                            "a scene description is a table (a dict) of its keys"
                        } else {
                            "null (None) is not a value: leave the key out"
                        };
                        Error::at(
                            super::key_location(label.clone(), key),
                            ErrorKind::Invalid(what.to_string()),
                        )
                    })
                    .collect(),
            ));
        }
        let text = toml::to_string(&value).map_err(|e| {
            Error::at(
                super::key_location(label.clone(), ""),
                ErrorKind::Invalid(format!("not a scene description: {e}")),
            )
        })?;
        super::from_serialized(&text, label, base_dir.to_path_buf(), &super::Files, compile)
    }

    /// The built-in demo scene: a table arena, a two-finger arm on a mount, and boxes,
    /// cylinders and spheres with random poses, colours, frictions, masses and light. Its
    /// models are ours and built into the library, so it needs no file.
    pub fn demo() -> Result<Scene, Errors> {
        super::from_toml(
            demo::SCENE,
            Arc::from(Path::new("<demo>/demo.toml")),
            &demo::Embedded,
            None,
        )
    }
}
