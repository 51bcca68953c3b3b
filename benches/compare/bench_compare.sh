#!/usr/bin/env bash
# Same-run speed comparison of the document tier with robosuite's MujocoXML:
# both load (inline defaults, resolve paths) and write the same robosuite model files,
# back to back on this machine; prints both JSON lines and the ratio.
# Needs scripts/setup_robosuite.sh (run here if missing).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
RUNS="${RUNS:-50}"
bash scripts/setup_robosuite.sh >/dev/null
cargo build --release --quiet --example load_throughput
rs_json="$(.cache/venv-robosuite/bin/python benches/compare/bench_robosuite.py --runs "$RUNS")"
# Exactly the files robosuite handled.
mapfile -t files < <(.cache/venv-robosuite/bin/python - "$rs_json" <<'PY'
import json, sys
from pathlib import Path
r = json.loads(sys.argv[1])
failed = set(r.get("failed_files", [f if isinstance(f, str) else f[0] for f in r.get("failed", [])]))
for line in Path(".cache/corpus/models.txt").read_text().splitlines():
    if "/robosuite-" in line and line not in failed:
        print(line)
PY
)
ours_json="$(target/release/examples/load_throughput --runs "$RUNS" "${files[@]}")"
echo "robosuite:  $rs_json"
echo "mjcf-forge: $ours_json"
.cache/venv-robosuite/bin/python - "$rs_json" "$ours_json" <<'PY'
import json, sys
rs, ours = json.loads(sys.argv[1]), json.loads(sys.argv[2])
assert rs["bytes"] == ours["bytes"], (rs["bytes"], ours["bytes"])
print(f"files {ours['files']}, {ours['bytes']} bytes: mjcf-forge {ours['mb_per_s']:.1f} MB/s, "
      f"robosuite {rs['mb_per_s']:.1f} MB/s, ratio {ours['mb_per_s'] / rs['mb_per_s']:.1f}x")
PY
