#!/usr/bin/env bash
# Optional: makes robosuite's MujocoXML importable for benches/compare/bench_robosuite.py
# (the same-run speed baseline). Idempotent; fast when already done.
#
# What it installs: a venv .cache/venv-robosuite with only numpy, pillow and
# termcolor (scripts/requirements-robosuite.txt), the third-party modules that
# robosuite.models.base and robosuite.utils.mjcf_utils import. robosuite's own
# code is NOT pip-installed: the bench puts the unpacked robosuite==1.5.2 wheel
# (.cache/corpus/robosuite-1.5.2, made by scripts/setup.sh, which this runs
# first) on sys.path and skips only robosuite/__init__.py, which imports every
# environment, controller and robot and with them numba, scipy, opencv, mink,
# qpsolvers and pynput (a full `pip install robosuite==1.5.2` is ~1.3 GB).
# The timed code (MujocoXML, mjcf_utils, macros) is robosuite's, unchanged.
#
# For the full install instead (same timings, see bench --import-mode):
#   python3 -m venv .cache/venv-robosuite-full
#   .cache/venv-robosuite-full/bin/pip install robosuite==1.5.2
#   .cache/venv-robosuite-full/bin/python benches/compare/bench_robosuite.py --import-mode installed
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT="$(pwd)"
VENV="$ROOT/.cache/venv-robosuite"
PY="$VENV/bin/python"
REQ="$ROOT/scripts/requirements-robosuite.txt"
PYTHON="${PYTHON:-python3}"

# The corpus (and models.txt, which the bench reads).
bash "$ROOT/scripts/setup.sh"

if [[ ! -x "$PY" ]]; then
  echo "setup_robosuite: creating venv $VENV"
  "$PYTHON" -m venv "$VENV"
fi
req_sha="$(sha256sum "$REQ" | cut -d' ' -f1)"
stamp="$VENV/.requirements.sha256"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$req_sha" ]]; then
  echo "setup_robosuite: venv up to date"
else
  echo "setup_robosuite: installing $REQ"
  "$PY" -m pip install --quiet --disable-pip-version-check -r "$REQ"
  echo "$req_sha" > "$stamp"
fi
echo "setup_robosuite: run  $PY benches/compare/bench_robosuite.py"
