#!/usr/bin/env bash
# Same-run comparison of mjcf_forge.base with robosuite.models.base (benches/compare/bench_base.py):
# the same Lift-parts code on both class hierarchies, and ElementPath findall on both trees.
#   bash benches/compare/bench_base.sh [ROUNDS]
# Runs in .cache/venv-robosuite-env (robosuite 1.5.2, MuJoCo 3.9.0) with the mjcf_forge
# that scripts/setup.sh installed into .cache/venv, linked alone onto the path.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
bash scripts/setup.sh >/dev/null
bash scripts/setup_robosuite_env.sh >/dev/null
pkg="$(.cache/venv/bin/python -c 'import mjcf_forge, os; print(os.path.dirname(mjcf_forge.__file__))')"
only="$(mktemp -d)"
trap 'rm -rf "$only"' EXIT
ln -s "$pkg" "$only/mjcf_forge"
PYTHONPATH="$only" .cache/venv-robosuite-env/bin/python benches/compare/bench_base.py --rounds "${1:-7}"
