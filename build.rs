//! Build script: does something only with the cargo feature `mujoco`, which links MuJoCo's C
//! library (3.17.0 or later) through our own C shim.
//!
//! No Rust copy of MuJoCo's headers exists: `src/mujoco/shim.c` (the FFI),
//! `src/compiled/patch.c` (the model cache) and `src/preview/render.c` (the renderer) are
//! compiled against the headers of the very MuJoCo the build links, so struct layouts and constants always match the library. The
//! MuJoCo is a folder laid out like the PyPI wheel's `mujoco/` package
//! (`include/mujoco/mujoco.h` beside `libmujoco.so.X.Y.Z`), looked for in this order:
//!
//! 1. `MJCF_FORGE_MUJOCO_DIR`, when set: that folder, and nothing else;
//! 2. the `mujoco` package of the Python in `MJCF_FORGE_PYTHON`, when that file exists
//!    (`.cargo/config.toml` names the repository's `.cache/venv`, MuJoCo 3.17.0, so builds
//!    inside the repository use what `scripts/setup.sh` installed);
//! 3. the `mujoco` package of `python3` on `PATH` (what `cargo install` elsewhere finds).
//!
//! A Python's package may span several folders (from 4.0 on, the wheel `mujoco` is a
//! pkgutil namespace whose library and headers come from the wheel `mujoco-core`), so every
//! folder of `mujoco.__path__` is tried. The library is linked by its file name, with an
//! rpath to its folder, so binaries, tests and examples run without `LD_LIBRARY_PATH`; its
//! version becomes the compile-time variable `MJCF_FORGE_MUJOCO_VERSION` (tests pick the
//! judge of that version by it). A missing MuJoCo, or one older than 3.17.0, stops the
//! build with a message naming what was tried and how to fix it.
//!
//! The cfg `mjcf_mujoco` means "built with MuJoCo" to the code. Without the feature this
//! script prints nothing but its own rerun conditions, so the default build neither needs
//! nor looks for MuJoCo.

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(mjcf_mujoco)");
    #[cfg(feature = "mujoco")]
    mujoco::build();
}

#[cfg(feature = "mujoco")]
mod mujoco {
    use std::env;
    use std::fmt;
    use std::path::{Path, PathBuf};
    use std::process::Command;

    /// The folder of one MuJoCo (headers in `include/`, the library beside them).
    const DIR_VAR: &str = "MJCF_FORGE_MUJOCO_DIR";
    /// A Python whose `mujoco` package is the MuJoCo to link.
    const PYTHON_VAR: &str = "MJCF_FORGE_PYTHON";
    /// The compile-time variable that names the linked MuJoCo's version.
    const VERSION_VAR: &str = "MJCF_FORGE_MUJOCO_VERSION";
    /// The oldest MuJoCo the shim and the model cache are known to work with.
    const OLDEST: Version = Version(3, 17, 0);

    /// Prints every folder of the `mujoco` package, the one of `__init__.py` first.
    const PYTHON_QUERY: &str = "import mujoco, os\n\
        print(os.path.dirname(mujoco.__file__))\n\
        for p in mujoco.__path__: print(p)";

    #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
    struct Version(u32, u32, u32);

    impl Version {
        /// `"3.17.0"`.
        fn parse(text: &str) -> Option<Version> {
            let mut parts = text.split('.').map(|p| p.parse::<u32>().ok());
            let v = Version(parts.next()??, parts.next()??, parts.next()??);
            parts.next().is_none().then_some(v)
        }

        /// `mjVERSION_HEADER`: 3017000 is 3.17.0; before 3.0 it had a digit a part (232).
        fn from_code(code: u32) -> Version {
            if code < 1_000_000 {
                Version(code / 100, code / 10 % 10, code % 10)
            } else {
                Version(code / 1_000_000, code / 1000 % 1000, code % 1000)
            }
        }
    }

