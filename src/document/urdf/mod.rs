//! URDF robots read into the same arena document as an MJCF model.
//!
//! A file whose root element is `<robot>` is URDF. The reader builds the MJCF document that
//! MuJoCo's own URDF importer builds as its model specification (links as bodies in the
//! importer's tree order, joints, collision geoms coloured by their link's last visual,
//! meshes named by file stem and scale, `<mimic>` as joint equalities, the file's own
//! `<mujoco>` block), so that with the default [`UrdfOptions`] it compiles to the model
//! MuJoCo compiles from the URDF file itself. The options go beyond the importer where it
//! stops: visual geoms kept, `package://` resolved, static links kept, actuators written.
//! The rules, each settled against MuJoCo 3.17.0 and 4.0.0, are in docs/urdf.md.
//!
//! The files, by what they do:
//! - [`convert`]: the URDF elements read and the MJCF elements written;
//! - [`packages`]: `package://` and `file://` paths resolved to files;
//! - [`robot`]: the link tree (parents, children, the importer's body order) and its errors.

mod convert;
mod packages;
mod robot;

use std::path::{Path, PathBuf};

use crate::document::Document;
use crate::document::limits::Limits;
use crate::error::Errors;

pub(crate) use convert::convert;

/// How a URDF file is read. The default is MuJoCo's importer, with `package://` paths
/// resolved where MuJoCo's own rule (the file's `<compiler strippath meshdir>`) finds no
/// file: MuJoCo cannot open such a path, so resolving it changes no model MuJoCo builds.
///
/// ```
/// use mjcf_forge::{Document, UrdfOptions};
/// let urdf = r#"<robot name="r">
///   <link name="base"/>
///   <link name="arm">
///     <inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
///     <visual><geometry><sphere radius="0.1"/></geometry></visual>
///     <collision><geometry><sphere radius="0.1"/></geometry></collision>
///   </link>
///   <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
///     <limit lower="-1" upper="1" effort="5"/></joint>
/// </robot>"#;
/// // MuJoCo's importer: the visual is dropped.
/// let doc = Document::from_urdf_str(urdf, ".", &UrdfOptions::default())?;
/// assert_eq!(doc.to_xml_string().matches("<geom").count(), 1);
/// // Visuals kept: group 1, no mass, no contacts.
/// let opts = UrdfOptions { visuals: true, ..UrdfOptions::default() };
/// let doc = Document::from_urdf_str(urdf, ".", &opts)?;
/// assert!(doc.to_xml_string().contains(r#"contype="0" conaffinity="0" group="1" density="0""#));
/// # Ok::<(), mjcf_forge::Errors>(())
/// ```
#[derive(Clone, Debug)]
pub struct UrdfOptions {
    /// Keep each `<visual>` as a geom of group 1 with no mass and no contacts, its URDF
    /// material as a MuJoCo `<material>`. MuJoCo's importer drops them (`discardvisual`),
    /// which is the default here too; a file whose own `<mujoco><compiler>` keeps them is
    /// read as MuJoCo reads it either way.
    pub visuals: bool,
    /// Fuse static links (those joined by `fixed` joints) into their parents, as MuJoCo's
    /// importer does (`fusestatic`). `false` keeps every link a body.
    pub fuse_static: bool,
    /// Links kept as bodies even when static links are fused (`fuse="false"`): a gripper's
    /// mount point, a camera frame.
    pub keep_links: Vec<String>,
    /// Resolve `package://NAME/...` and `file://...` mesh paths. The package folder is
    /// found in [`UrdfOptions::packages`], then `ROS_PACKAGE_PATH`, then
    /// `AMENT_PREFIX_PATH` (`share/NAME`), then a folder `NAME` beside the URDF, then by
    /// walking up from the URDF's folder to a folder named `NAME` or holding a
    /// `package.xml` that names it.
    pub resolve_packages: bool,
    /// Package folders given by the user: (package name, folder).
    pub packages: Vec<(String, PathBuf)>,
    /// Actuators written for the URDF's moving joints (MuJoCo's importer writes none).
    pub actuators: Option<UrdfActuators>,
    /// Which MuJoCo's importer to read as, where they differ.
    pub importer: UrdfImporter,
}

