#!/usr/bin/env bash
# Same-run speed comparison of assembling robosuite's Lift scene (table arena, Panda
# with Rethink mount and Panda gripper, 5 XML objects, merged and written to a string):
# robosuite 1.5.2 (benches/compare/bench_robosuite_scene.py) vs mjcf-forge
# (benches/tools/assemble_scene.rs), back to back on this machine.
#
# Prints the mjcf-forge line, the robosuite JSON for its own classes (--mode classes,
# as Lift builds the scene) and for its bare MujocoXML merge path (--mode merge,
# exactly mjcf-forge's steps), and the ratios robosuite time / mjcf-forge time.
#
# Not identical measurements, read with the docstring of bench_robosuite_scene.py:
#  - robosuite: best of RUNS single scenes; its constructors parse the XML files each
#    time (parse_ms_per_scene is that share on its own); no way to start from parsed trees.
#  - mjcf-forge: mean per scene over FORGE_SCENES scenes, best of FORGE_REPEATS
#    processes; starts from documents already loaded (cloned per scene).
# Env: RUNS (default 20), FORGE_SCENES (default 1000), FORGE_REPEATS (default 3).
# Needs scripts/setup_robosuite.sh (run here; fast when done).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
RUNS="${RUNS:-20}"
FORGE_SCENES="${FORGE_SCENES:-1000}"
FORGE_REPEATS="${FORGE_REPEATS:-3}"
PY=.cache/venv-robosuite/bin/python

bash scripts/setup_robosuite.sh >/dev/null
cargo build --release --quiet --example assemble_scene

# mjcf-forge: "N scenes, B bytes, X us per scene"; keep the fastest process.
forge_best=""
for _ in $(seq "$FORGE_REPEATS"); do
  line="$(target/release/examples/assemble_scene "$FORGE_SCENES")"
  us="$(sed -E 's/.*, ([0-9.]+) us per scene$/\1/' <<<"$line")"
  if [[ -z "$forge_best" ]] || awk -v a="$us" -v b="$forge_best" 'BEGIN{exit !(a<b)}'; then
    forge_best="$us"; forge_line="$line"
  fi
done

rs_classes="$("$PY" benches/compare/bench_robosuite_scene.py --runs "$RUNS" --mode auto 2>/dev/null)"
rs_merge="$("$PY" benches/compare/bench_robosuite_scene.py --runs "$RUNS" --mode merge 2>/dev/null)"

echo "mjcf-forge:          $forge_line (best of $FORGE_REPEATS processes)"
echo "robosuite (classes): $rs_classes"
echo "robosuite (merge):   $rs_merge"
"$PY" - "$forge_best" "$rs_classes" "$rs_merge" <<'PY'
import json, sys
forge_us = float(sys.argv[1])
for label, raw in (("robosuite " + json.loads(sys.argv[2])["mode"], sys.argv[2]), ("robosuite merge", sys.argv[3])):
    r = json.loads(raw)
    rs_us = r["ms_per_scene"] * 1e3
    no_parse_us = (r["ms_per_scene"] - r["parse_ms_per_scene"]) * 1e3
    print(f"{label}: {rs_us:.0f} us/scene vs mjcf-forge {forge_us:.1f} us/scene: "
          f"ratio {rs_us / forge_us:.1f}x (minus robosuite's parse share: {no_parse_us / forge_us:.1f}x)")
PY
