"""What robosuite's clients read, through their own code paths, stock or on the switch.

Run in a robosuite venv (robosuite 1.5.2 with MuJoCo 3.9.0, or LIBERO's robosuite 1.4.0
with MuJoCo 3.3.1) by test_robosuite_clients.py, with a PYTHONPATH holding only this
checkout's mjcf_forge; one process per mode, so that nothing of one reaches the other:

    python robosuite_clients.py record MODE OUT --envs Lift,Door [--demos 3] [--steps 20]
    python robosuite_clients.py replay MODE OUT --data DIR --envs Lift,Door
    python robosuite_clients.py envs MODE OUT [--envs ...] [--steps 10]

MODE is ``stock`` or ``switch`` (``mjcf_forge.robosuite.use()`` before robosuite).

``record``: robosuite's own collection path. Each environment wrapped in robosuite's
``DataCollectionWrapper`` (which saves ``env.sim.model.get_xml()`` per episode), demos of
seeded random actions; then robosuite's own ``gather_demonstrations_as_hdf5`` (from
``robosuite/scripts/collect_human_demonstrations.py``) writes ``OUT/<env>/demo.hdf5``.
That function keeps only successful demos, and random actions succeed at nothing, so
each recorded episode's files are marked successful first (the only change to what
robosuite wrote).

``replay``: the dataset of another process (``--data``) read back by three clients:

- robosuite's ``playback_demonstrations_from_hdf5.py`` loop (``reset``,
  ``edit_model_xml``, ``reset_from_xml_string``, ``sim.reset``; the states forced one by
  one, and the actions played open loop from the first state, as ``--use-actions``);
- robomimic 0.3.0's conversion (``dataset_states_to_obs.py``'s ``extract_trajectory``
  over ``EnvRobosuite.reset_to`` / ``get_observation`` / ``get_state``, with agentview
  and wrist images at 84x84): robomimic 0.3.0 itself cannot be imported next to
  robosuite 1.4 or 1.5 (its ``env_robosuite.py`` imports ``mujoco_py``, and its
  utilities ``torch``), so its calls into robosuite are made here in its order;
- a MimicGen-style generation loop: per attempt ``reset()``, ``get_state()`` (robomimic's:
  ``get_xml()`` and the flattened state), the source demo's actions replayed.

``envs``: every environment of ``robosuite.ALL_ENVIRONMENTS`` with its default robots
(Panda; two for the TwoArm ones): the compiled model after a hard reset (a digest of
every array and size), ``get_xml()``, and the observations over seeded steps with an
agentview image; then robosuite's ``CameraMover`` on Lift's frontview, moved and
rotated, with a frame after each move; then (robosuite 1.5) Lift inside robosuite's
``DomainRandomizationWrapper``, ``get_xml()`` after each reset and after 5 steps (the
wrapper's changes to the live model, copied back into the text).

Everything is written to ``OUT`` (``*.npz``, ``*.json``, the XML texts) for the test to
compare stock with switched, bit for bit and byte for byte.
"""
from __future__ import annotations

import argparse
import contextlib
import glob
import hashlib
import inspect
import json
import logging
import os
import random
import sys
from pathlib import Path

MODE = sys.argv[2] if len(sys.argv) > 2 else "stock"
if MODE == "switch":
    import mjcf_forge.robosuite

    mjcf_forge.robosuite.use()

import numpy as np  # noqa: E402

with contextlib.redirect_stdout(sys.stderr):
    import h5py  # noqa: E402
    import robosuite  # noqa: E402
    from robosuite.environments.base import MujocoEnv  # noqa: E402
    from robosuite.wrappers import DataCollectionWrapper  # noqa: E402

with contextlib.suppress(ImportError):
    from robosuite.utils.log_utils import ROBOSUITE_DEFAULT_LOGGER

    ROBOSUITE_DEFAULT_LOGGER.setLevel(logging.WARNING)

SEEDED = "seed" in inspect.signature(MujocoEnv.__init__).parameters  # robosuite 1.5


def robots(name: str) -> object:
    return ["Panda", "Panda"] if name.startswith("TwoArm") else "Panda"


