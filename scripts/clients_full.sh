#!/usr/bin/env bash
# The full runs of what CI samples of "the switch is stock wherever a client looks"
# (results: docs/fidelity.md, "What a client reads"):
# - python/tests/test_robosuite_clients.py with MJCF_FORGE_CLIENTS_FULL=1: 10 demos of 50
#   steps in Lift, PickPlaceCan, NutAssemblySquare, Stack and Door, recorded, replayed
#   across modes, converted, and every environment of ALL_ENVIRONMENTS, under robosuite
#   1.5.2 (MuJoCo 3.9.0), robosuite 1.4.0 (MuJoCo 3.3.1) and robosuite 1.4.0 (MuJoCo 2.3.7);
# - every LIBERO task's get_xml() after its first reset, stock against the switch
#   (scripts/libero_check.sh --model-only, 130 tasks).
#
#   bash scripts/clients_full.sh [--robosuite-only | --libero-only]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup.sh >/dev/null
bash scripts/setup_robosuite_env.sh >/dev/null
bash scripts/setup_libero_env.sh >/dev/null
bash scripts/setup_mj2_env.sh >/dev/null
if [[ "${1:-}" != --libero-only ]]; then
  MJCF_FORGE_CLIENTS_FULL=1 .cache/venv/bin/python -m pytest python/tests/test_robosuite_clients.py \
    -q -p no:cacheprovider
fi
if [[ "${1:-}" != --robosuite-only ]]; then
  bash scripts/libero_check.sh --model-only
fi
