#!/usr/bin/env bash
# Optional: a real, pip-installed robosuite==1.5.2 that can create its Lift env
# headless, for benches/compare/bench_robosuite_dr.py (the same-run baseline for ModelCache:
# robosuite's DomainRandomizationWrapper on a compiled model). Idempotent; fast when
# already done. Needs only python3 and PyPI.
#
# What it installs: a venv .cache/venv-robosuite-env with exactly the packages pinned
# in scripts/requirements-robosuite-env.txt, installed with --no-deps (that file says
# which of robosuite's declared dependencies are left out or swapped, and why MuJoCo
# is 3.9.0 there and not the judge's 3.17.0). Unlike scripts/setup_robosuite.sh, which
# puts only robosuite's XML classes on sys.path, this runs robosuite/__init__.py and
# the whole env stack (controllers, robots, observables, numba), as a user would.
# About 1.3 GB on disk, over half of it robosuite's own meshes for all its robots.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT="$(pwd)"
VENV="$ROOT/.cache/venv-robosuite-env"
PY="$VENV/bin/python"
REQ="$ROOT/scripts/requirements-robosuite-env.txt"
PYTHON="${PYTHON:-python3}"

if [[ ! -x "$PY" ]]; then
  echo "setup_robosuite_env: creating venv $VENV"
  "$PYTHON" -m venv "$VENV"
fi
req_sha="$(sha256sum "$REQ" | cut -d' ' -f1)"
stamp="$VENV/.requirements.sha256"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$req_sha" ]]; then
  echo "setup_robosuite_env: venv up to date"
else
  echo "setup_robosuite_env: installing $REQ"
  # --no-deps: the file is the whole install. pip would otherwise add robosuite's
  # declared opencv-python, mink, qpsolvers, pynput, pytest and tqdm.
  "$PY" -m pip install --quiet --disable-pip-version-check --no-deps -r "$REQ"
  # Fails here, not in the bench, if a pin stops importing (robosuite logs warnings
  # about its macros and optional packages at import: shown only on failure).
  if ! out="$(cd "$VENV" && "$PY" -c \
      "import robosuite; from robosuite.wrappers import DomainRandomizationWrapper" 2>&1)"; then
    echo "$out" >&2
    echo "setup_robosuite_env: robosuite does not import in $VENV" >&2
    exit 1
  fi
  echo "$req_sha" > "$stamp"
fi
echo "setup_robosuite_env: run  $PY benches/compare/bench_robosuite_dr.py"