    impl fmt::Display for Version {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "{}.{}.{}", self.0, self.1, self.2)
        }
    }

    /// A MuJoCo found: its folder, the library's file name there, and its version.
    struct Mujoco {
        dir: PathBuf,
        lib: String,
        version: Version,
    }

    pub fn build() {
        println!("cargo::rustc-cfg=mjcf_mujoco");
        println!("cargo::rerun-if-env-changed={DIR_VAR}");
        println!("cargo::rerun-if-env-changed={PYTHON_VAR}");
        println!("cargo::rerun-if-changed=src/mujoco/shim.c");
        println!("cargo::rerun-if-changed=src/compiled/patch.c");
        println!("cargo::rerun-if-changed=src/preview/render.c");

        let mujoco = find().unwrap_or_else(|tried| stop(&not_found(&tried)));
        if mujoco.version < OLDEST {
            stop(&format!(
                "the cargo feature `mujoco` needs MuJoCo {OLDEST} or later, and the MuJoCo found \
                 in {} is {}.\n\
                 Upgrade it (`pip install -U mujoco`), or set {DIR_VAR} to the `mujoco` folder \
                 of a newer one.",
                mujoco.dir.display(),
                mujoco.version
            ));
        }
        let include = mujoco.dir.join("include");
        println!(
            "cargo::rerun-if-changed={}",
            mujoco.dir.join(&mujoco.lib).display()
        );
        println!(
            "cargo::rerun-if-changed={}",
            include.join("mujoco/mujoco.h").display()
        );
        println!("cargo::rustc-env={VERSION_VAR}={}", mujoco.version);

        compile_c("src/mujoco/shim.c", &include, "mjcf_forge_mujoco_shim");
        compile_c(
            "src/compiled/patch.c",
            &include,
            "mjcf_forge_compiled_patch",
        );
        // The preview tier's renderer: opens EGL or OSMesa at run time (dlopen), so nothing
        // of OpenGL is linked; only libdl (part of libc since glibc 2.34).
        compile_c(
            "src/preview/render.c",
            &include,
            "mjcf_forge_preview_render",
        );
        println!("cargo::rustc-link-lib=dylib=dl");
        // After the C libraries, which need its symbols. By file name: the wheel ships the
        // versioned file only, no `libmujoco.so` for `-lmujoco` to find.
        println!("cargo::rustc-link-search=native={}", mujoco.dir.display());
        println!("cargo::rustc-link-lib=dylib:+verbatim={}", mujoco.lib);
        if env::var("CARGO_CFG_TARGET_OS").unwrap_or_default() != "windows" {
            println!("cargo::rustc-link-arg=-Wl,-rpath,{}", mujoco.dir.display());
        }
    }

    fn compile_c(file: &str, include: &Path, name: &str) {
        cc::Build::new()
            .file(file)
            .include(include)
            .warnings(true)
            .compile(name);
    }

    /// The MuJoCo to link, or what was tried (one line each) when none was found.
    fn find() -> Result<Mujoco, Vec<String>> {
        if let Some(dir) = env::var_os(DIR_VAR).filter(|d| !d.is_empty()) {
            // Set on purpose: a wrong folder is an error, not a reason to look elsewhere.
            let dir = PathBuf::from(dir);
            return in_folder(&dir).map_err(|why| {
                vec![format!(
                    "{DIR_VAR}={}: {why} (being set, it is the only place looked in)",
                    dir.display()
                )]
            });
        }
        let mut tried = vec![format!("{DIR_VAR}: not set")];
        if let Some(python) = env::var_os(PYTHON_VAR).filter(|p| !p.is_empty()) {
            let python = PathBuf::from(python);
            let label = format!("{PYTHON_VAR}={}", python.display());
            if python.is_file() {
                match from_python(&python) {
                    Ok(found) => return Ok(found),
                    Err(why) => tried.push(format!("{label}: {why}")),
                }
            } else {
                tried.push(format!("{label}: no such file"));
            }
        } else {
            tried.push(format!("{PYTHON_VAR}: not set"));
        }
        // Only now does PATH decide, so only now is it a reason to look again.
        println!("cargo::rerun-if-env-changed=PATH");
        match from_python(Path::new("python3")) {
            Ok(found) => Ok(found),
            Err(why) => {
                tried.push(format!("python3 on PATH: {why}"));
                Err(tried)
            }
        }
    }

    /// The MuJoCo of `python`'s `mujoco` package: the first of its folders that holds one.
    fn from_python(python: &Path) -> Result<Mujoco, String> {
        let out = Command::new(python)
            .args(["-c", PYTHON_QUERY])
            .output()
            .map_err(|e| format!("cannot run it ({e})"))?;
        if !out.status.success() {
            let stderr = String::from_utf8_lossy(&out.stderr);
            let last = stderr.lines().rev().find(|l| !l.trim().is_empty());
            return Err(format!(
                "cannot import mujoco ({})",
                last.unwrap_or("no message").trim()
            ));
        }
        let stdout = String::from_utf8_lossy(&out.stdout);
        let mut reasons = Vec::new();
        for dir in stdout.lines().map(str::trim).filter(|l| !l.is_empty()) {
            match in_folder(Path::new(dir)) {
                Ok(found) => return Ok(found),
                Err(why) => reasons.push(format!("{dir}: {why}")),
            }
        }
        Err(format!(
            "its mujoco package has no C library: {}",
            reasons.join("; ")
        ))
    }

    /// The MuJoCo in `dir`: `include/mujoco/mujoco.h` and the library, whose version the
    /// file name gives (`libmujoco.so.3.17.0`; a plain `libmujoco.so` takes the headers').
    fn in_folder(dir: &Path) -> Result<Mujoco, String> {
        let header = dir.join("include/mujoco/mujoco.h");
        let text = std::fs::read_to_string(&header)
            .map_err(|_| "no include/mujoco/mujoco.h".to_string())?;
        let code = text
            .lines()
            .find_map(|l| l.trim().strip_prefix("#define mjVERSION_HEADER"))
            .and_then(|v| v.trim().parse::<u32>().ok())
            .ok_or_else(|| "include/mujoco/mujoco.h defines no mjVERSION_HEADER".to_string())?;
        let headers = Version::from_code(code);
        let names: Vec<String> = std::fs::read_dir(dir)
            .map_err(|e| format!("cannot list it ({e})"))?
            .filter_map(Result::ok)
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with("libmujoco.so"))
            .collect();
        let versioned: Vec<(String, Version)> = names
            .iter()
            .filter_map(|n| Some((n.clone(), Version::parse(n.strip_prefix("libmujoco.so.")?)?)))
            .collect();
        // The file of the headers' version; else any versioned one (refused just below);
        // else a plain `libmujoco.so`.
        let (lib, version) = versioned
            .iter()
            .find(|(_, v)| *v == headers)
            .or_else(|| versioned.iter().max_by_key(|(_, v)| *v))
            .cloned()
            .or_else(|| {
                names
                    .iter()
                    .find(|n| *n == "libmujoco.so")
                    .map(|n| (n.clone(), headers))
            })
            .ok_or_else(|| "no libmujoco.so.X.Y.Z".to_string())?;
        if version != headers {
            return Err(format!(
                "{lib} is MuJoCo {version}, but its headers are {headers}'s"
            ));
        }
        // An absolute path, so the rpath works from wherever a binary is started.
        let dir = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
        Ok(Mujoco { dir, lib, version })
    }

    fn not_found(tried: &[String]) -> String {
        let tried: String = tried.iter().map(|t| format!("  - {t}\n")).collect();
        format!(
            "the cargo feature `mujoco` needs MuJoCo's C library ({OLDEST} or later), and none \
             was found. Tried, in order:\n{tried}\
             To fix it, either:\n\
             \x20 - `pip install mujoco` into the Python that `python3` runs (or set {PYTHON_VAR} \
             to a Python that has it), or\n\
             \x20 - set {DIR_VAR} to a folder with include/mujoco/mujoco.h and \
             libmujoco.so.X.Y.Z (the `mujoco` folder of an installed wheel).\n\
             In a checkout of mjcf-forge, `scripts/setup.sh` installs MuJoCo 3.17.0 into \
             .cache/venv, which {PYTHON_VAR} names by default."
        )
    }

    fn stop(message: &str) -> ! {
        eprintln!("\nerror: {message}\n");
        std::process::exit(1);
    }
}
