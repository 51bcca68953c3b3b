#!/usr/bin/env bash
# How `generate` scales from 1 to 2 threads (issue 8's "1 to 2 threads at least 1.8x"):
# `mjcf-forge generate SCENE -n N -o - --threads T > /dev/null` for T = 1 and 2, in ROUNDS
# interleaved rounds (1, 2, 1, 2, ...), each a whole process (scene load included).
# Variants per second come from `--json` (the command's own clock, from start-up to the
# last byte written). Prints each run, each round's ratio (2 threads / 1 thread), the
# median of the rounds' ratios and the ratio of the best runs. Run it on an otherwise idle machine: with another process on
# one of the two cores, the two-thread runs share it.
#
# Usage: bash scripts/bench_thread_scaling.sh [SCENE]   (default benches/scenes/lift5.toml)
# Env: N (variants per run, default 200000), ROUNDS (default 5), BIN (default
#      target/release/mjcf-forge, built here when it is the default).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
SCENE="${1:-benches/scenes/lift5.toml}"
N="${N:-200000}"
ROUNDS="${ROUNDS:-5}"
BIN="${BIN:-target/release/mjcf-forge}"
if [[ "$BIN" == target/release/mjcf-forge ]]; then
  if [[ "$SCENE" == benches/scenes/lift5.toml ]]; then
    bash scripts/setup_robosuite.sh >/dev/null
  fi
  cargo build --release --quiet --bin mjcf-forge
fi
echo "machine: $(nproc) cores;$(uptime | sed 's/.*load average/ load average/')"
echo "scene: $SCENE, $N variants per run, $ROUNDS rounds"
rate() {
  "$BIN" generate "$SCENE" -n "$N" -o - --threads "$1" --json 2>&1 >/dev/null \
    | sed -nE 's/.*"variants_per_second":([0-9.]+).*/\1/p'
}
best1=0
best2=0
ratios=()
for r in $(seq 1 "$ROUNDS"); do
  one="$(rate 1)"
  two="$(rate 2)"
  [[ -n "$one" && -n "$two" ]] || { echo "bench_thread_scaling: generate failed" >&2; exit 1; }
  awk -v r="$r" -v a="$one" -v b="$two" \
    'BEGIN { printf "round %d: 1 thread %.0f/s, 2 threads %.0f/s, ratio %.2fx\n", r, a, b, b / a }'
  ratios+=("$(awk -v a="$one" -v b="$two" 'BEGIN { print b / a }')")
  best1="$(awk -v a="$best1" -v b="$one" 'BEGIN { print (b > a) ? b : a }')"
  best2="$(awk -v a="$best2" -v b="$two" 'BEGIN { print (b > a) ? b : a }')"
done
printf '%s\n' "${ratios[@]}" | sort -g \
  | awk '{ r[NR] = $1 } END { m = (NR % 2) ? r[(NR + 1) / 2] : (r[NR / 2] + r[NR / 2 + 1]) / 2;
      printf "median of the rounds: %.2fx (lowest %.2fx, highest %.2fx)\n", m, r[1], r[NR] }'
awk -v a="$best1" -v b="$best2" \
  'BEGIN { printf "best: 1 thread %.0f/s, 2 threads %.0f/s, ratio %.2fx\n", a, b, b / a }'
