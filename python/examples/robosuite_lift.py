"""For robosuite users: an environment's model-building step as one ``Scene`` call.

robosuite's ``Lift._load_model`` rebuilds the whole MJCF tree in Python at every hard
reset: it creates the robot, its mount and gripper, the arena and each object from their
XML files (parsing each again), samples placements, merges everything into a
``ManipulationTask`` and writes it with ``get_xml()`` (about 8 ms per scene here, before
MuJoCo compiles it). With mjcf-forge the scene description (``benches/scenes/lift5.toml``:
robosuite's table arena, Panda with mount and gripper, five objects drawn from robosuite's
object models, placed without overlap, random z rotation and colours) is loaded once and
each episode's scene is ``scene.variant(i)``: tens of microseconds, reproducible from
``(seed, i)``.

``Lift5Env`` below keeps robosuite's structure (``_load_model``, ``_setup_references``,
``reset``) so the change is easy to see; ``build_lift_with_models`` shows the model tier
for code that wants robosuite's step-by-step assembly (``Model`` is robosuite's
``MujocoXMLModel``: ``naming_prefix``, ``joints``, ``bottom_offset``, ``merge`` ...).

Run: .cache/venv/bin/python python/examples/robosuite_lift.py
"""
from __future__ import annotations

import time
from pathlib import Path
from typing import Optional

import mujoco
import numpy as np

import mjcf_forge
from mjcf_forge import Document, Model, Scene

ROOT = Path(__file__).resolve().parents[2]
LIFT5 = ROOT / "benches" / "scenes" / "lift5.toml"
ASSETS = ROOT / ".cache" / "corpus" / "robosuite-1.5.2" / "robosuite" / "models" / "assets"


class Lift5Env:
    """robosuite's Lift environment skeleton, five random objects, rebuilt per episode.

    robosuite's ``_load_model`` (abridged)::

        self.robots[0].robot_model.set_base_xpos(xpos)
        mujoco_arena = TableArena(table_full_size=..., table_offset=...)
        objects = [CanObject("object0"), MilkObject("object1"), ...]
        self.placement_initializer = UniformRandomSampler(mujoco_objects=objects,
            x_range=[-0.3, 0.3], y_range=[-0.3, 0.3], rotation=None, ...)
        self.model = ManipulationTask(mujoco_arena=mujoco_arena,
            mujoco_robots=[robot.robot_model for robot in self.robots], mujoco_objects=objects)
        ... self.model.get_xml() -> MjSim

    becomes ``self.variant = self.scene.variant(index)``.
    """

    def __init__(self, scene_file: Path = LIFT5, seed: int = 0):
        # Once per environment: every model file is read once, the fixed part assembled once.
        self.scene = Scene.load(scene_file)
        self.rng = np.random.default_rng(seed)
        self.variant: Optional[mjcf_forge.Variant] = None

    def _load_model(self, index: int) -> None:
        self.variant = self.scene.variant(index)

    def _setup_references(self) -> None:
        # What robosuite reads off its model objects (root body, joints) comes from the
        # variant's parameters: each placed object with its prefix and root body.
        self.object_body_ids = {
            o["prefix"]: self.sim_model.body(o["body"]).id for o in self.variant.params["objects"]
        }
        self.robot_joints = [
            self.sim_model.joint(i).name
            for i in range(self.sim_model.njnt)
            if self.sim_model.joint(i).name.startswith("robot0_")
        ]

    def reset(self, index: Optional[int] = None) -> dict:
        index = int(self.rng.integers(0, 2**62)) if index is None else index
        t0 = time.perf_counter()
        self._load_model(index)
        t1 = time.perf_counter()
        self.sim_model = self.variant.compile()
        self.sim_data = mujoco.MjData(self.sim_model)
        mujoco.mj_forward(self.sim_model, self.sim_data)
        t2 = time.perf_counter()
        self._setup_references()
        return {"variant": index, "build_ms": (t1 - t0) * 1e3, "compile_ms": (t2 - t1) * 1e3}


def build_lift_with_models() -> tuple[str, dict[str, Model]]:
    """robosuite's assembly step by step with the model tier (fixed object choice, no
    randomization): robot + mount + gripper, arena, objects, one scene."""
    robot = Model(ASSETS / "robots" / "panda" / "robot.xml", "robot0")
    mount = Model(ASSETS / "bases" / "rethink_mount.xml", "mount0")
    gripper = Model(ASSETS / "grippers" / "panda_gripper.xml", "gripper0")
    robot.merge(mount, body="robot0_base")
    robot.merge(gripper, body="robot0_right_hand")
    world = Document.load(ASSETS / "arenas" / "table_arena.xml")
    # robosuite's set_base_xpos: the robot base behind the table.
    robot_doc = robot.document
    robot_doc.find_named("body", robot.root_body).set("pos", [-0.56, 0, 0.912])
    world.merge(robot_doc)
    objects = {}
    # The table's top surface, in the world: the table body's position plus its site's.
    table, top_site = world.find_named("body", "table"), world.find_named("site", "table_top")
    table_top = float(table["pos"].split()[2]) + float(top_site["pos"].split()[2])
    for i, name in enumerate(["can", "milk", "bread", "cereal", "lemon"]):
        obj = Model(ASSETS / "objects" / f"{name}.xml", f"object{i}")
        doc = obj.document
        root = doc.worldbody[0]
        # Rest on the table by the object's own bottom offset (robosuite's placement rule),
        # free to move, as robosuite's objects are.
        root.set("pos", [-0.2 + 0.1 * i, 0.0, table_top - obj.bottom_offset[2]])
        root.append("freejoint", {"name": obj.correct_naming("joint0")})
        world.merge(doc)
        objects[name] = obj
    return world.to_xml(), {"robot": robot, "gripper": gripper, "mount": mount, **objects}


def main() -> None:
    env = Lift5Env()
    for episode in range(5):
        info = env.reset()
        names = [o["model"].rsplit("/", 1)[-1] for o in env.variant.params["objects"]]
        print(f"episode {episode}: variant {info['variant']}: {', '.join(names)}; "
              f"built in {info['build_ms']:.2f} ms, compiled in {info['compile_ms']:.1f} ms")
    xml, parts = build_lift_with_models()
    m = mujoco.MjModel.from_xml_string(xml)
    print(f"model tier: {m.nbody} bodies, {m.njnt} joints, robot joints {parts['robot'].joints[:3]}...")


if __name__ == "__main__":
    main()
