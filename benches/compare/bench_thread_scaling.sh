#!/usr/bin/env bash
# How `generate` scales from 1 to 2 threads (issue 8's "1 to 2 threads at least 1.8x"):
# `mjcf-forge generate SCENE -n N -o - --threads T > /dev/null` for T = 1 and 2, in ROUNDS
# interleaved rounds (1, 2, 1, 2, ...), each a whole process (scene load included).
# Variants per second come from `--json` (the command's own clock, from start-up to the
# last byte written). Prints each run, each round's ratio (2 threads / 1 thread), the
# median of the rounds' ratios and the ratio of the best runs. Each run also shows the
# CPUs it kept busy and its CPU time per variant (user + sys from /usr/bin/time, scene
# load included): on a shared host a slow round is told apart from a pipeline that
# leaves a core idle (the first number drops) by the second (the work itself took
# longer). Run it on an otherwise idle machine: with another process on
# one of the two cores, the two-thread runs share it.
#
# Usage: bash benches/compare/bench_thread_scaling.sh [SCENE]   (default benches/scenes/lift5.toml)
# Env: N (variants per run, default 200000), ROUNDS (default 5), BIN (default
#      target/release/mjcf-forge, built here when it is the default).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
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
times="$(mktemp)"
trap 'rm -f "$times"' EXIT
# One run: "variants/s CPUs-busy CPU-us-per-variant".
run() {
  local json seconds rate cpu
  json="$(/usr/bin/time -f '%U %S' -o "$times" \
    "$BIN" generate "$SCENE" -n "$N" -o - --threads "$1" --json 2>&1 >/dev/null)"
  seconds="$(sed -nE 's/.*"seconds":([0-9.e-]+).*/\1/p' <<<"$json")"
  rate="$(sed -nE 's/.*"variants_per_second":([0-9.]+).*/\1/p' <<<"$json")"
  cpu="$(awk '{ print $1 + $2 }' "$times")"
  [[ -n "$seconds" && -n "$rate" ]] || return 1
  awk -v r="$rate" -v s="$seconds" -v c="$cpu" -v n="$N" \
    'BEGIN { printf "%s %.2f %.2f\n", r, c / s, c * 1e6 / n }'
}
best1=0
best2=0
ratios=()
for r in $(seq 1 "$ROUNDS"); do
  read -r one cpus1 us1 < <(run 1) || true
  read -r two cpus2 us2 < <(run 2) || true
  [[ -n "${one:-}" && -n "${two:-}" ]] || { echo "bench_thread_scaling: generate failed" >&2; exit 1; }
  awk -v r="$r" -v a="$one" -v b="$two" -v c1="$cpus1" -v u1="$us1" -v c2="$cpus2" -v u2="$us2" \
    'BEGIN { printf "round %d: 1 thread %.0f/s (%s CPUs, %s us CPU per variant), 2 threads %.0f/s (%s CPUs, %s us), ratio %.2fx\n", r, a, c1, u1, b, c2, u2, b / a }'
  ratios+=("$(awk -v a="$one" -v b="$two" 'BEGIN { print b / a }')")
  best1="$(awk -v a="$best1" -v b="$one" 'BEGIN { print (b > a) ? b : a }')"
  best2="$(awk -v a="$best2" -v b="$two" 'BEGIN { print (b > a) ? b : a }')"
done
printf '%s\n' "${ratios[@]}" | sort -g \
  | awk '{ r[NR] = $1 } END { m = (NR % 2) ? r[(NR + 1) / 2] : (r[NR / 2] + r[NR / 2 + 1]) / 2;
      printf "median of the rounds: %.2fx (lowest %.2fx, highest %.2fx)\n", m, r[1], r[NR] }'
awk -v a="$best1" -v b="$best2" \
  'BEGIN { printf "best: 1 thread %.0f/s, 2 threads %.0f/s, ratio %.2fx\n", a, b, b / a }'
