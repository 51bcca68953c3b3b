//! Build script: only does something with the cargo feature `mujoco` or `mujoco-c`.
//!
//! With `mujoco` (MuJoCo 3.17.0), the crate links MuJoCo's C library through `mujoco-rs`,
//! taking the library from the PyPI wheel `mujoco==3.17.0` that `scripts/setup.sh` installs
//! into the repository's `.cache/venv`. The wheel ships the versioned file
//! `libmujoco.so.3.17.0` only; `.cargo/config.toml` points mujoco-rs
//! (`MUJOCO_DYNAMIC_LINK_DIR`) at a committed linker script named `libmujoco.so` that
//! redirects `-lmujoco` to that versioned name. This script:
//!
//! 1. finds the wheel's directory (or `MJCF_FORGE_MUJOCO_LIB_DIR` when set),
//! 2. stops the build with a message naming `scripts/setup.sh` when the library is missing,
//! 3. puts the directory on the linker's search path, so the linker script resolves, and
//! 4. embeds it as an rpath in every binary, test and example of this package, so they run
//!    without `LD_LIBRARY_PATH`.
//!
//! With `mujoco-c` (the MuJoCo a user has; MuJoCo 4.0.0 by default), there is no mujoco-rs:
//! `src/mujoco_shim.c` is compiled against the headers of a MuJoCo directory laid out like
//! the wheel's `mujoco/` package (`include/mujoco/mujoco.h` and one `libmujoco.so.X.Y.Z`):
//! `MJCF_FORGE_MUJOCO_DIR` when set, else the 4.0.0 wheel that `scripts/setup.sh` installs
//! into `.cache/venv-mj4`. That library is linked by its file name, with an rpath.
//!
//! Either feature sets the cfg `mjcf_mujoco`, which the code tests for "built with MuJoCo".
//! Without them it prints nothing but its own rerun conditions, so the default build
//! neither needs nor looks for MuJoCo.

use std::env;
use std::path::{Path, PathBuf};

/// The MuJoCo version that the `mujoco-rs` dependency binds and the wheel provides.
const MUJOCO_VERSION: &str = "3.17.0";

/// Overrides the directory that holds `libmujoco.so.<MUJOCO_VERSION>`.
const LIB_DIR_VAR: &str = "MJCF_FORGE_MUJOCO_LIB_DIR";

/// `mujoco-c`: the MuJoCo directory (headers in `include/`, the library beside them).
const MUJOCO_DIR_VAR: &str = "MJCF_FORGE_MUJOCO_DIR";

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(mjcf_mujoco)");
    let with_rs = env::var_os("CARGO_FEATURE_MUJOCO").is_some();
    let with_c = env::var_os("CARGO_FEATURE_MUJOCO_C").is_some();
    if with_rs && with_c {
        eprintln!(
            "\nerror: the cargo features `mujoco` (MuJoCo 3.17.0 through mujoco-rs) and `mujoco-c` \
             (the MuJoCo in {MUJOCO_DIR_VAR}, 4.0.0 by default) each link a MuJoCo library; \
             enable one of them.\n"
        );
        std::process::exit(1);
    }
    if with_c {
        println!("cargo::rustc-cfg=mjcf_mujoco");
        #[cfg(feature = "mujoco-c")]
        build_shim();
        return;
    }
    if !with_rs {
        return;
    }
    println!("cargo::rustc-cfg=mjcf_mujoco");
    println!("cargo::rerun-if-env-changed={LIB_DIR_VAR}");

    let manifest_dir = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let lib_name = format!("libmujoco.so.{MUJOCO_VERSION}");
    let lib_dir = match env::var_os(LIB_DIR_VAR) {
        Some(dir) => Some(PathBuf::from(dir)),
        None => find_wheel_dir(&manifest_dir, &lib_name),
    };
    let lib_dir = match lib_dir {
        Some(dir) if dir.join(&lib_name).is_file() => dir,
        found => missing_library(&manifest_dir, &lib_name, found.as_deref()),
    };
    // An absolute path, so the rpath works from wherever a binary is started.
    let lib_dir = lib_dir.canonicalize().unwrap_or(lib_dir);

    println!(
        "cargo::rerun-if-changed={}",
        lib_dir.join(&lib_name).display()
    );
    println!(
        "cargo::rerun-if-changed={}",
        manifest_dir
            .join(".cargo/mujoco-link/libmujoco.so")
            .display()
    );
    println!("cargo::rustc-link-search=native={}", lib_dir.display());
    let target_os = env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if target_os != "windows" {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{}", lib_dir.display());
    }
    // The model cache's C side, against the wheel's own 3.17.0 headers.
    #[cfg(feature = "mujoco")]
    build_patch(&lib_dir.join("include"));
}

