#!/usr/bin/env bash
# LIBERO's 130 tasks stock and on the switch, compared bit for bit (what
# python/tests/test_libero.py checks on five of them in CI). Results: docs/fidelity.md.
#
#   bash scripts/libero_check.sh [--model-only] [--resume] [SUITE:INDEX ...]
#
# --resume keeps the records of an earlier run (of the same kind) and runs only the tasks
# it has not recorded both ways: a long campaign can stop and go on.
# Without tasks: every task of libero_spatial, libero_object, libero_goal, libero_10 and
# libero_90. Each way runs in its own process (two at once); each task's record is
# .cache/libero-check/{stock,switch}/<suite>-<index>.npz (python/tests/drivers/libero_run.py), and
# the last line says how many tasks were built, how many have equal models, how many the
# same get_xml() text (after the first reset and after each hard reset), and how many
# equal observations (50 steps with cameras, then a hard reset and 5 steps, unless
# --model-only). Model arrays are recorded as digests (--digest).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT="$(pwd)"
bash scripts/setup.sh >/dev/null
bash scripts/setup_libero_env.sh >/dev/null
PY="$ROOT/.cache/venv-libero/bin/python"
OUT="$ROOT/.cache/libero-check"
only="$OUT/path"
mkdir -p "$only"
ln -sfn "$("$ROOT/.cache/venv/bin/python" -c 'import mjcf_forge, os; print(os.path.dirname(mjcf_forge.__file__))')" "$only/mjcf_forge"
flags=(--digest --cameras --steps 50 --resets 1)
resume=0
while [[ "${1:-}" == --* ]]; do
  case "$1" in
    --model-only) flags=(--digest --model-only) ;;
    --resume) resume=1 ;;
    *) echo "libero_check: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
tasks=("$@")
if [[ ${#tasks[@]} -eq 0 ]]; then
  read -r -a tasks <<<"$(PYTHONPATH="$ROOT/python/tests/drivers" LIBERO_CONFIG_PATH="$ROOT/.cache/libero-config" "$PY" -c \
    'from libero_tasks import task_map; print(" ".join(f"{s}:{i}" for s, t in task_map().items() for i in range(len(t))))')"
fi
if [[ $resume -eq 0 ]]; then
  rm -rf "$OUT/stock" "$OUT/switch"
else
  todo=()
  for t in "${tasks[@]}"; do
    name="${t/:/-}"
    [[ -f "$OUT/stock/$name.npz" && -f "$OUT/switch/$name.npz" ]] || todo+=("$t")
  done
  tasks=("${todo[@]}")
fi
if [[ ${#tasks[@]} -gt 0 ]]; then
  for mode in stock switch; do
    PYTHONPATH="$only" PYTHONHASHSEED=0 LIBERO_CONFIG_PATH="$ROOT/.cache/libero-config" MUJOCO_GL="${MUJOCO_GL:-egl}" \
      "$PY" python/tests/drivers/libero_run.py "$mode" "$OUT/$mode" "${tasks[@]}" "${flags[@]}" >>"$OUT/$mode.log" 2>&1 &
  done
  wait
fi
"$ROOT/.cache/venv/bin/python" - "$OUT" <<'PY'
import glob, os, sys
import numpy as np
out = sys.argv[1]
built = models = observed = kept = xmls = 0
# Tasks recorded both ways (a stopped run may have recorded one way only).
records = sorted(p for p in glob.glob(f"{out}/stock/*.npz")
                 if not p.endswith(".part.npz") and os.path.exists(p.replace("/stock/", "/switch/")))
for path in records:
    a = dict(np.load(path))
    b = dict(np.load(path.replace("/stock/", "/switch/")))
    name = os.path.basename(path)[:-4]
    if "error" in a or "error" in b:
        print(name, "error:", a.get("error"), b.get("error"))
        continue
    built += 1
    kept += int(b.get("kept", 0))
    def same(prefix):
        keys = {k for k in a if k.startswith(prefix)} | {k for k in b if k.startswith(prefix)}
        return [k for k in sorted(keys) if k not in a or k not in b or a[k].dtype != b[k].dtype
                or a[k].shape != b[k].shape or a[k].tobytes() != b[k].tobytes()]
    bad = same("model/")
    models += not bad
    wrote = same("xml/")
    xmls += not wrote and any(k.startswith("xml/") for k in a)
    bad += wrote
    obs = [k for p in ("obs/", "success", "state", "reset/", "again/") for k in same(p)]
    observed += not obs and any(k.startswith("obs/") for k in a)
    if bad or obs:
        print(name, "differs:", (bad + obs)[:10])
n = len(records)
print(f"libero_check: {n} tasks, {built} built both ways, {models} models bit-equal, "
      f"{xmls} with get_xml() byte-equal, "
      f"{observed} with every observation bit-equal, {kept} hard resets on the switch kept the simulation")
PY
