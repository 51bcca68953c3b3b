#!/usr/bin/env bash
# Runs every test of mjcf-forge (the README's test command; .ci/run calls it):
# formatting, clippy, the Rust tests with and without the `mujoco` feature (real MuJoCo
# judges every output), the judge's own tests, the Python package's tests (setup has
# built and installed it into .cache/venv) and a short run of each fuzz target. Sets up
# first (idempotent).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/setup.sh

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy"
cargo clippy --all-targets -- -D warnings
cargo clippy --all-targets --features mujoco -- -D warnings
# The Python bindings crate (the workspace's other member; not built by the commands above).
PYO3_PYTHON="$PWD/.cache/venv/bin/python" cargo clippy -p mjcf-forge-python --all-targets -- -D warnings
echo "== cargo test (default features)"
cargo test --all-targets
echo "== cargo test --features mujoco (with doctests)"
cargo test --features mujoco
echo "== judge self-tests"
.cache/venv/bin/python -m pytest tests/judge -q -p no:cacheprovider
echo "== python package (pytest: API, errors, threads, MuJoCo judge, Gymnasium, Ray)"
.cache/venv/bin/python -m pytest python/tests -q -p no:cacheprovider
echo "== fuzz smoke run (5 s per target; long campaigns: bash scripts/fuzz.sh SECONDS)"
bash scripts/fuzz.sh 5
