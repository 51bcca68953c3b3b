#!/usr/bin/env bash
# The slow client runs that CI samples, in full (results: docs/fidelity.md):
#
#   bash scripts/test_full.sh
#
# - every test of python/tests/test_batch_sim.py, the ones marked `full` included (MuJoCo
#   Warp and MJX on the big scenes: lift5, LIBERO, the demo, Menagerie's UR5e), with
#   MJCF_FORGE_FULL=1 (CI runs the unmarked ones: the same checks on the small scenes);
# - LIBERO's 130 tasks stock against the switch (scripts/libero_check.sh);
# - robosuite's clients in full (scripts/clients_full.sh --robosuite-only: 10 demos of 50
#   steps in five environments, every environment, in the three robosuite venvs);
# - every wheel model in the document, prefix, merge and geometry judges (CI judges every
#   second: tests/common/mod.rs, `sampled`) and every corpus URDF prepared for MuJoCo
#   (tests/urdf_judge.rs; CI judges every fourth), with MJCF_FORGE_FULL=1; the 21 further
#   URDF wheels (scripts/urdf_wide.sh).
# Sets up first (idempotent), as scripts/test.sh does.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup.sh
bash scripts/setup_sim_env.sh
bash scripts/setup_libero_env.sh
bash scripts/setup_robosuite_env.sh
bash scripts/setup_mj2_env.sh
echo "== batched simulators, every scene"
MJCF_FORGE_FULL=1 .cache/venv-sim/bin/python -m pytest python/tests/test_batch_sim.py -q -p no:cacheprovider
echo "== LIBERO's 130 tasks, stock against the switch"
bash scripts/libero_check.sh
echo "== robosuite's clients in full, stock against the switch"
bash scripts/clients_full.sh --robosuite-only
echo "== every wheel model (CI judges every second), every corpus URDF prepared for MuJoCo"
MJCF_FORGE_FULL=1 cargo test --test document_judge --test prefix_judge --test merge_judge \
  --test geometry_judge --test urdf_judge
echo "== the further URDF wheels"
bash scripts/urdf_wide.sh
