#!/usr/bin/env bash
# robosuite 1.4.0 on MuJoCo 2.3.7 (the oldest MuJoCo robosuite 1.4.0 accepts; what
# libero-infinity pins) in .cache/venv-mj2, for python/tests/test_robosuite_clients.py:
# robosuite's clients stock against the switch there, where the switch's model cache is
# off (it needs MuJoCo 3.3) and says so once. Every package is pinned in
# scripts/requirements-mj2.txt and installed with --no-deps. Idempotent; about 150 MB of
# wheels the first time (robosuite's meshes included), cached by pip.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT="$(pwd)"
VENV="$ROOT/.cache/venv-mj2"
PY="$VENV/bin/python"
REQ="$ROOT/scripts/requirements-mj2.txt"
PYTHON="${PYTHON:-python3}"

if [[ ! -x "$PY" ]]; then
  echo "setup_mj2_env: creating venv $VENV"
  "$PYTHON" -m venv "$VENV"
fi
key="$( { sha256sum "$REQ" "${BASH_SOURCE[0]}"; } | sha256sum | cut -d' ' -f1)"
stamp="$VENV/.requirements.sha256"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$key" ]]; then
  echo "setup_mj2_env: venv up to date"
else
  echo "setup_mj2_env: installing $REQ"
  "$PY" -m pip install --quiet --disable-pip-version-check --no-deps -r "$REQ"
  if ! out="$(cd "$VENV" && "$PY" -c "import mujoco, robosuite; from robosuite.wrappers import DataCollectionWrapper" 2>&1)"; then
    echo "$out" >&2
    echo "setup_mj2_env: robosuite does not import in $VENV" >&2
    exit 1
  fi
  echo "$key" > "$stamp"
fi
