#!/usr/bin/env python3
"""robosuite's hard reset, stock against mjcf_forge.robosuite.use(), in one run.

    .cache/venv-robosuite-env/bin/python benches/compare/bench_robosuite_reset.py \
        [--envs Lift,PickPlace,NutAssembly] [--rounds 8] [--per-round 3] [--profile ENV]

Two worker processes of the robosuite venv (robosuite 1.5.2, MuJoCo 3.9.0) stay alive for
the whole run: one with robosuite as installed, one with ``mjcf_forge.robosuite.use()``
called first (this checkout's package, through a PYTHONPATH holding only it). For each
environment (Panda; headless, no camera observations) each worker makes the environment
and resets it once untimed; then the rounds alternate between the two workers, each round
timing ``--per-round`` hard resets (``env.reset()`` with robosuite's default
``hard_reset=True``: the model rebuilt from robosuite's classes, the simulation made from
its XML, robosuite's own reset of robots, controllers, placements and observables).
Printed: per environment and side, the median and best reset in ms, and the ratios
stock / ours of the medians and of the bests; and how many resets compiled on our side.

``--profile ENV``: instead, cProfile of 20 hard resets of ENV with use() on, printed as
the shares of the reset that go to MuJoCo's compile, to our cache (reading the XML, the
split, the patch), and to robosuite's own Python, then the top functions.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def worker(mode: str) -> None:
    """Reads commands on stdin ("make ENV", "reset N"), answers one JSON line each."""
    if mode == "forge":
        import mjcf_forge.robosuite

        mjcf_forge.robosuite.use()
    import logging

    import numpy as np

    with contextlib.redirect_stdout(sys.stderr):
        import robosuite
        from robosuite.utils.log_utils import ROBOSUITE_DEFAULT_LOGGER
    ROBOSUITE_DEFAULT_LOGGER.setLevel(logging.WARNING)
    np.random.seed(0)
    env = None
    for line in sys.stdin:
        cmd, arg = line.split()
        if cmd == "make":
            if env is not None:
                env.close()
            robots = ["Panda", "Panda"] if arg.startswith("TwoArm") else "Panda"
            with contextlib.redirect_stdout(sys.stderr):
                env = robosuite.make(
                    arg, robots=robots, has_renderer=False, has_offscreen_renderer=False,
                    use_camera_obs=False,
                )
                env.reset()
            answer: object = "ok"
        else:
            times = []
            with contextlib.redirect_stdout(sys.stderr):
                for _ in range(int(arg)):
                    t = time.perf_counter()
                    env.reset()
                    times.append((time.perf_counter() - t) * 1e3)
            answer = times
        if mode == "forge":
            from mjcf_forge import base

            cache = base.model_cache()
            answer = {"t": answer, "compiles": cache.compiles, "patches": cache.patches}
        else:
            answer = {"t": answer}
        print(json.dumps(answer), flush=True)


def profile(env_name: str) -> None:
    import cProfile
    import pstats

    import mjcf_forge.robosuite

    mjcf_forge.robosuite.use()
    import logging

    with contextlib.redirect_stdout(sys.stderr):
        import robosuite
        from robosuite.utils.log_utils import ROBOSUITE_DEFAULT_LOGGER
    ROBOSUITE_DEFAULT_LOGGER.setLevel(logging.WARNING)
    robots = ["Panda", "Panda"] if env_name.startswith("TwoArm") else "Panda"
    with contextlib.redirect_stdout(sys.stderr):
        env = robosuite.make(env_name, robots=robots, has_renderer=False,
                             has_offscreen_renderer=False, use_camera_obs=False)
        env.reset()
        prof = cProfile.Profile()
        t = time.perf_counter()
        prof.enable()
        for _ in range(20):
            env.reset()
        prof.disable()
        wall = (time.perf_counter() - t) / 20 * 1e3
    stats = pstats.Stats(prof)
    total = sum(v[2] for v in stats.stats.values())  # tottime over every function

    def cumulative(pred) -> float:
        return max((v[3] for k, v in stats.stats.items() if pred(k)), default=0.0)

    compile_s = sum(v[2] for k, v in stats.stats.items() if "from_xml_string" in k[2] and "mujoco" in str(k))
    ours_model = cumulative(lambda k: k[2] == "model" and k[0].endswith("_doc_cache.py"))
    ours_robot = cumulative(lambda k: k[2] == "set_mujoco_model" and k[0].endswith("robosuite.py"))
    forge_tot = sum(v[2] for k, v in stats.stats.items() if "mjcf_forge" in k[0] or "_mjcf_forge" in k[2])
    print(f"{env_name}: {wall:.1f} ms per hard reset under cProfile (20 resets)")
    print(f"  MuJoCo compile (MjModel.from_xml_string): {compile_s / 20 * 1e3:.2f} ms")
    print(f"  DocumentCache.model (read XML, split, compile or patch): {ours_model / 20 * 1e3:.2f} ms")
    print(f"  robot model (lazy, uncompiled): {ours_robot / 20 * 1e3:.2f} ms")
    print(f"  all of mjcf_forge (documents, merges, etree, cache): {forge_tot / total:.0%} of profiled time")
    stats.sort_stats("tottime").print_stats(25)


def package() -> Path:
    """The mjcf_forge that scripts/setup.sh installed into .cache/venv (built from this
    checkout), else this checkout's sources if an extension was built into them."""
    venv = ROOT / ".cache" / "venv" / "bin" / "python"
    if venv.exists():
        found = subprocess.run(
            [str(venv), "-c", "import mjcf_forge, os; print(os.path.dirname(mjcf_forge.__file__))"],
            capture_output=True, text=True,
        )
        if found.returncode == 0:
            return Path(found.stdout.strip())
    return ROOT / "python" / "mjcf_forge"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--envs", default="Lift,PickPlace,NutAssembly")
    ap.add_argument("--rounds", type=int, default=8)
    ap.add_argument("--per-round", type=int, default=3)
    ap.add_argument("--profile")
    ap.add_argument("--worker", choices=["stock", "forge", "profile"], help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker == "profile":
        profile(args.profile)
        return
    if args.worker:
        worker(args.worker)
        return
    with tempfile.TemporaryDirectory() as tmp:
        # This checkout's mjcf_forge alone on the path (the folder it is installed in may
        # hold another MuJoCo; the robosuite venv may hold an older mjcf_forge).
        (Path(tmp) / "mjcf_forge").symlink_to(package())
        if args.profile:
            subprocess.run(
                [sys.executable, __file__, "--worker", "profile", "--profile", args.profile],
                env=dict(os.environ, PYTHONPATH=tmp), check=True,
            )
            return
        workers = {}
        for side in ("stock", "forge"):
            env = dict(os.environ, PYTHONPATH=tmp if side == "forge" else "")
            workers[side] = subprocess.Popen(
                [sys.executable, __file__, "--worker", side], stdin=subprocess.PIPE,
                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env,
            )

        def ask(side: str, line: str) -> dict:
            w = workers[side]
            w.stdin.write(line + "\n")
            w.stdin.flush()
            return json.loads(w.stdout.readline())

        out = {}
        for name in args.envs.split(","):
            for side in workers:
                ask(side, f"make {name}")
            times: dict[str, list[float]] = {"stock": [], "forge": []}
            before = ask("forge", "reset 0")
            for r in range(args.rounds):
                order = ("stock", "forge") if r % 2 == 0 else ("forge", "stock")
                for side in order:
                    answer = ask(side, f"reset {args.per_round}")
                    times[side] += answer["t"]
                    if side == "forge":
                        after = answer
            med = {s: statistics.median(t) for s, t in times.items()}
            best = {s: min(t) for s, t in times.items()}
            out[name] = {
                "resets_per_side": len(times["forge"]),
                "stock_ms": {"median": round(med["stock"], 2), "best": round(best["stock"], 2)},
                "forge_ms": {"median": round(med["forge"], 2), "best": round(best["forge"], 2)},
                "ratio_of_medians": round(med["stock"] / med["forge"], 2),
                "ratio_of_bests": round(best["stock"] / best["forge"], 2),
                "forge_compiles": after["compiles"] - before["compiles"],
                "forge_patches": after["patches"] - before["patches"],
            }
            print(name, json.dumps(out[name]), flush=True)
        for w in workers.values():
            w.stdin.close()
            w.wait()
        import mujoco
        import robosuite

        print(json.dumps({"mujoco": mujoco.__version__, "robosuite": robosuite.__version__,
                          "load": os.getloadavg(), "results": out}, indent=1))


if __name__ == "__main__":
    main()
