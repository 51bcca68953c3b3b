"""Runs LIBERO's own tasks with LIBERO's own code, stock or on the switch
(``mjcf_forge.robosuite.use()``), and records what a comparison needs: run by
test_libero.py and benches/compare/bench_libero.py in the LIBERO venv (.cache/venv-libero:
LIBERO 0.1.1, robosuite 1.4.0, MuJoCo 3.3.1; scripts/setup_libero_env.sh).

    python libero_run.py {stock|switch} OUT_DIR SUITE:INDEX [SUITE:INDEX ...]
        [--steps N] [--resets N] [--cameras] [--model-only] [--digest] [--again]

Per task, ``OUT_DIR/<suite>-<index>.npz`` holds:

- ``model/<field>``: every array of the ``MjModel`` the environment simulates, after its
  first reset (names as the raw ``names`` buffer, which holds every name in order), and
  ``model/sizes`` (every ``n*`` size);
- unless ``--model-only``: the observations after ``set_init_state`` (LIBERO's first init
  state of the task, read from its init file without torch) and after each of ``--steps``
  steps of actions drawn by ``np.random.default_rng(0)`` from [-1, 1] (``obs/<key>``,
  stacked), LIBERO's success predicate after each (``success``), and the simulator state
  (``state``); then ``--resets`` more hard resets, each followed by ``set_init_state`` and
  the same actions for 5 steps (``reset/<key>``: the observations ``reset()`` returned,
  ``again/<key>``: those after the 5 steps), and how many of those resets kept the
  simulation object (``kept``);
- ``xml/first`` and ``xml/reset<i>``: ``env.sim.model.get_xml()`` (robosuite's, which is
  ``mujoco.mj_saveLastXML``: what a dataset saves with each demo) after the first reset
  and after each later hard reset;
- with ``--again``, after the environment is closed, a second environment of the task
  made in the same process (what an evaluation worker making the task again gets):
  ``second/model/<field>`` (each array's SHA-256, as with ``--digest``), the observations
  after ``set_init_state`` and 5 steps of the same actions (``second/obs/<key>``), and
  whether it runs on the first environment's simulation (``second/kept``: the switch
  keeps a closed environment's simulation, its model patched and its render context as
  it was, for the next one of its structure);
- ``error``: the exception's type and message, if LIBERO's code raised.

With ``--digest`` each ``model/`` array is its SHA-256 instead (of its dtype, shape and
bytes; scripts/libero_check.sh: 130 models' textures and meshes would be tens of GB).

With ``--cameras`` the environment renders LIBERO's agentview and wrist images at 128x128
(``MUJOCO_GL`` chooses the GL platform; egl by default).
"""
from __future__ import annotations

import argparse
import hashlib
import os
import sys
import traceback

os.environ.setdefault("MUJOCO_GL", "egl")

ap = argparse.ArgumentParser()
ap.add_argument("mode", choices=["stock", "switch"])
ap.add_argument("out")
ap.add_argument("tasks", nargs="+")
ap.add_argument("--steps", type=int, default=50)
ap.add_argument("--resets", type=int, default=1)
ap.add_argument("--cameras", action="store_true")
ap.add_argument("--model-only", action="store_true")
ap.add_argument("--digest", action="store_true")
ap.add_argument("--again", action="store_true")
args = ap.parse_args()

if args.mode == "switch":
    import mjcf_forge.robosuite

    mjcf_forge.robosuite.use()

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from libero.libero.envs import OffScreenRenderEnv  # noqa: E402
from libero_tasks import bddl_file, init_states, task_name  # noqa: E402


def _digest(value: np.ndarray) -> np.ndarray:
    """An array's SHA-256 (of its dtype, shape and bytes): equal digests, equal arrays."""
    h = hashlib.sha256(f"{value.dtype.str}{value.shape}".encode())
    h.update(np.ascontiguousarray(value).tobytes())
    return np.frombuffer(h.digest(), dtype=np.uint8)


