"""robosuite's hard resets with mjcf_forge.robosuite.use() on, judged by MuJoCo.

Run in the robosuite venv (robosuite 1.5.2, MuJoCo 3.9.0) by test_robosuite_resets.py,
with a PYTHONPATH holding only this checkout's mjcf_forge and tests/judge:

    python robosuite_resets.py judge OUT.json [--resets N] [--envs Lift,Door] [--robots random:SEED]
    python robosuite_resets.py xml OUT_DIR [--resets N] [--envs ...]

``judge``: every robosuite environment with Panda (two for the TwoArm ones; with
``--robots random:SEED`` arms drawn per environment), made and
hard-reset N times with use() on, plain and inside robosuite's DomainRandomizationWrapper
(camera, lighting, dynamics; colour needs an OpenGL context). At every
``MjSim.from_xml_string`` (the environment's construction and each hard reset), the model
the simulation gets is compared, before robosuite touches it, with MuJoCo compiling the
same XML (tests/judge compare_models, then bit for bit on every array): equal means that
the cache's patch is exact and that nothing of an earlier reset (the wrapper's
randomization, robosuite's site colours) outlived it. OUT.json: per environment and mode,
the number of models judged, of compiles and patches, of hard resets that kept the
simulation (its model patched in place), the differences found (none expected), and whether the wrapper changed the model it was given (it must, or the check
proves nothing). Also: robosuite never read a robot's ``mujoco_model`` (none compiled).

``xml``: the XML of each environment's hard resets (robosuite's placements differ per
reset), as files for the judge under another MuJoCo (test_document_cache.py, 4.0.0).
"""
from __future__ import annotations

import argparse
import contextlib
import json
import logging
import sys
from pathlib import Path

import mjcf_forge.robosuite

mjcf_forge.robosuite.use()

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

with contextlib.redirect_stdout(sys.stderr):
    import robosuite  # noqa: E402
    from robosuite.utils import binding_utils  # noqa: E402
    from robosuite.utils.log_utils import ROBOSUITE_DEFAULT_LOGGER  # noqa: E402
    from robosuite.wrappers import DomainRandomizationWrapper  # noqa: E402

import judge  # noqa: E402
from mjcf_forge import base  # noqa: E402

ROBOSUITE_DEFAULT_LOGGER.setLevel(logging.WARNING)


def envs(names: str | None) -> list[str]:
    return names.split(",") if names else sorted(robosuite.ALL_ENVIRONMENTS)


# The arms --robots random:SEED draws from (robosuite 1.5.2's single arms).
ARMS = ["Panda", "Sawyer", "IIWA", "Jaco", "Kinova3", "UR5e"]
ROBOTS: str | None = None


def robots_for(name: str) -> list[str]:
    """Panda (two for the TwoArm environments), or with ``--robots random:SEED`` arms drawn
    per environment from ARMS (seeded by SEED and the environment's name)."""
    n = 2 if name.startswith("TwoArm") else 1
    if not ROBOTS:
        return ["Panda"] * n
    seed = int(ROBOTS.split(":")[1])
    rng = np.random.default_rng([seed, sum(map(ord, name))])
    return [ARMS[int(k)] for k in rng.integers(len(ARMS), size=n)]


def make(name: str) -> object:
    robots = robots_for(name)
    robots = robots if len(robots) > 1 else robots[0]
    with contextlib.redirect_stdout(sys.stderr):
        return robosuite.make(
            name, robots=robots, has_renderer=False, has_offscreen_renderer=False,
            use_camera_obs=False, hard_reset=True,
        )


def bit_differences(ref: object, model: object) -> list[str]:
    """Float arrays and statistics that are not bit for bit the same."""
    out = []
    for n in dir(ref):
        a = getattr(ref, n, None)
        if isinstance(a, np.ndarray) and a.dtype.kind == "f":
            b = getattr(model, n)
            if a.shape != b.shape or a.tobytes() != b.tobytes():
                out.append(n)
    for n in ("meaninertia", "meanmass", "meansize", "extent", "center"):
        if np.asarray(getattr(ref.stat, n)).tobytes() != np.asarray(getattr(model.stat, n)).tobytes():
            out.append(f"stat.{n}")
    return out


