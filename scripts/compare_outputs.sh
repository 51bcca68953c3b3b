#!/usr/bin/env bash
# Before/after check for changes that must not change behaviour: runs the same commands
# with two builds of `mjcf-forge` and compares every output byte for byte.
#
#   bash scripts/compare_outputs.sh OLD_BINARY NEW_BINARY [WORK_DIR]
#
# What it runs with each binary: `generate` on the built-in demo and on every scene file of
# the repository (two seeds, one thread and two, folders and tar), `inline` of every
# wheel model that compiles (pretty and compact), `prefix`, `info --json`, a robosuite
# scene built with `merge`, and `export` of models with meshes and textures. The binaries
# are run with the repository root as working folder, so scene files name the same
# models. Exits non-zero and lists the differing files when any output differs.
# Needs scripts/setup.sh's corpus (.cache/corpus/models.txt).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
old="$(realpath "$1")"
new="$(realpath "$2")"
work="${3:-$(mktemp -d)}"
rm -rf "$work/old" "$work/new"
mapfile -t models < .cache/corpus/models.txt
rs=.cache/corpus/robosuite-1.5.2/robosuite/models/assets

run_all() { # binary out-dir
  local bin="$1" out="$2"
  mkdir -p "$out"
  for seed in 7 123456789; do
    "$bin" generate -n 300 --seed "$seed" --threads 1 -o "$out/demo-$seed" >/dev/null 2>&1
    "$bin" generate -n 300 --seed "$seed" --threads 2 -o "$out/demo-$seed.tar" >/dev/null 2>&1
    for scene in corpora/scenes/patch/*.toml benches/scenes/*.toml; do
      local name
      name="$(basename "$scene" .toml)"
      "$bin" generate "$scene" -n 200 --seed "$seed" -o "$out/$name-$seed" >/dev/null 2>&1
      "$bin" generate "$scene" -n 100 --start 1000 --seed "$seed" --pretty --shard 1/2 \
        -o "$out/$name-$seed-shard.tar" >/dev/null 2>&1
    done
  done
  # Each model by its index, so files of the same name in different wheels do not collide.
  local i=0
  mkdir -p "$out/inline" "$out/compact" "$out/prefix" "$out/info"
  for m in "${models[@]}"; do
    "$bin" inline "$m" -o "$out/inline/$i.xml" >/dev/null 2>&1 || echo "failed" >"$out/inline/$i.err"
    "$bin" inline "$m" --compact -o "$out/compact/$i.xml" >/dev/null 2>&1 || true
    "$bin" prefix "$m" --prefix "p${i}_" -o "$out/prefix/$i.xml" >/dev/null 2>&1 \
      || echo "failed" >"$out/prefix/$i.err"
    "$bin" info "$m" --prefix "p${i}_" --json >"$out/info/$i.json" 2>&1 || true
    i=$((i + 1))
  done
  "$bin" prefix "$rs/robots/panda/robot.xml" --prefix robot0_ -o "$out/robot0.xml" >/dev/null 2>&1
  "$bin" merge "$out/robot0.xml" \
    --part "$rs/grippers/panda_gripper.xml:gripper0_:robot0_right_hand" \
    -o "$out/arm.xml" >/dev/null 2>&1 || echo failed >"$out/arm.err"
  "$bin" merge "$rs/arenas/table_arena.xml" --part "$out/arm.xml" \
    --part "$rs/objects/can.xml:can0_" --part "$rs/objects/milk.xml:milk0_" \
    -o "$out/merge.xml" >/dev/null 2>&1 || echo failed >"$out/merge.err"
  "$bin" export "$rs/robots/panda/robot.xml" -o "$out/export-panda" >/dev/null 2>&1
  "$bin" export "$rs/arenas/bins_arena.xml" -o "$out/export-bins.tar" --tar >/dev/null 2>&1
}

run_all "$old" "$work/old"
run_all "$new" "$work/new"
files="$(cd "$work/old" && find . -type f | wc -l)"
if diff -r -q "$work/old" "$work/new"; then
  echo "compare_outputs: identical: $files files ($(du -sh "$work/old" | cut -f1)) in $work"
else
  echo "compare_outputs: outputs differ (above); both sets are in $work" >&2
  exit 1
fi