/// The MuJoCo release whose URDF importer a file is read as. They differ in one rule: a
/// `continuous` joint's `<limit lower upper>` limits it in 3.17.0 and is ignored in 4.0.0
/// (such a joint has no range there).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UrdfImporter {
    /// MuJoCo 3.x (checked against 3.17.0).
    MuJoCo3,
    /// MuJoCo 4.0.0, what `pip install mujoco` gives today.
    MuJoCo4,
}

/// The process's default importer, set by [`UrdfImporter::set_default`]: 0 for none (the
/// build's), else 1 + the variant's index. An atomic, read once per URDF read.
static PROCESS_DEFAULT: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(0);

impl Default for UrdfImporter {
    /// The one [`UrdfImporter::set_default`] set; else the importer of the MuJoCo this
    /// build links (the `mujoco` feature), else 4.0.0's.
    fn default() -> Self {
        match PROCESS_DEFAULT.load(std::sync::atomic::Ordering::Relaxed) {
            1 => return UrdfImporter::MuJoCo3,
            2 => return UrdfImporter::MuJoCo4,
            _ => {}
        }
        #[cfg(mjcf_mujoco)]
        {
            UrdfImporter::of_version(env!("MJCF_FORGE_MUJOCO_VERSION"))
        }
        #[cfg(not(mjcf_mujoco))]
        {
            UrdfImporter::MuJoCo4
        }
    }
}

impl UrdfImporter {
    /// Makes `importer` the default of every later URDF read in this process that names
    /// none (`Document::load`, scene files); `None` goes back to the build's. For a host
    /// that knows which MuJoCo compiles what it reads: the Python package sets the
    /// installed `mujoco`'s before it loads a scene.
    ///
    /// ```
    /// use mjcf_forge::UrdfImporter;
    /// UrdfImporter::set_default(Some(UrdfImporter::MuJoCo3));
    /// assert_eq!(UrdfImporter::default(), UrdfImporter::MuJoCo3);
    /// UrdfImporter::set_default(None);
    /// ```
    pub fn set_default(importer: Option<UrdfImporter>) {
        let v = match importer {
            None => 0,
            Some(UrdfImporter::MuJoCo3) => 1,
            Some(UrdfImporter::MuJoCo4) => 2,
        };
        PROCESS_DEFAULT.store(v, std::sync::atomic::Ordering::Relaxed);
    }

    /// The importer of a MuJoCo version (`"3.17.0"`, `"4.0.0"`): 3.x reads as 3.17.0,
    /// anything else as 4.0.0.
    ///
    /// ```
    /// use mjcf_forge::UrdfImporter;
    /// assert_eq!(UrdfImporter::of_version("3.17.0"), UrdfImporter::MuJoCo3);
    /// assert_eq!(UrdfImporter::of_version("4.0.0"), UrdfImporter::MuJoCo4);
    /// ```
    pub fn of_version(version: &str) -> UrdfImporter {
        match version.split('.').next() {
            Some("3") => UrdfImporter::MuJoCo3,
            _ => UrdfImporter::MuJoCo4,
        }
    }
}

impl Default for UrdfOptions {
    fn default() -> Self {
        UrdfOptions {
            visuals: false,
            fuse_static: true,
            keep_links: Vec::new(),
            resolve_packages: true,
            packages: Vec::new(),
            actuators: None,
            importer: UrdfImporter::default(),
        }
    }
}

/// The actuators [`UrdfOptions::actuators`] writes: one per hinge or slide joint, named
/// after it, its control range from the joint's `<limit>` (position: `lower upper`;
/// velocity: `±velocity`; motor: `±effort`) where the URDF gives one, and its force range
/// from `effort`.
#[derive(Clone, Debug, PartialEq)]
pub enum UrdfActuators {
    /// `<position kp=...>`, with `kv` when it is above 0.
    Position {
        /// Position gain.
        kp: f64,
        /// Velocity gain (damping), 0 for none.
        kv: f64,
    },
    /// `<velocity kv=...>`.
    Velocity {
        /// Velocity gain.
        kv: f64,
    },
    /// `<motor>`: the control is the joint torque or force, with gear 1.
    Motor,
}