def model_arrays(model, digest: bool = False) -> dict:
    out = {}
    sizes = {}
    for name in dir(model):
        if name.startswith("_"):
            continue
        value = getattr(model, name)
        if isinstance(value, np.ndarray):
            out["model/" + name] = value.copy()
        elif name.startswith("n") and isinstance(value, int):
            sizes[name] = value
    if args.digest or digest:
        out = {k: _digest(v) for k, v in out.items()}
    out["model/sizes"] = np.array([sizes[k] for k in sorted(sizes)], dtype=np.int64)
    out["model/size_names"] = np.array(sorted(sizes))
    for group in ("opt", "stat", "vis"):
        obj = getattr(model, group)
        for name in dir(obj):
            if not name.startswith("_"):
                v = getattr(obj, name)
                if isinstance(v, (int, float, np.ndarray)):
                    out[f"model/{group}.{name}"] = np.asarray(v).copy()
    return out


def run(suite: str, index: int) -> dict:
    task = task_name(suite, index)
    bddl = bddl_file(suite, task)
    size = 128
    env = OffScreenRenderEnv(
        bddl_file_name=bddl, camera_heights=size, camera_widths=size,
        has_offscreen_renderer=args.cameras, use_camera_obs=args.cameras,
    )
    env.seed(0)
    env.reset()
    out = model_arrays(env.sim.model)
    # What robosuite's get_xml() gives (mujoco.mj_saveLastXML: what a dataset saves).
    out["xml/first"] = np.array(env.sim.model.get_xml())
    if args.model_only:
        env.close()
        return out
    state0 = init_states(suite, task)[0]
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, size=(args.steps, env.env.action_dim))
    obs = env.set_init_state(state0)
    frames = [obs]
    success = []
    for a in actions:
        obs, _reward, done, _info = env.step(a)
        frames.append(obs)
        success.append(bool(env.check_success()))
    for key in frames[0]:
        out["obs/" + key] = np.stack([np.asarray(f[key]) for f in frames])
    out["success"] = np.array(success)
    out["state"] = env.sim.get_state().flatten()
    again, first, kept = [], [], 0
    for i in range(args.resets):
        sim = env.sim
        first.append(env.reset())
        kept += env.sim is sim
        out[f"xml/reset{i}"] = np.array(env.sim.model.get_xml())
        obs = env.set_init_state(state0)
        for a in actions[:5]:
            obs, *_ = env.step(a)
        again.append(obs)
    for key in (again[0] if again else {}):
        out["again/" + key] = np.stack([np.asarray(f[key]) for f in again])
        out["reset/" + key] = np.stack([np.asarray(f[key]) for f in first])
    # Hard resets that kept the simulation (the switch's, when the structure is the same).
    out["kept"] = np.array(kept)
    sim = env.sim
    env.close()
    if args.again:
        env = OffScreenRenderEnv(
            bddl_file_name=bddl, camera_heights=size, camera_widths=size,
            has_offscreen_renderer=args.cameras, use_camera_obs=args.cameras,
        )
        env.seed(0)
        env.reset()
        out.update({"second/" + k: v for k, v in model_arrays(env.sim.model, digest=True).items()})
        out["second/kept"] = np.array(env.sim is sim)
        frames = [env.set_init_state(state0)]
        for a in actions[:5]:
            obs, *_ = env.step(a)
            frames.append(obs)
        for key in frames[0]:
            out["second/obs/" + key] = np.stack([np.asarray(f[key]) for f in frames])
        env.close()
    return out


os.makedirs(args.out, exist_ok=True)
for spec in args.tasks:
    suite, _, index = spec.partition(":")
    try:
        record = run(suite, int(index))
    except Exception as e:  # noqa: BLE001 - the record says what LIBERO's code raised
        traceback.print_exc()
        record = {"error": np.array(f"{type(e).__name__}: {e}")}
    # Written whole or not at all: a killed run leaves no half record (libero_check --resume).
    path = os.path.join(args.out, f"{suite}-{index}.npz")
    np.savez(path + ".part.npz", **record)
    os.replace(path + ".part.npz", path)
    print(spec, "error" if "error" in record else "ok", flush=True)
