"""A Gymnasium environment over MuJoCo whose scene is a new randomized variant at every
reset: which objects, how many, where, their colours, frictions and masses all change,
which MuJoCo-side randomization (one compiled model) cannot do.

    env = SceneEnv("corpora/scenes/demo/demo.toml")
    obs, info = env.reset(seed=3)        # variant chosen by the seed: the same seed, the same scene
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    obs, info = env.reset()              # the next episode: another variant

The variant index comes from the environment's own random generator (``self.np_random``,
which ``reset(seed=...)`` seeds), so seeding reproduces the scene and the episode exactly,
and every unseeded reset draws a new scene. Making a variant takes tens of microseconds.
Its compiled model comes from a ``mjcf_forge.ModelCache``: when the variant's structure
(which objects stand in which slot) was seen before, the cached model is patched in place
(poses, colours, frictions, masses, then ``mj_setConst``): a fraction of a millisecond,
the same model MuJoCo would compile; otherwise MuJoCo compiles it (milliseconds for the
demo scene, ~100 ms with a robot's meshes) and the cache keeps it.

Run: .cache/venv/bin/python python/examples/gym_env.py [SCENE.toml] [--episodes N]
(corpora/scenes/patch/patch.toml has four structures, so most resets are patches.)
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any, Optional

import gymnasium as gym
import mujoco
import numpy as np

import mjcf_forge


class SceneEnv(gym.Env):
    """Reach the first placed object with the hand; the scene is redrawn per reset.

    Actions drive the actuators of the scene's fixtures (the robot), which every variant
    shares; observations are the robot's joint positions and velocities and the positions
    of up to ``max_objects`` placed objects (zeros for empty slots), so both spaces stay
    fixed while the scene changes.
    """

    metadata = {"render_modes": []}

    def __init__(
        self,
        scene: Optional[str | Path] = None,
        *,
        max_objects: int = 8,
        frame_skip: int = 10,
        max_episode_steps: int = 200,
        hand_body: str = "robot0_hand",
        cached_models: int = 8,
    ):
        self.scene = mjcf_forge.Scene.load(scene)
        # Compiled models per structure, patched per variant (see the module's docstring).
        self.cache = mjcf_forge.ModelCache(self.scene, max_models=cached_models)
        self.cache_models = cached_models
        self._datas: dict[int, mujoco.MjData] = {}
        self.max_objects = max_objects
        self.frame_skip = frame_skip
        self.max_episode_steps = max_episode_steps
        # The template (base + fixtures) fixes what every variant shares: the robot's
        # joints and actuators.
        template = mujoco.MjModel.from_xml_string(self.scene.template.to_xml())
        self.robot_joints = [template.joint(i).name for i in range(template.njnt)]
        self.hand_body = hand_body
        low, high = template.actuator_ctrlrange.T.astype(np.float32)
        self.action_space = gym.spaces.Box(low, high, dtype=np.float32)
        n_obs = 2 * len(self.robot_joints) + 3 * max_objects
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (n_obs,), dtype=np.float64)
        self.model: Optional[mujoco.MjModel] = None
        self.data: Optional[mujoco.MjData] = None
        self.variant: Optional[mjcf_forge.Variant] = None

    # ---------------------------------------------------------------- Gymnasium API

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None):
        super().reset(seed=seed)
        # options={"variant": i} picks a variant directly (e.g. to replay a manifest line).
        index = (options or {}).get("variant")
        if index is None:
            index = int(self.np_random.integers(0, 2**62))
        self.variant = self.scene.variant(index)
        self.model = self.cache.model(self.variant)
        # One MjData per cached model, made once (allocating one costs more than a patch).
        self.data = self._datas.get(id(self.model))
        if self.data is None or self.data.model is not self.model:
            if len(self._datas) >= 2 * self.cache_models:
                self._datas.clear()
            self.data = mujoco.MjData(self.model)
            self._datas[id(self.model)] = self.data
        else:
            mujoco.mj_resetData(self.model, self.data)
        mujoco.mj_forward(self.model, self.data)
        self._qpos_adr = [self.model.joint(j).qposadr[0] for j in self.robot_joints]
        self._qvel_adr = [self.model.joint(j).dofadr[0] for j in self.robot_joints]
        # What was drawn, read once per episode (the parameters are JSON).
        self._placed = [o["body"] for o in self.variant.params["objects"]]
        objects = self._placed[: self.max_objects]
        self._object_bodies = [self.model.body(b).id for b in objects]
        self._steps = 0
        return self._obs(), self._info()

    def step(self, action):
        assert self.model is not None and self.data is not None, "call reset() first"
        self.data.ctrl[:] = np.clip(action, self.action_space.low, self.action_space.high)
        mujoco.mj_step(self.model, self.data, nstep=self.frame_skip)
        self._steps += 1
        reward = -self._distance_to_target()
        truncated = self._steps >= self.max_episode_steps
        return self._obs(), float(reward), False, truncated, self._info()

    # ---------------------------------------------------------------- helpers

    def _obs(self) -> np.ndarray:
        qpos = self.data.qpos[self._qpos_adr]
        qvel = self.data.qvel[self._qvel_adr]
        objects = np.zeros((self.max_objects, 3))
        for k, b in enumerate(self._object_bodies):
            objects[k] = self.data.xpos[b]
        return np.concatenate([qpos, qvel, objects.ravel()])

    def _distance_to_target(self) -> float:
        if not self._object_bodies:
            return 0.0
        tip = self.data.body(self.hand_body).xpos
        return float(np.linalg.norm(self.data.xpos[self._object_bodies[0]] - tip))

    def _info(self) -> dict[str, Any]:
        return {
            "variant": self.variant.index,
            "objects": self._placed,
        }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", nargs="?", help="scene file (default: the built-in demo)")
    parser.add_argument("--episodes", type=int, default=5)
    args = parser.parse_args()
    env = SceneEnv(args.scene, max_episode_steps=50)
    for episode in range(args.episodes):
        t = time.perf_counter()
        # Seeded once: the whole run (every scene of it) is reproducible.
        obs, info = env.reset(seed=0) if episode == 0 else env.reset()
        reset_ms = (time.perf_counter() - t) * 1e3
        total = 0.0
        truncated = False
        while not truncated:
            obs, reward, _, truncated, info = env.step(env.action_space.sample())
            total += reward
        print(f"episode {episode}: variant {info['variant']}, {len(info['objects'])} objects, "
              f"reset {reset_ms:.2f} ms, return {total:.2f}")
    print(f"model cache: {env.cache.compiles} compiled, {env.cache.patches} patched")


if __name__ == "__main__":
    main()
