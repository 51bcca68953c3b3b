#!/usr/bin/env bash
# A long differential campaign of the model caches against MuJoCo on random documents
# (mjcf_forge::fuzzing::random_mjcf): the Rust DocumentCache (tests/document_differential.rs)
# and the Python one with the caller's ways of holding models (python/tests/test_differential.py),
# each over SEEDS seeds x VARIANTS variants, and random scenes (fuzzing::random_scene, half
# as many) through each face's ModelCache and the Python superset, under MuJoCo 3.17.0 (and
# the Python face under 4.0.0 too). Prints each face's counts; a finding fails the run with the seed/variant that
# shows it. Results go in docs/limits.md ("Differential campaigns").
# Usage: bash scripts/differential.sh [SEEDS] [VARIANTS]   (default 2000 8)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export MJCF_FORGE_DIFFERENTIAL="${1:-2000},${2:-8}"
echo "== Rust DocumentCache, MuJoCo 3.17.0 ($MJCF_FORGE_DIFFERENTIAL)"
cargo test --release --features mujoco --test document_differential -- --nocapture 2>&1 | grep -E "answered|findings|test result|^[0-9]+/|^scene|^includes"
status=0
for py in .cache/venv/bin/python .cache/venv-mj4/bin/python; do
  echo "== Python caches, MuJoCo $($py -c 'import mujoco; print(mujoco.__version__)')"
  $py -m pytest python/tests/test_differential.py -q -s -p no:cacheprovider > "${TMPDIR:-/tmp}/differential.log" 2>&1 || status=1
  grep -E "^python:|^scenes:|passed|failed|^E  " "${TMPDIR:-/tmp}/differential.log" || true
done
exit $status
