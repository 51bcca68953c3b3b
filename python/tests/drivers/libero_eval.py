"""Evaluations of a LIBERO task as LIBERO's own scripts run them, on the switch
(``mjcf_forge.robosuite.use()``; stock LIBERO with ``--stock``): run by test_libero.py in
the LIBERO venv.

    python libero_eval.py OUT.npz SUITE:INDEX [--episodes N] [--steps N] [--stock] [--no-vector]

Records, in OUT.npz, the rollouts of three evaluations of the task in this process, one
after the other with the same environment (seeds 0, 0 and 1), and of one evaluation in
LIBERO's
``SubprocVectorEnv`` (two workers running the same episodes, forked from this process
before it makes an environment of its own: a worker forked after the parent made an EGL
context hangs making its own, stock or not; not with ``--no-vector``). An evaluation: ``seed(0)`` (LIBERO's: numpy's global
generator, which its object placements draw from), then per episode ``k``, a hard reset (``env.reset()``), LIBERO's
init state ``k`` (``set_init_state``), then ``--steps`` actions drawn by
``np.random.default_rng(k)``; its rollout is every observation (no cameras) after each
step, the success predicate and the simulator's state.

- ``single/<e>/<k>/<key>``: evaluation ``e`` (0, 1, 2) in this process, episode ``k``;
- ``vector/<w>/<k>/<key>``: worker ``w`` of the vector environment, episode ``k``;
- ``kept``: the hard resets of the single evaluations that kept the simulation.
"""
from __future__ import annotations

import argparse
import sys

if "--stock" not in sys.argv:
    import mjcf_forge.robosuite

    mjcf_forge.robosuite.use()

import numpy as np  # noqa: E402
from libero.libero.envs import OffScreenRenderEnv, SubprocVectorEnv  # noqa: E402
from libero_tasks import bddl_file, init_states, task_name  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("out")
ap.add_argument("task")
ap.add_argument("--episodes", type=int, default=2)
ap.add_argument("--steps", type=int, default=10)
ap.add_argument("--stock", action="store_true")
ap.add_argument("--no-vector", action="store_true")
args = ap.parse_args()

suite, _, index = args.task.partition(":")
name = task_name(suite, int(index))
BDDL = bddl_file(suite, name)
INIT = init_states(suite, name)


def make_env():
    env = OffScreenRenderEnv(
        bddl_file_name=BDDL, camera_heights=128, camera_widths=128,
        has_offscreen_renderer=False, use_camera_obs=False,
    )
    env.seed(0)
    return env


def actions(k: int, dim: int) -> np.ndarray:
    return np.random.default_rng(k).uniform(-1.0, 1.0, size=(args.steps, dim))


def rollout(frames: list, success: list, state) -> dict:
    out = {f"obs/{key}": np.stack([np.asarray(f[key]) for f in frames]) for key in frames[0]}
    out["success"] = np.array(success)
    out["state"] = np.asarray(state)
    return out


def evaluate(env, seed: int) -> tuple[list, int]:
    env.seed(seed)  # LIBERO's: numpy's global generator, which its placements draw from
    episodes, kept = [], 0
    for k in range(args.episodes):
        sim = env.sim
        env.reset()
        kept += env.sim is sim
        frames = [env.set_init_state(INIT[k])]
        success = []
        for a in actions(k, env.env.action_dim):
            obs, _reward, _done, _info = env.step(a)
            frames.append(obs)
            success.append(bool(env.check_success()))
        episodes.append(rollout(frames, success, env.get_sim_state()))
    return episodes, kept


# The single evaluations' seeds: 0 twice, then 1 (the vector workers' seeds).
SEEDS = (0, 0, 1)
record = {}
if not args.no_vector:
    workers = 2
    venv = SubprocVectorEnv([make_env for _ in range(workers)])
    venv.seed(0)  # worker w: seed(w), as tianshou's vector environments seed
    dim = 7  # LIBERO's Panda with its OSC_POSE controller: LIBERO's own evaluation's action size
    for k in range(args.episodes):
        venv.reset()
        first = venv.set_init_state(np.stack([INIT[k]] * workers))
        frames = [[first[w]] for w in range(workers)]
        success = [[] for _ in range(workers)]
        for a in actions(k, dim):
            obs, _reward, _done, _info = venv.step(np.stack([a] * workers))
            done = venv.check_success()
            for w in range(workers):
                frames[w].append(obs[w])
                success[w].append(bool(done[w]))
        states = venv.get_sim_state()
        for w in range(workers):
            ep = rollout(frames[w], success[w], states[w])
            record.update({f"vector/{w}/{k}/{key}": v for key, v in ep.items()})
    venv.close()

env = make_env()
env.reset()
kept = 0
for e, seed in enumerate(SEEDS):
    episodes, n = evaluate(env, seed)
    kept += n
    for k, ep in enumerate(episodes):
        record.update({f"single/{e}/{k}/{key}": v for key, v in ep.items()})
record["kept"] = np.array(kept)
if "--stock" not in sys.argv:
    # This process's misses that loaded the structure from the model store, and the
    # compiles: a warm store (MJCF_FORGE_STORE) leaves no compile of the task.
    from mjcf_forge import base

    cache = base.model_cache()
    record["loads"] = np.array([cache.loads, cache.compiles])
env.close()

np.savez(args.out, **record)
print("ok")
