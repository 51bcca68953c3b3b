#!/usr/bin/env bash
# Sets up everything (Python venv with the pinned MuJoCo, the wheel corpora of
# scripts/setup.sh, a release build with MuJoCo compiled in) and runs the main jobs on built-in
# examples, writing to out/:
#   0. generate: 500 seeded variants of the built-in demo scene, validated by MuJoCo;
#   1. inline: a feature model with includes, default classes and compiler dirs;
#   2. merge: robosuite's Lift scene (table arena, Panda + gripper, a can), validated by
#      compiling it with MuJoCo;
#   3. compile --json and info --json on the results.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/setup.sh
cargo build --release --features mujoco
forge=target/release/mjcf-forge
rs=.cache/corpus/robosuite-1.5.2/robosuite/models/assets
mkdir -p out

echo "== generate: 500 variants of the built-in demo scene, each compiled and checked by MuJoCo -> out/demo/"
rm -rf out/demo
"$forge" generate -n 500 -o out/demo --validate
head -c 600 out/demo/manifest.jsonl; echo " ..."

echo "== inline corpora/features/include_nested.xml -> out/include_nested.xml"
"$forge" inline corpora/features/include_nested.xml -o out/include_nested.xml --validate

echo "== merge a Lift scene -> out/lift.xml"
"$forge" merge "$rs/arenas/table_arena.xml" \
  --part "$rs/robots/panda/robot.xml:robot0_" \
  --part "$rs/grippers/panda_gripper.xml:gripper0_:robot0_right_hand" \
  --part "$rs/objects/can.xml:cube_" \
  -o out/lift.xml --validate

echo "== compile --json out/lift.xml"
"$forge" compile out/lift.xml --json
echo "== info --json (the can as one instance)"
"$forge" info "$rs/objects/can.xml" --prefix can0_ --json

echo "== python: a Gymnasium environment drawing a new scene variant per reset (the built-in demo scene)"
.cache/venv/bin/python python/examples/gym_env.py --episodes 3
echo "== python: the same on a scene of four structures: repeated ones are patched, not compiled"
.cache/venv/bin/python python/examples/gym_env.py corpora/scenes/patch/patch.toml --episodes 8
