"""LIBERO's environment creation and hard reset, stock against the switch
(``mjcf_forge.robosuite.use()``), same run: processes alternate between the two, and each
figure is the median over its runs. Results: docs/speed.md.

    bash scripts/setup_libero_env.sh
    .cache/venv/bin/python benches/compare/bench_libero.py [--tasks SUITE:INDEX ...] [--resets N]
        [--rounds N] [--cameras] [--store off|cold|warm]

Each process makes one task's environment (LIBERO's ``OffScreenRenderEnv``; with the
offscreen render context and the agentview and wrist camera observations at 128x128 when
``--cameras``), hard-resets it ``--resets`` times (``env.reset()``, every LIBERO reset is
a hard one), closes it and makes a second environment of the task (``second``: what a
worker that evaluates the task again pays); ``--rounds`` processes each way per task,
alternating. The switch's processes run with the model store (``MJCF_FORGE_STORE``)
``off``, ``cold`` (a new empty folder per process: the task compiled and stored) or
``warm`` (a folder one untimed switched process filled first: the task loaded).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LIBERO_PY = ROOT / ".cache" / "venv-libero" / "bin" / "python"

CHILD = r"""
import json, os, sys, time
mode, task, resets, cameras = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4] == "1"
if mode == "switch":
    import mjcf_forge.robosuite
    mjcf_forge.robosuite.use()
from libero.libero.envs import OffScreenRenderEnv
from libero_tasks import bddl_file, task_name
suite, _, index = task.partition(":")
bddl = bddl_file(suite, task_name(suite, int(index)))
def make_env():
    env = OffScreenRenderEnv(bddl_file_name=bddl, camera_heights=128, camera_widths=128,
                             has_offscreen_renderer=cameras, use_camera_obs=cameras)
    env.seed(0)
    env.reset()
    return env
t = time.perf_counter()
env = make_env()
make = time.perf_counter() - t
times = []
for _ in range(resets):
    t = time.perf_counter()
    env.reset()
    times.append(time.perf_counter() - t)
env.close()
t = time.perf_counter()
env = make_env()
second = time.perf_counter() - t
print(json.dumps({"make": make, "resets": times, "second": second}))
"""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--tasks", nargs="+", default=["libero_spatial:0", "libero_object:0", "libero_goal:1",
                                                   "libero_10:2", "libero_90:20"])
    ap.add_argument("--resets", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--cameras", action="store_true")
    ap.add_argument("--store", choices=["off", "cold", "warm"], default="off")
    args = ap.parse_args()
    import tempfile

    stores = Path(tempfile.mkdtemp(prefix="bench-libero-store-"))
    only = ROOT / ".cache" / "bench-libero-path"
    only.mkdir(parents=True, exist_ok=True)
    import mjcf_forge

    link = only / "mjcf_forge"
    if link.is_symlink() or link.exists():
        link.unlink()
    link.symlink_to(Path(mjcf_forge.__file__).resolve().parent)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(only), str(ROOT / "python" / "tests" / "drivers")]), PYTHONHASHSEED="0",
               LIBERO_CONFIG_PATH=str(ROOT / ".cache" / "libero-config"))
    env.setdefault("MUJOCO_GL", "egl")
    print(f"LIBERO environment creation and hard reset, {'with' if args.cameras else 'without'} "
          f"cameras, store {args.store}; {args.rounds} processes each way per task, "
          f"{args.resets} resets each; medians")
    print("| task | make: stock s | switch s | x | second: stock s | switch s | x "
          "| reset: stock ms | switch ms | x |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")

    def child(mode: str, task: str, store: str) -> dict:
        out = subprocess.run(
            [str(LIBERO_PY), "-c", CHILD, mode, task, str(args.resets), "1" if args.cameras else "0"],
            env=dict(env, MJCF_FORGE_STORE=store), capture_output=True, text=True, cwd=only, check=False,
        )
        if out.returncode != 0:
            sys.exit(out.stderr[-3000:])
        return json.loads(out.stdout.strip().splitlines()[-1])

    for n, task in enumerate(args.tasks):
        warm = stores / f"warm-{n}"
        if args.store == "warm":
            child("switch", task, str(warm))  # fills the store, untimed
        runs: dict[str, dict[str, list]] = {
            m: {"make": [], "resets": [], "second": []} for m in ("stock", "switch")
        }
        for r in range(args.rounds):
            for mode in ("stock", "switch"):
                store = {"off": "off", "cold": str(stores / f"cold-{n}-{r}"), "warm": str(warm)}[args.store]
                record = child(mode, task, store if mode == "switch" else "off")
                for key in ("make", "second"):
                    runs[mode][key].append(record[key])
                runs[mode]["resets"].extend(record["resets"])
        med = {m: {k: statistics.median(v) for k, v in r.items()} for m, r in runs.items()}
        s, w = med["stock"], med["switch"]
        print(f"| {task} | {s['make']:.2f} | {w['make']:.2f} | {s['make'] / w['make']:.1f} "
              f"| {s['second']:.2f} | {w['second']:.2f} | {s['second'] / w['second']:.1f} "
              f"| {s['resets'] * 1e3:.0f} | {w['resets'] * 1e3:.0f} | {s['resets'] / w['resets']:.1f} |", flush=True)
    import shutil

    shutil.rmtree(stores, ignore_errors=True)


if __name__ == "__main__":
    main()