/// Compiles `src/mujoco_patch.c` (the model cache's C side) against MuJoCo's headers in
/// `include`.
#[cfg(any(feature = "mujoco", feature = "mujoco-c"))]
fn build_patch(include: &Path) {
    println!("cargo::rerun-if-changed=src/mujoco_patch.c");
    cc::Build::new()
        .file("src/mujoco_patch.c")
        .include(include)
        .warnings(true)
        .compile("mjcf_forge_mujoco_patch");
}

/// `<repo>/.cache/venv/lib/python3.*/site-packages/mujoco`, the first that holds the library.
fn find_wheel_dir(manifest_dir: &Path, lib_name: &str) -> Option<PathBuf> {
    let venv_lib = manifest_dir.join(".cache/venv/lib");
    let mut candidates: Vec<PathBuf> = std::fs::read_dir(&venv_lib)
        .ok()?
        .filter_map(Result::ok)
        .filter(|entry| entry.file_name().to_string_lossy().starts_with("python3"))
        .map(|entry| entry.path().join("site-packages/mujoco"))
        .collect();
    candidates.sort();
    candidates
        .into_iter()
        .find(|dir| dir.join(lib_name).is_file())
}

fn missing_library(manifest_dir: &Path, lib_name: &str, looked_in: Option<&Path>) -> ! {
    let looked_in = looked_in.map_or_else(
        || {
            manifest_dir
                .join(".cache/venv/lib/python3.*/site-packages/mujoco")
                .display()
                .to_string()
        },
        |dir| dir.display().to_string(),
    );
    eprintln!(
        "\nerror: the cargo feature `mujoco` needs MuJoCo {MUJOCO_VERSION}'s C library, and {lib_name} \
         was not found in {looked_in}.\n\
         Run `scripts/setup.sh` in the repository root: it installs the PyPI wheel \
         mujoco=={MUJOCO_VERSION} into .cache/venv, which ships the library.\n\
         (Or set {LIB_DIR_VAR} to a directory that holds {lib_name}.)\n"
    );
    std::process::exit(1);
}

/// `mujoco-c`: compiles the shim against the chosen MuJoCo's headers and links its library.
#[cfg(feature = "mujoco-c")]
fn build_shim() {
    println!("cargo::rerun-if-env-changed={MUJOCO_DIR_VAR}");
    println!("cargo::rerun-if-changed=src/mujoco_shim.c");
    let manifest_dir = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let dir = match env::var_os(MUJOCO_DIR_VAR) {
        Some(dir) => PathBuf::from(dir),
        None => {
            let venv_lib = manifest_dir.join(".cache/venv-mj4/lib");
            let mut candidates: Vec<PathBuf> = std::fs::read_dir(&venv_lib)
                .map(|rd| {
                    rd.filter_map(Result::ok)
                        .filter(|e| e.file_name().to_string_lossy().starts_with("python3"))
                        .map(|e| e.path().join("site-packages/mujoco"))
                        .collect()
                })
                .unwrap_or_default();
            candidates.sort();
            candidates
                .into_iter()
                .find(|d| d.join("include/mujoco/mujoco.h").is_file())
                .unwrap_or_else(|| {
                    manifest_dir.join(".cache/venv-mj4/lib/python3.*/site-packages/mujoco")
                })
        }
    };
    let dir = dir.canonicalize().unwrap_or(dir);
    let include = dir.join("include");
    // The versioned library (`libmujoco.so.4.0.0`), else a plain `libmujoco.so`.
    let mut libs: Vec<String> = std::fs::read_dir(&dir)
        .map(|rd| {
            rd.filter_map(Result::ok)
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with("libmujoco.so"))
                .collect()
        })
        .unwrap_or_default();
    libs.sort_by_key(|n| std::cmp::Reverse(n.len()));
    let (true, Some(lib)) = (include.join("mujoco/mujoco.h").is_file(), libs.first()) else {
        eprintln!(
            "\nerror: the cargo feature `mujoco-c` needs a MuJoCo directory with \
             include/mujoco/mujoco.h and libmujoco.so.X.Y.Z; {} has not both.\n\
             Run `scripts/setup.sh` in the repository root (it installs the PyPI wheel \
             mujoco==4.0.0 into .cache/venv-mj4), or set {MUJOCO_DIR_VAR} to the `mujoco` \
             folder of your installation (e.g. .../site-packages/mujoco).\n",
            dir.display()
        );
        std::process::exit(1);
    };
    println!("cargo::rerun-if-changed={}", dir.join(lib).display());
    println!(
        "cargo::rerun-if-changed={}",
        include.join("mujoco/mujoco.h").display()
    );
    cc::Build::new()
        .file("src/mujoco_shim.c")
        .include(&include)
        .warnings(true)
        .compile("mjcf_forge_mujoco_shim");
    build_patch(&include);
    println!("cargo::rustc-link-search=native={}", dir.display());
    println!("cargo::rustc-link-lib=dylib:+verbatim={lib}");
    if env::var("CARGO_CFG_TARGET_OS").unwrap_or_default() != "windows" {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{}", dir.display());
    }
}
