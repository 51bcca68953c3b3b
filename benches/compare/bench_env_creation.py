"""Environment creation, stock against the switch (``mjcf_forge.robosuite.use()``), same
run, processes alternating, medians: robosuite 1.5.2's ``robosuite.make`` and LIBERO's
``SubprocVectorEnv``, with the model store cold or warm. Results: docs/speed.md.

    .cache/venv/bin/python benches/compare/bench_env_creation.py robosuite [--env Lift]
        [--rounds N] [--store cold|warm] [--cameras]
    .cache/venv/bin/python benches/compare/bench_env_creation.py libero-vector
        [--task libero_object:0] [--workers 8] [--rounds N] [--store cold|warm]

``robosuite``: each process (the robosuite venv: robosuite 1.5.2, MuJoCo 3.9.0) makes the
environment (Panda; with the offscreen renderer and an agentview observation at 84x84 when
``--cameras``) and resets it (``make``), closes it and makes and resets a second one
(``second``). ``libero-vector``: each process (the LIBERO venv) makes LIBERO's
``SubprocVectorEnv`` of ``--workers`` environments of the task (cameras off, as LIBERO's
evaluation without images) and times the first observations (``reset()`` of every worker
returned). The switch's processes run with ``MJCF_FORGE_STORE`` a new empty folder
(``cold``: every structure compiled and stored; the workers of a vector environment race
on it) or a folder one untimed switched process filled first (``warm``).
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PYTHONS = {
    "robosuite": ROOT / ".cache" / "venv-robosuite-env" / "bin" / "python",
    "libero-vector": ROOT / ".cache" / "venv-libero" / "bin" / "python",
}

ROBOSUITE = r"""
import json, sys, time
mode, name, cameras = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
if mode == "switch":
    import mjcf_forge.robosuite
    mjcf_forge.robosuite.use()
import robosuite
def make():
    env = robosuite.make(name, robots="Panda", has_renderer=False, has_offscreen_renderer=cameras,
                         use_camera_obs=cameras, camera_names="agentview", camera_heights=84,
                         camera_widths=84)
    env.reset()
    return env
t = time.perf_counter()
env = make()
first = time.perf_counter() - t
env.close()
t = time.perf_counter()
env = make()
second = time.perf_counter() - t
print(json.dumps({"make": first, "second": second}))
"""

LIBERO_VECTOR = r"""
import json, sys, time
mode, task, workers = sys.argv[1], sys.argv[2], int(sys.argv[3])
if mode == "switch":
    import mjcf_forge.robosuite
    mjcf_forge.robosuite.use()
from libero.libero.envs import OffScreenRenderEnv, SubprocVectorEnv
from libero_tasks import bddl_file, task_name
suite, _, index = task.partition(":")
bddl = bddl_file(suite, task_name(suite, int(index)))
def make_env():
    env = OffScreenRenderEnv(bddl_file_name=bddl, camera_heights=128, camera_widths=128,
                             has_offscreen_renderer=False, use_camera_obs=False)
    env.seed(0)
    return env
t = time.perf_counter()
venv = SubprocVectorEnv([make_env for _ in range(workers)])
venv.seed(0)
obs = venv.reset()
first = time.perf_counter() - t
assert len(obs) == workers
venv.close()
print(json.dumps({"make": first}))
"""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("client", choices=sorted(PYTHONS))
    ap.add_argument("--env", default="Lift")
    ap.add_argument("--task", default="libero_object:0")
    ap.add_argument("--workers", type=int, default=8)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--store", choices=["cold", "warm"], default="warm")
    ap.add_argument("--cameras", action="store_true")
    args = ap.parse_args()
    python = PYTHONS[args.client]
    assert python.exists(), f"{python} missing: run scripts/setup.sh"
    only = Path(tempfile.mkdtemp(prefix="bench-env-path-"))
    stores = Path(tempfile.mkdtemp(prefix="bench-env-store-"))
    import mjcf_forge

    (only / "mjcf_forge").symlink_to(Path(mjcf_forge.__file__).resolve().parent)
    path = [str(only), str(ROOT / "python" / "tests" / "drivers")]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(path), PYTHONHASHSEED="0",
               LIBERO_CONFIG_PATH=str(ROOT / ".cache" / "libero-config"))
    env.setdefault("MUJOCO_GL", "egl")
    if args.client == "robosuite":
        code, what = ROBOSUITE, [args.env, "1" if args.cameras else "0"]
        label = f"robosuite.make({args.env!r}), {'with' if args.cameras else 'without'} cameras"
    else:
        code, what = LIBERO_VECTOR, [args.task, str(args.workers)]
        label = f"LIBERO SubprocVectorEnv of {args.workers} x {args.task}, time to first observation"

    def child(mode: str, store: str) -> dict:
        out = subprocess.run([str(python), "-c", code, mode, *what], env=dict(env, MJCF_FORGE_STORE=store),
                             capture_output=True, text=True, cwd=only, check=False)
        if out.returncode != 0:
            sys.exit(out.stderr[-3000:])
        return json.loads(out.stdout.strip().splitlines()[-1])

    warm = stores / "warm"
    if args.store == "warm":
        child("switch", str(warm))  # fills the store, untimed
    runs: dict = {"stock": {}, "switch": {}}
    for r in range(args.rounds):
        for mode in ("stock", "switch"):
            store = str(warm if args.store == "warm" else stores / f"cold-{r}") if mode == "switch" else "off"
            for key, value in child(mode, store).items():
                runs[mode].setdefault(key, []).append(value)
    print(f"{label}; store {args.store}; {args.rounds} processes each way, medians (s)")
    for key in runs["stock"]:
        s, w = statistics.median(runs["stock"][key]), statistics.median(runs["switch"][key])
        print(f"| {key} | {s:.2f} | {w:.2f} | {s / w:.1f}x |")
    shutil.rmtree(stores, ignore_errors=True)
    shutil.rmtree(only, ignore_errors=True)


if __name__ == "__main__":
    main()