def make(name: str, **kwargs: object) -> object:
    """``robosuite.make`` with the default robots, seeded (1.5's ``seed``; 1.4 draws from
    NumPy's global generator, and its single-object tasks, ``NutAssemblySingle`` and
    ``PickPlaceSingle``, pick their object with Python's ``random``)."""
    np.random.seed(0)
    random.seed(0)
    if SEEDED:
        kwargs.setdefault("seed", 0)
    kwargs.setdefault("robots", robots(name))
    with contextlib.redirect_stdout(sys.stderr):
        return robosuite.make(name, **kwargs)


def actions(env: object, n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-1, 1, (n, env.action_dim))


# ---------------------------------------------------------------------------- record


def robosuites_gather() -> object:
    """``gather_demonstrations_as_hdf5``, robosuite's own function, compiled from its
    script's source: importing the script would import its input devices (robosuite
    1.4's need ``pynput`` and a display)."""
    import ast
    import datetime
    from glob import glob

    path = Path(robosuite.__file__).parent / "scripts" / "collect_human_demonstrations.py"
    tree = ast.parse(path.read_text())
    (function,) = [n for n in tree.body if getattr(n, "name", "") == "gather_demonstrations_as_hdf5"]
    namespace = {"os": os, "glob": glob, "h5py": h5py, "np": np, "datetime": datetime, "suite": robosuite}
    exec(compile(ast.Module(body=[function], type_ignores=[]), str(path), "exec"), namespace)
    return namespace["gather_demonstrations_as_hdf5"]


def record(out: Path, names: list, demos: int, steps: int) -> None:
    gather_demonstrations_as_hdf5 = robosuites_gather()
    for name in names:
        raw = out / name / "raw"
        env = make(
            name, has_renderer=False, has_offscreen_renderer=False, use_camera_obs=False,
            ignore_done=True, control_freq=20,
        )
        env_info = json.dumps({"env_name": name, "robots": robots(name)})
        with contextlib.redirect_stdout(sys.stderr):
            env = DataCollectionWrapper(env, str(raw))
            for demo in range(demos):
                env.reset()
                for action in actions(env, steps, demo):
                    env.step(action)
            env.close()
        for path in glob.glob(str(raw / "*" / "state_*.npz")):
            data = dict(np.load(path, allow_pickle=True))
            data["successful"] = np.array(True)
            np.savez(path, **data)
        with contextlib.redirect_stdout(sys.stderr):
            gather_demonstrations_as_hdf5(str(raw), str(out / name), env_info)
        # What the file holds, for the test (whose venv has no h5py): per demo, in the
        # order of their actions, its actions, states and model file.
        saved = read_demos(out / name)
        np.savez(
            out / name / "demos.npz",
            **{f"{kind}/{i}": d[kind] for i, d in enumerate(saved) for kind in ("actions", "states")},
        )
        (out / name / "demos.json").write_text(json.dumps([d["model_file"] for d in saved]))
        print(name, "ok")


def read_demos(folder: Path) -> list:
    """The demos of ``folder/demo.hdf5``, in the order of their actions (robosuite's
    script numbers them in the order its folder of episodes lists them)."""
    with h5py.File(folder / "demo.hdf5", "r") as f:
        demos = [
            {
                "model_file": f[f"data/{ep}"].attrs["model_file"],
                "states": f[f"data/{ep}/states"][()],
                "actions": np.array(f[f"data/{ep}/actions"][()]),
            }
            for ep in f["data"].keys()
        ]
    return sorted(demos, key=lambda d: d["actions"].tobytes())


# ---------------------------------------------------------------------------- replay


def get_state(env: object) -> dict:
    """robomimic's ``EnvRobosuite.get_state``."""
    return dict(model=env.sim.model.get_xml(), states=np.array(env.sim.get_state().flatten()))


def reset_to(env: object, state: dict) -> object:
    """robomimic 0.3.0's ``EnvRobosuite.reset_to`` (robosuite 1.4 and on)."""
    if "model" in state:
        env.reset()
        xml = env.edit_model_xml(state["model"])
        env.reset_from_xml_string(xml)
        env.sim.reset()
    if "states" in state:
        env.sim.set_state_from_flattened(state["states"])
        env.sim.forward()
        return dict(env._get_observations(force_update=True))
    return None