class Recorder:
    """Wraps the hooked ``MjSim.from_xml_string``: each model it gives is judged, or its
    XML kept."""

    def __init__(self, keep_xml: bool = False) -> None:
        self.judged = 0
        self.diffs: list[str] = []
        self.xmls: list[str] = []
        self.keep_xml = keep_xml
        hooked = binding_utils.MjSim.__dict__["from_xml_string"].__func__
        recorder = self

        def from_xml_string(cls, xml):
            sim = hooked(cls, xml)
            recorder.seen(xml, sim.model._model)
            return sim

        binding_utils.MjSim.from_xml_string = classmethod(from_xml_string)
        self._hooked = hooked

    def seen(self, xml: str, model: object) -> None:
        if self.keep_xml:
            self.xmls.append(xml)
            return
        ref = mujoco.MjModel.from_xml_string(xml)
        found = judge.compare_models(ref, model) or bit_differences(ref, model)
        self.judged += 1
        self.diffs += [f"model {self.judged}: {d}" for d in found[:5]]

    def close(self) -> None:
        binding_utils.MjSim.from_xml_string = classmethod(self._hooked)


def judge_env(name: str, resets: int, dr: bool) -> dict:
    cache = base.model_cache()
    compiles, patches = cache.compiles, cache.patches
    recorder = Recorder()
    changed = kept = 0
    try:
        env = make(name)
        target = env
        if dr:
            target = DomainRandomizationWrapper(
                env, seed=3, randomize_color=False, randomize_camera=True,
                randomize_lighting=True, randomize_dynamics=True, randomize_on_reset=True,
                randomize_every_n_steps=0,
            )
        for _ in range(resets):
            sim = env.sim
            with contextlib.redirect_stdout(sys.stderr):
                target.reset()
            kept += env.sim is sim
            if dr:
                # The wrapper randomized the model the reset was given, in place: compiled
                # again from the XML of the sim's last compile, it must differ.
                ref = mujoco.MjModel.from_xml_string(last_xml[0])
                changed += bool(judge.compare_models(ref, env.sim.model._model))
            env.step(np.zeros(env.action_dim))
        robots_compiled = sum(
            not isinstance(r.robot_model.__dict__.get("_mjcf_forge_model"), mjcf_forge.robosuite._Pending)
            for r in env.robots
        )
        env.close()
    finally:
        recorder.close()
    return {
        "judged": recorder.judged,
        "diffs": recorder.diffs,
        "compiles": cache.compiles - compiles,
        "patches": cache.patches - patches,
        "randomized_resets": changed,
        "kept_simulations": kept,
        "robot_models_compiled": robots_compiled,
        "robots": robots_for(name),
    }


last_xml: list[str] = [""]


def remember_xml() -> None:
    """Keeps the XML of the last simulation made (for the wrapper's check)."""
    hooked = binding_utils.MjSim.__dict__["from_xml_string"].__func__

    def from_xml_string(cls, xml):
        last_xml[0] = xml
        return hooked(cls, xml)

    binding_utils.MjSim.from_xml_string = classmethod(from_xml_string)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["judge", "xml"])
    ap.add_argument("out")
    ap.add_argument("--resets", type=int, default=3)
    ap.add_argument("--envs")
    ap.add_argument("--robots", help="random:SEED: arms drawn per environment (default Panda)")
    args = ap.parse_args()
    global ROBOTS
    ROBOTS = args.robots
    np.random.seed(0)
    remember_xml()
    if args.mode == "judge":
        out = {}
        for name in envs(args.envs):
            for dr in (False, True):
                try:
                    out[f"{name}{'+dr' if dr else ''}"] = judge_env(name, args.resets, dr)
                except Exception as e:  # noqa: BLE001 - reported to the test
                    out[f"{name}{'+dr' if dr else ''}"] = {"error": f"{type(e).__name__}: {e}"}
        Path(args.out).write_text(json.dumps(out, indent=1))
    else:
        folder = Path(args.out)
        folder.mkdir(parents=True, exist_ok=True)
        base.set_model_cache(None)  # robosuite's own compiles: only the XML is wanted
        for name in envs(args.envs):
            recorder = Recorder(keep_xml=True)
            try:
                env = make(name)
                for _ in range(args.resets):
                    with contextlib.redirect_stdout(sys.stderr):
                        env.reset()
                env.close()
            finally:
                recorder.close()
            for i, xml in enumerate(recorder.xmls):
                (folder / f"{name}-{i}.xml").write_text(xml)


if __name__ == "__main__":
    main()
