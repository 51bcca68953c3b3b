#!/usr/bin/env bash
# The batched simulators' venv, .cache/venv-sim, for python/tests/test_batch_sim.py: the
# packages pinned in scripts/requirements-sim.txt (MuJoCo 4.0.0, MuJoCo Warp 4.0.0, Warp
# 1.19.0, MJX and JAX on CPU), and mjcf_forge built from this checkout into it (maturin
# develop --release). Idempotent: the install reruns only when the requirements change,
# the build when maturin finds the sources changed. Needs python3.11 (or PYTHON) and PyPI.
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
echo "setup_sim_env: building mjcf_forge into $VENV"
VIRTUAL_ENV="$VENV" PATH="$VENV/bin:$PATH" "$VENV/bin/maturin" develop --release