def replay(out: Path, data: Path, names: list) -> None:
    for name in names:
        got: dict = {}
        texts: dict = {}
        with h5py.File(data / name / "demo.hdf5", "r") as f:
            env_info = json.loads(f["data"].attrs["env_info"])
        # Matched across processes by their actions.
        demos = [(d["model_file"], d["states"], d["actions"]) for d in read_demos(data / name)]
        order = range(len(demos))
        env = make(
            env_info["env_name"], robots=env_info["robots"], has_renderer=False,
            has_offscreen_renderer=False, ignore_done=True, use_camera_obs=False,
            reward_shaping=True, control_freq=20,
        )
        # robosuite's playback script.
        for i, ep in enumerate(order):
            model_xml, states, acts = demos[ep]
            env.reset()
            xml = env.edit_model_xml(model_xml)
            env.reset_from_xml_string(xml)
            env.sim.reset()
            texts[f"playback{i}.xml"] = env.sim.model.get_xml()
            forced = []
            for state in states:
                env.sim.set_state_from_flattened(state)
                env.sim.forward()
                forced.append(np.concatenate([env.sim.data.xpos.ravel(), env.sim.data.site_xpos.ravel()]))
            got[f"forced/{i}"] = np.array(forced)
            env.sim.set_state_from_flattened(states[0])
            env.sim.forward()
            played = []
            for action in acts:
                env.step(action)
                played.append(env.sim.get_state().flatten())
            got[f"played/{i}"] = np.array(played)
            got[f"recorded/{i}"] = states
        # A MimicGen-style generation loop on the same environment: per attempt a reset,
        # robomimic's get_state, and the source demo's actions.
        _, states, acts = demos[order[0]]
        for attempt in range(3):
            env.reset()
            state = get_state(env)
            texts[f"attempt{attempt}.xml"] = state["model"]
            got[f"attempt/{attempt}/start"] = state["states"]
            for action in acts:
                env.step(action)
            got[f"attempt/{attempt}/end"] = env.sim.get_state().flatten()
        env.close()
        # robomimic's dataset_states_to_obs, with images.
        env = make(
            env_info["env_name"], robots=env_info["robots"], has_renderer=False,
            has_offscreen_renderer=True, ignore_done=True, use_object_obs=True,
            use_camera_obs=True, camera_names=["agentview", "robot0_eye_in_hand"],
            camera_heights=84, camera_widths=84, camera_depths=False, reward_shaping=False,
            control_freq=20,
        )
        for i, ep in enumerate(order):
            model_xml, states, acts = demos[ep]
            env.reset()
            obs = [reset_to(env, {"model": model_xml, "states": states[0]})]
            texts[f"robomimic{i}.xml"] = get_state(env)["model"]
            for t in range(1, len(states) + 1):
                if t == len(states):
                    obs.append(dict(env.step(acts[t - 1])[0]))
                else:
                    obs.append(reset_to(env, {"states": states[t]}))
                # robomimic's get_reward() (robosuite's reward(); Stack's requires an
                # action argument, which its reward does not read).
                got[f"robomimic/{i}/reward/{t}"] = np.array(env.reward(None))
            for t, o in enumerate(obs):
                for key, value in o.items():
                    got[f"robomimic/{i}/{t}/{key}"] = np.asarray(value)
        env.close()
        np.savez(out / f"{name}.npz", **got)
        (out / f"{name}.json").write_text(json.dumps(texts))
        print(name, "ok")


# ---------------------------------------------------------------------------- envs


def model_digest(model: object) -> dict:
    """Every array and scalar of an ``MjModel`` (its ``_model``), as digests."""
    digest = {}
    for key in dir(model):
        if key.startswith("_"):
            continue
        try:
            value = getattr(model, key)
        except Exception:  # noqa: BLE001 - a property this version cannot read
            continue
        if isinstance(value, np.ndarray):
            digest[key] = hashlib.sha256(np.ascontiguousarray(value).tobytes()).hexdigest()
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            digest[key] = repr(value)
    for group in ("opt", "stat"):
        obj = getattr(model, group)
        for key in dir(obj):
            if not key.startswith("_"):
                value = getattr(obj, key)
                if isinstance(value, (int, float, np.ndarray)):
                    digest[f"{group}.{key}"] = hashlib.sha256(np.asarray(value).tobytes()).hexdigest()
    return digest