impl Document {
    /// Loads a URDF file with `options` ([`Document::load`] reads one with the defaults).
    ///
    /// ```no_run
    /// use mjcf_forge::{Document, UrdfOptions};
    /// let opts = UrdfOptions { visuals: true, ..UrdfOptions::default() };
    /// let arm = Document::load_urdf("arm.urdf", &opts)?;
    /// arm.write_file("arm.xml")?;
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn load_urdf(path: impl AsRef<Path>, options: &UrdfOptions) -> Result<Document, Errors> {
        Document::load_full(path.as_ref(), &Limits::default(), options)
    }

    /// [`Document::load_urdf`] within other [`Limits`] than the default ones; an MJCF file
    /// loads as [`Document::load_with`] loads it.
    ///
    /// ```no_run
    /// use mjcf_forge::{Document, Limits, UrdfOptions};
    /// let doc = Document::load_urdf_with("arm.urdf", &Limits::default(), &UrdfOptions::default())?;
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn load_urdf_with(
        path: impl AsRef<Path>,
        limits: &Limits,
        options: &UrdfOptions,
    ) -> Result<Document, Errors> {
        Document::load_full(path.as_ref(), limits, options)
    }

    /// URDF text read with `options`; `base_dir` plays the part of the file's folder
    /// (relative mesh paths and `package.xml` searches start there).
    ///
    /// ```
    /// use mjcf_forge::{Document, UrdfOptions};
    /// let doc = Document::from_urdf_str(r#"<robot name="r"><link name="a"/></robot>"#, ".", &UrdfOptions::default())?;
    /// assert_eq!(doc.model_name(), Some("r"));
    /// # Ok::<(), mjcf_forge::Errors>(())
    /// ```
    pub fn from_urdf_str(
        xml: &str,
        base_dir: impl AsRef<Path>,
        options: &UrdfOptions,
    ) -> Result<Document, Errors> {
        Document::from_str_full(xml, base_dir.as_ref(), &Limits::default(), options)
    }

    /// Whether the document was read from URDF (its root is `<robot>`); only the reader
    /// sees such a document, which it converts before any pass runs.
    pub(crate) fn is_urdf(&self) -> bool {
        self.tag(self.root) == "robot"
    }
}

/// The URDF text of a `.xacro` file, expanded through the `xacro` command where one is on
/// `PATH`; without it, an error naming the command. `None` for any other file.
pub(crate) fn xacro_text(path: &Path, limits: &Limits) -> Result<Option<String>, Errors> {
    if path.extension().is_none_or(|e| e != "xacro") {
        return Ok(None);
    }
    let at = || crate::error::Location::new(std::sync::Arc::from(path), 1, 1);
    let expanded = std::process::Command::new("xacro").arg(path).output();
    match expanded {
        Ok(out) if out.status.success() => {
            if out.stdout.len() as u64 > limits.max_file_size {
                return Err(crate::error::Error::at(
                    at(),
                    crate::error::ErrorKind::Invalid(format!(
                        "xacro expanded it to {} bytes, more than the limit of {} (Limits::max_file_size)",
                        out.stdout.len(),
                        limits.max_file_size
                    )),
                )
                .into());
            }
            Ok(Some(String::from_utf8_lossy(&out.stdout).into_owned()))
        }
        Ok(out) => Err(crate::error::Error::at(
            at(),
            crate::error::ErrorKind::Invalid(format!(
                "xacro could not expand it: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            )),
        )
        .into()),
        Err(_) => Err(crate::error::Error::at(
            at(),
            crate::error::ErrorKind::Invalid(xacro_advice(path)),
        )
        .into()),
    }
}

/// What to do with a xacro file when no `xacro` command is installed.
pub(crate) fn xacro_advice(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = name.trim_end_matches(".xacro").trim_end_matches(".urdf");
    format!(
        "a xacro file, which needs expanding into URDF first: `xacro {name} > {stem}.urdf` \
         (the `xacro` command: `pip install xacro`, or ROS's xacro package), then load {stem}.urdf"
    )
}
