#!/usr/bin/env bash
# The batched simulators' venv, .cache/venv-sim, for python/tests/test_batch_sim.py: the
# packages pinned in scripts/requirements-sim.txt (MuJoCo 4.0.0, MuJoCo Warp 4.0.0, Warp
# 1.19.0, MJX and JAX on CPU), and mjcf_forge from the wheel scripts/setup.sh built (run
# it first). Idempotent: the install reruns only when the requirements or the wheel
# change. Needs python3.11 (or PYTHON) and PyPI.
# Warp's compiled kernels go to .cache/warp-kernels (the tests set WARP_CACHE_PATH), so
# only the first run pays their compile (about a minute on CPU).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT="$(pwd)"
VENV="$ROOT/.cache/venv-sim"
PY="$VENV/bin/python"
REQ="$ROOT/scripts/requirements-sim.txt"
PYTHON="${PYTHON:-python3.11}"

if [[ ! -x "$PY" ]]; then
  echo "setup_sim_env: creating venv $VENV"
  "$PYTHON" -m venv "$VENV"
fi
req_sha="$(sha256sum "$REQ" | cut -d' ' -f1)"
stamp="$VENV/.requirements.sha256"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$req_sha" ]]; then
  echo "setup_sim_env: venv up to date"
else
  echo "setup_sim_env: installing $REQ"
  "$PY" -m pip install --quiet --disable-pip-version-check --no-deps -r "$REQ"
  if ! out="$("$PY" -c "import mujoco_warp, warp, jax; from mujoco import mjx" 2>&1)"; then
    echo "$out" >&2
    echo "setup_sim_env: the simulators do not import in $VENV" >&2
    exit 1
  fi
  echo "$req_sha" > "$stamp"
fi
mkdir -p "$ROOT/.cache/warp-kernels"
# The package: the wheel scripts/setup.sh built (abi3, so any CPython 3 takes it), installed
# again only when it changed; no second release build of the bindings.
wheel="$(ls "$ROOT"/.cache/mjcf-forge-wheel/mjcf_forge-*.whl 2>/dev/null | head -n1 || true)"
if [[ -z "$wheel" ]]; then
  echo "setup_sim_env: no wheel in .cache/mjcf-forge-wheel: run scripts/setup.sh first" >&2
  exit 1
fi
wheel_sha="$(sha256sum "$wheel" | cut -d' ' -f1)"
wstamp="$VENV/.mjcf_forge-wheel.sha256"
if [[ -f "$wstamp" && "$(cat "$wstamp")" == "$wheel_sha" ]] && "$PY" -c "import mjcf_forge" 2>/dev/null; then
  echo "setup_sim_env: mjcf_forge up to date"
else
  echo "setup_sim_env: installing $(basename "$wheel") into $VENV"
  "$PY" -m pip install --quiet --disable-pip-version-check --no-deps --force-reinstall "$wheel"
  echo "$wheel_sha" > "$wstamp"
fi
