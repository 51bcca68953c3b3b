#!/usr/bin/env python3
"""What robosuite's clients pay per episode, stock against mjcf_forge.robosuite.use().

    .cache/venv-robosuite-env/bin/python benches/compare/bench_robosuite_clients.py \
        [--env Lift] [--rounds 8] [--per-round 3] [--measures record,attempt,...]

Per measure, two worker processes of the robosuite venv (robosuite 1.5.2, MuJoCo 3.9.0),
one stock, one with ``use()`` first (this checkout's package, through a PYTHONPATH holding
only it), each holding only the environments of that measure, as a client's script does;
rounds alternate between them, and each round times ``--per-round`` of the measure
(Panda, headless). The measures:

- ``record``: one episode's start in robosuite's ``DataCollectionWrapper``: its
  ``reset()`` (a hard reset, ``get_xml()``, ``reset_from_xml_string`` of that XML, the
  state set back), no cameras;
- ``attempt``: MimicGen's attempt loop, ``reset()`` then robomimic's ``get_state()``
  (``get_xml()`` and the flattened state), no cameras;
- ``camera_mover``: robosuite's ``CameraMover(env, camera="frontview")`` (``get_xml()``,
  the mocap body added, ``reset_from_xml_string``), on an environment with an offscreen
  renderer, after a hard reset;
- ``robomimic``: robomimic's ``dataset_states_to_obs`` for one demo of 20 steps (its
  ``reset``, ``reset_to`` with the model and the first state, then a state reset and an
  observation per step, agentview and wrist images at 84x84);
- ``render``: what of that no reset can save: the demo's 21 observations alone
  (``_get_observations(force_update=True)``: both cameras rendered, the other sensors
  read), on the state the environment is in.

Printed: per measure the median and best in ms on each side, and the ratios stock / ours
of the medians and of the bests (docs/speed.md, "robosuite's clients").
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
MEASURES = ("record", "attempt", "camera_mover", "robomimic", "render")


def worker(mode: str, name: str, measure: str) -> None:
    """Reads "N" lines on stdin, answers one JSON list of ``measure``'s times (ms) each."""
    if mode == "forge":
        import mjcf_forge.robosuite

        mjcf_forge.robosuite.use()
    import logging

    import numpy as np

    with contextlib.redirect_stdout(sys.stderr):
        import robosuite
        from robosuite.utils.camera_utils import CameraMover
        from robosuite.utils.log_utils import ROBOSUITE_DEFAULT_LOGGER
        from robosuite.wrappers import DataCollectionWrapper
    ROBOSUITE_DEFAULT_LOGGER.setLevel(logging.WARNING)

    def make(**kwargs):
        with contextlib.redirect_stdout(sys.stderr):
            return robosuite.make(
                name, robots="Panda", has_renderer=False, ignore_done=True, control_freq=20,
                seed=0, **kwargs,
            )

    plain = dict(has_offscreen_renderer=False, use_camera_obs=False)
    if measure == "record":
        recorder = DataCollectionWrapper(make(**plain), tempfile.mkdtemp())
    elif measure == "attempt":
        env = make(**plain)
    elif measure == "camera_mover":
        viewer = make(has_offscreen_renderer=True, use_camera_obs=False)
    else:
        images = make(
            has_offscreen_renderer=True, use_camera_obs=True,
            camera_names=["agentview", "robot0_eye_in_hand"], camera_heights=84, camera_widths=84,
        )
        # A demo to convert: 20 seeded steps recorded as DataCollectionWrapper records them.
        images.reset()
        start = images.sim.model.get_xml()
        states = [images.sim.get_state().flatten()]
        for action in np.random.default_rng(0).uniform(-1, 1, (20, images.action_dim)):
            images.step(action)
            states.append(images.sim.get_state().flatten())
        last_action = action

    def reset_to(e, state):
        if "model" in state:
            e.reset()
            e.reset_from_xml_string(e.edit_model_xml(state["model"]))
            e.sim.reset()
        e.sim.set_state_from_flattened(state["states"])
        e.sim.forward()
        return e._get_observations(force_update=True)

    def once() -> None:
        if measure == "record":
            recorder.reset()
        elif measure == "attempt":
            env.reset()
            _ = dict(model=env.sim.model.get_xml(), states=np.array(env.sim.get_state().flatten()))
        elif measure == "camera_mover":
            viewer.reset()
            CameraMover(viewer, camera="frontview")
        elif measure == "render":
            for _ in range(len(states)):
                images._get_observations(force_update=True)
        else:
            images.reset()
            reset_to(images, {"model": start, "states": states[0]})
            for t in range(1, len(states)):
                reset_to(images, {"states": states[t]})
            images.step(last_action)

    with contextlib.redirect_stdout(sys.stderr):
        once()  # untimed: every structure seen once
    for line in sys.stdin:
        times = []
        with contextlib.redirect_stdout(sys.stderr):
            for _ in range(int(line)):
                t = time.perf_counter()
                once()
                times.append((time.perf_counter() - t) * 1e3)
        print(json.dumps(times), flush=True)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--env", default="Lift")
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--per-round", type=int, default=3)
    parser.add_argument("--measures", default=",".join(MEASURES), help="comma-separated, of: " + ", ".join(MEASURES))
    parser.add_argument("--worker", choices=["stock", "forge"])
    args = parser.parse_args()
    measures = args.measures.split(",")
    if args.worker:
        return worker(args.worker, args.env, measures[0])

    sys.path.insert(0, str(Path(__file__).parent))
    from bench_robosuite_reset import package

    only = Path(tempfile.mkdtemp()) / "path"
    only.mkdir()
    (only / "mjcf_forge").symlink_to(package())
    env = dict(os.environ, PYTHONPATH=str(only), PYTHONHASHSEED="0")
    env.setdefault("MUJOCO_GL", "egl")
    times: dict = {}
    for measure in measures:
        workers = {
            mode: subprocess.Popen(
                [sys.executable, __file__, "--worker", mode, "--env", args.env, "--measures", measure],
                stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env,
            )
            for mode in ("stock", "forge")
        }
        for mode in workers:
            times[(measure, mode)] = []
        for _ in range(args.rounds):
            for mode, proc in workers.items():
                proc.stdin.write(f"{args.per_round}\n")
                proc.stdin.flush()
                times[(measure, mode)] += json.loads(proc.stdout.readline())
        for proc in workers.values():
            proc.stdin.close()
            proc.wait()
    print(f"{args.env}: {args.rounds} rounds x {args.per_round}, ms (median / best), stock / ours")
    for measure in measures:
        s, f = times[(measure, "stock")], times[(measure, "forge")]
        print(
            f"{measure:13s} stock {statistics.median(s):8.1f} / {min(s):8.1f}   "
            f"ours {statistics.median(f):8.1f} / {min(f):8.1f}   "
            f"x{statistics.median(s) / statistics.median(f):5.1f} (medians)  "
            f"x{min(s) / min(f):5.1f} (bests)"
        )


if __name__ == "__main__":
    main()
