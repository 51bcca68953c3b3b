//! The built-in demo scene: `corpora/scenes/demo/`, compiled into the library so that it
//! runs with nothing on disk.

use std::path::{Path, PathBuf};

use crate::document::Document;
use crate::error::{Error, ErrorKind, Errors};

use super::load::ModelSource;

/// The demo's scene file.
pub(crate) const SCENE: &str = include_str!("../../corpora/scenes/demo/demo.toml");

/// The demo's models, by the name the scene file uses.
const MODELS: &[(&str, &str)] = &[
    (
        "arena.xml",
        include_str!("../../corpora/scenes/demo/arena.xml"),
    ),
    ("arm.xml", include_str!("../../corpora/scenes/demo/arm.xml")),
    (
        "mount.xml",
        include_str!("../../corpora/scenes/demo/mount.xml"),
    ),
    (
        "gripper.xml",
        include_str!("../../corpora/scenes/demo/gripper.xml"),
    ),
    ("box.xml", include_str!("../../corpora/scenes/demo/box.xml")),
    (
        "cylinder.xml",
        include_str!("../../corpora/scenes/demo/cylinder.xml"),
    ),
    (
        "sphere.xml",
        include_str!("../../corpora/scenes/demo/sphere.xml"),
    ),
    (
        "block.xml",
        include_str!("../../corpora/scenes/demo/block.xml"),
    ),
    (
        "coin.xml",
        include_str!("../../corpora/scenes/demo/coin.xml"),
    ),
];

/// The demo's models, from the texts above (they use no file: textures are built in).
pub(crate) struct Embedded;

impl ModelSource for Embedded {
    fn load(&self, _dir: &Path, file: &str) -> Result<(Document, Option<PathBuf>), Errors> {
        let (_, text) = MODELS
            .iter()
            .find(|(name, _)| *name == file)
            .ok_or_else(|| {
                Error::bare(ErrorKind::Io {
                    path: PathBuf::from(file),
                    reason: "not a model of the built-in demo".into(),
                })
            })?;
        Ok((Document::from_str(text, ".")?, None))
    }
}
