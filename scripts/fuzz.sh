#!/usr/bin/env bash
# Runs the fuzz targets of fuzz/ (cargo-fuzz layout) for a fixed time each, one after the
# other, on the stable toolchain (`-s none`: no sanitizer, which needs nightly).
#
#   bash scripts/fuzz.sh [SECONDS] [TARGET ...]    # default: 60 s, every target
#
# Seeds come from corpora/ (the feature, error, prefix and merge cases); what libFuzzer
# finds stays in fuzz/corpus/TARGET (git-ignored) for the next run. Each target's log is in
# fuzz/logs/TARGET.log and its execution count is printed at the end. A crash stops the
# script with its input in fuzz/artifacts/TARGET/: make it a regression case in
# corpora/fuzz/ (see tests/fuzz_regressions.rs). Installs cargo-fuzz from crates.io once.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

seconds="${1:-60}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(roundtrip readers prefix merge scene)
fi

if ! cargo fuzz --version >/dev/null 2>&1; then
  cargo install cargo-fuzz --locked
fi

cd fuzz
for t in "${targets[@]}"; do cargo fuzz build -s none "$t"; done

# Seeds: every model we wrote (as is for the readers; with a prefix, or as base and part,
# for the others, in the input layouts the targets document); scene descriptions for
# the scene target.
seed() {
  local target="$1" dir="corpus/$1"
  mkdir -p "$dir"
  local i=0
  for f in ../corpora/features/*.xml ../corpora/errors/*.xml ../corpora/prefix/*.xml \
           ../corpora/merge/*.xml ../corpora/urdf/*.urdf ../corpora/fuzz/*/*; do
    [ -f "$f" ] || continue
    i=$((i + 1))
    case "$target" in
      roundtrip|readers) cp "$f" "$dir/seed-$i" ;;
      prefix) { printf 'p0_\0'; cat "$f"; } > "$dir/seed-$i" ;;
      merge) { cat "$f"; printf '\0'; cat "$f"; printf '\0p1_\0'; } > "$dir/seed-$i" ;;
      scene) case "$f" in ../corpora/fuzz/scene/*) cp "$f" "$dir/seed-$i" ;; esac ;;
    esac
  done
  if [ "$target" = scene ]; then
    cp ../corpora/scenes/demo/*.toml "$dir/"
  fi
}

mkdir -p logs
for t in "${targets[@]}"; do
  seed "$t"
  echo "== fuzz $t for ${seconds}s"
  status=0
  cargo fuzz run -s none "$t" "corpus/$t" -- \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
    -print_final_stats=1 > "logs/$t.log" 2>&1 || status=$?
  grep -E '^Done [0-9]+ runs' "logs/$t.log" | sed "s/^/$t: /" || true
  if [ "$status" -ne 0 ]; then
    tail -n 40 "logs/$t.log"
    echo "fuzz target $t failed (input in fuzz/artifacts/$t/)" >&2
    exit 1
  fi
done
