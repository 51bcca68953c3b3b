#!/usr/bin/env bash
# Same-run cost of writing outputs against the filesystem's own cost per file: the 52
# robosuite models of the corpus written by `mjcf-forge inline --out-dir` (the command
# on the 41 with distinct file names; in process, all 52) and through OutputDir, against
# a plain std::fs::write loop of the same bytes (benches/tools/out_dir_cost.rs). Prints one
# JSON line; the *_ratio fields are the figures (1.0 = the filesystem's own cost).
# The OutputDir part writes COPIES (default 20) times the 52 outputs, so its one sync at
# the end is paid as in a batch rather than per 52 files.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
RUNS="${RUNS:-30}"
bash scripts/setup.sh >/dev/null
cargo build --release --quiet --bin mjcf-forge --example out_dir_cost
mapfile -t files < <(grep "/robosuite-" .cache/corpus/models.txt)
target/release/examples/out_dir_cost --runs "$RUNS" --copies "${COPIES:-20}" --bin target/release/mjcf-forge "${files[@]}"
