#!/usr/bin/env bash
# Runs every test of mjcf-forge (the README's test command; .ci/run calls it):
# formatting, clippy, the Rust tests without the `mujoco` feature and once with it per
# MuJoCo version the feature links (3.17.0 from .cache/venv, as .cargo/config.toml sets
# MJCF_FORGE_PYTHON, and 4.0.0 from .cache/venv-mj4 through MJCF_FORGE_MUJOCO_DIR; real
# MuJoCo 3.17.0 and 4.0.0 judge every output in each run), the judge's own tests under both
# versions, the Python package's tests (setup has built and installed it into .cache/venv).
# Fuzzing is not part of it (tests/fuzz_regressions.rs replays what it found; campaigns:
# scripts/fuzz.sh). Sets up first (idempotent).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/setup.sh
# robosuite 1.5.2 with MuJoCo 3.9.0, where python/tests/test_robosuite_use.py builds
# robosuite's own classes both ways (idempotent; about 300 MB of wheels the first time).
bash scripts/setup_robosuite_env.sh
# LIBERO 0.1.1 with robosuite 1.4.0 and MuJoCo 3.3.1 in .cache/venv-libero, with its assets,
# for python/tests/test_libero.py (idempotent; about 550 MB of wheels the first time).
bash scripts/setup_libero_env.sh
# robosuite 1.4.0 on MuJoCo 2.3.7 in .cache/venv-mj2 (the oldest MuJoCo robosuite 1.4.0
# accepts), for python/tests/test_robosuite_clients.py (idempotent; about 150 MB the first time).
bash scripts/setup_mj2_env.sh
# MuJoCo Warp, MJX and JAX on CPU in .cache/venv-sim, with mjcf_forge built into it, for
# python/tests/test_batch_sim.py (idempotent; Warp's kernels cached in .cache/warp-kernels).
bash scripts/setup_sim_env.sh

echo "== cargo fmt --check [${SECONDS}s in]"
cargo fmt --all -- --check
echo "== cargo clippy [${SECONDS}s in]"
cargo clippy --all-targets -- -D warnings
cargo clippy --all-targets --features mujoco -- -D warnings
# The Python bindings crate (the workspace's other member; not built by the commands above).
PYO3_PYTHON="$PWD/.cache/venv/bin/python" cargo clippy -p mjcf-forge-python --all-targets -- -D warnings
echo "== cargo test (default features) [${SECONDS}s in]"
cargo test --all-targets
echo "== cargo test --features mujoco, MuJoCo 3.17.0 (with doctests) [${SECONDS}s in]"
cargo test --features mujoco
# From 4.0 on the wheel `mujoco` depends on `mujoco-core`, which puts libmujoco.so.4.0.0 and
# include/ into the same `mujoco` folder; the venv's Python says where that is. Its own
# target folder, so the two MuJoCo builds do not evict each other's artifacts (CI, which
# builds each once, sets MJCF_FORGE_MJ4_TARGET=target: the dependencies build once).
echo "== cargo test --features mujoco, MuJoCo 4.0.0 (with doctests) [${SECONDS}s in]"
MJ4_DIR="$(.cache/venv-mj4/bin/python -c 'import mujoco, os; print(os.path.dirname(mujoco.__file__))')"
MJCF_FORGE_MUJOCO_DIR="$MJ4_DIR" CARGO_TARGET_DIR="${MJCF_FORGE_MJ4_TARGET:-target/mujoco-4}" \
  cargo test --features mujoco
echo "== judge self-tests (MuJoCo 3.17.0 and 4.0.0) [${SECONDS}s in]"
.cache/venv/bin/python -m pytest tests/judge -q -p no:cacheprovider
.cache/venv-mj4/bin/python -m pytest tests/judge -q -p no:cacheprovider
echo "== python package (pytest: API, errors, threads, MuJoCo judge, Gymnasium, Ray) [${SECONDS}s in]"
# (test_batch_sim.py needs MuJoCo Warp and JAX: it runs in .cache/venv-sim below.)
# (test_libero.py runs LIBERO in .cache/venv-libero, MuJoCo 3.3.1, stock and on the switch.)
.cache/venv/bin/python -m pytest python/tests -q -p no:cacheprovider --ignore=python/tests/test_batch_sim.py --durations=15
echo "== ModelCache, DocumentCache, URDF and MuJoCo's last loaded XML under MuJoCo 4.0.0 (judged against 4.0.0's compile and import) [${SECONDS}s in]"
.cache/venv-mj4/bin/python -m pytest python/tests/test_model_cache.py python/tests/test_world_batch.py python/tests/test_document_cache.py python/tests/test_differential.py python/tests/test_urdf.py python/tests/test_last_xml.py -q -p no:cacheprovider
# MuJoCo's last loaded XML model under LIBERO's MuJoCo 3.3.1 too, where a write through
# the held load covers a geom's size and frame (mjcf_forge._last_xml.copied_back).
only="$(mktemp -d)"
ln -s "$(.cache/venv/bin/python -c 'import mjcf_forge, os; print(os.path.dirname(mjcf_forge.__file__))')" "$only/mjcf_forge"
PYTHONPATH="$only:python/tests" .cache/venv-libero/bin/python -m pytest python/tests/test_last_xml.py -q -p no:cacheprovider
rm -rf "$only"
# robosuite's task XMLs (written by the robosuite venv) through a DocumentCache, judged by 4.0.0.
.cache/venv-mj4/bin/python -m pytest python/tests/test_robosuite_resets.py -k task_xmls -q -p no:cacheprovider
echo "== batched simulators (MuJoCo Warp, MJX on JAX's CPU backend, CPU MuJoCo) judge WorldBatch [${SECONDS}s in]"
.cache/venv-sim/bin/python -m pytest python/tests/test_batch_sim.py -q -p no:cacheprovider
echo "== all tests passed [${SECONDS}s]"