def envs(out: Path, names: list, steps: int) -> None:
    from robosuite.utils.camera_utils import CameraMover

    got: dict = {}
    summary: dict = {}
    for name in names:
        env = make(
            name, has_renderer=False, has_offscreen_renderer=True, use_camera_obs=True,
            camera_names="agentview", camera_heights=64, camera_widths=64, ignore_done=True,
            control_freq=20,
        )
        env.reset()
        obs = [env.reset()]
        (out / f"{name}.xml").write_text(env.sim.model.get_xml())
        summary[name] = model_digest(env.sim.model._model)
        for action in actions(env, steps, 7):
            obs.append(env.step(action)[0])
        for t, o in enumerate(obs):
            for key, value in o.items():
                got[f"{name}/{t}/{key}"] = np.asarray(value)
        env.close()
    if "Lift" in names:
        env = make(
            "Lift", has_renderer=False, has_offscreen_renderer=True, use_camera_obs=False,
            ignore_done=True, control_freq=20,
        )
        env.reset()
        mover = CameraMover(env, camera="frontview")
        (out / "camera_mover.xml").write_text(env.sim.model.get_xml())
        frames = []
        for direction, scale in ((0, 0.1), (1, -0.1), (2, 0.05)):
            mover.move_camera(direction=np.eye(3)[direction], scale=scale)
            frames.append(env.sim.render(camera_name="frontview", height=64, width=64))
        for axis, angle in ((0, 5.0), (1, -5.0)):
            mover.rotate_camera(point=None, axis=np.eye(3)[axis], angle=angle)
            frames.append(env.sim.render(camera_name="frontview", height=64, width=64))
        got["camera_mover/frames"] = np.array(frames)
        got["camera_mover/pose"] = np.concatenate(mover.get_camera_pose())
        env.close()
    if "Lift" in names and SEEDED:
        # robosuite's DomainRandomizationWrapper writes its randomization into the live
        # model at every reset and step: get_xml() copies it back into the XML. Stock
        # robosuite 1.4's wrapper fails at its first hard reset (its modders keep the
        # freed simulation), and 1.5's inside DataCollectionWrapper (whose
        # reset_from_xml_string does the same): robosuite 1.5, alone.
        from robosuite.wrappers import DomainRandomizationWrapper

        env = make(
            "Lift", has_renderer=False, has_offscreen_renderer=False, use_camera_obs=False,
            ignore_done=True, control_freq=20,
        )
        env = DomainRandomizationWrapper(env, seed=3, randomize_color=False)
        texts = []
        for episode in range(3):
            env.reset()
            texts.append(env.sim.model.get_xml())
            for action in actions(env, 5, episode):
                env.step(action)
            texts.append(env.sim.model.get_xml())
        (out / "randomized.json").write_text(json.dumps(texts))
        env.close()
    np.savez(out / "envs.npz", **got)
    (out / "models.json").write_text(json.dumps(summary))
    print("envs", "ok")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("command", choices=["record", "replay", "envs"])
    parser.add_argument("mode", choices=["stock", "switch"])
    parser.add_argument("out", type=Path)
    parser.add_argument("--envs", default="")
    parser.add_argument("--demos", type=int, default=3)
    parser.add_argument("--steps", type=int, default=20)
    parser.add_argument("--data", type=Path)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    names = args.envs.split(",") if args.envs else sorted(robosuite.ALL_ENVIRONMENTS)
    if args.command == "record":
        record(args.out, names, args.demos, args.steps)
    elif args.command == "replay":
        replay(args.out, args.data, names)
    else:
        envs(args.out, names, args.steps)
    if MODE == "switch":
        # How the switch gave MuJoCo's last loaded XML model its content: loads paid,
        # writes through the held load.
        from mjcf_forge import _last_xml

        (args.out / "last_xml.json").write_text(json.dumps(_last_xml.state()))


if __name__ == "__main__":
    main()
