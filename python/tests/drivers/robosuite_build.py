"""Builds robosuite's own models and writes their XML, with robosuite as it is or on
mjcf_forge.base (``mjcf_forge.robosuite.use()``): run by test_robosuite_use.py in the
robosuite venv (.cache/venv-robosuite-env, scripts/setup_robosuite_env.sh), once each way.

    python robosuite_build.py {robosuite|forge|forge-mujoco} OUT.json

(``forge``: ``use()``, robosuite's rules; ``forge-mujoco``: ``use(rules="mujoco")``.)

OUT.json maps a case name to its XML (``get_xml()``), or to "ERROR <type>: <message>".
With ``--env`` it also makes robosuite's Lift environment and steps it (case "lift_env":
the number of bodies and the steps taken).
"""
from __future__ import annotations

import json
import sys
import traceback

mode, out_path = sys.argv[1], sys.argv[2]
import mujoco  # noqa: E402

# robosuite 1.5.2's environments run on MuJoCo 3.9.0 only (see
# scripts/requirements-robosuite-env.txt): another MuJoCo here means a path shadowed it.
assert mujoco.__version__ == "3.9.0", (mujoco.__version__, mujoco.__file__)
if mode.startswith("forge"):
    import mjcf_forge.robosuite

    mjcf_forge.robosuite.use(rules="mujoco" if mode == "forge-mujoco" else "robosuite")

import numpy as np  # noqa: E402
import robosuite  # noqa: E402,F401
from robosuite.models.arenas import BinsArena, EmptyArena, TableArena  # noqa: E402
from robosuite.models.bases import RethinkMount  # noqa: E402
from robosuite.models.grippers import (  # noqa: E402
    JacoThreeFingerGripper,
    PandaGripper,
    RethinkGripper,
    Robotiq140Gripper,
)
from robosuite.models.objects import (  # noqa: E402
    BallObject,
    BoxObject,
    BreadObject,
    CanObject,
    CylinderObject,
    MilkObject,
)
from robosuite.models.robots import Panda, Sawyer  # noqa: E402
from robosuite.models.tasks import ManipulationTask  # noqa: E402
from robosuite.models.world import MujocoWorldBase  # noqa: E402

out: dict[str, str] = {}


def case(name, build):
    try:
        out[name] = build()
    except Exception as e:  # noqa: BLE001 - written out and compared
        traceback.print_exc()
        out[name] = f"ERROR {type(e).__name__}: {e}"


def in_world(obj):
    """An object as robosuite's Task.merge_objects puts it into a world."""
    world = MujocoWorldBase()
    world.merge_assets(obj)
    world.worldbody.append(obj.get_obj())
    return world.get_xml()


def robot(cls, gripper, idn=0):
    r = cls(idn=idn)
    r.add_gripper(gripper(idn=idn))
    r.add_base(RethinkMount(idn=idn))
    return r


def lift_task():
    r = robot(Panda, PandaGripper)
    r.set_base_xpos([-0.56, 0, 0.912])
    arena = TableArena(table_full_size=(0.8, 0.8, 0.05), table_offset=(0, 0, 0.8))
    arena.set_origin([0, 0, 0])
    out["lift_task_arena"] = arena.get_xml()
    cube = BoxObject(name="cube", size=[0.02, 0.02, 0.02], rgba=[1, 0, 0, 1])
    can = CanObject(name="can")
    can.set_pos([0.1, 0.1, 0.9])
    return ManipulationTask(mujoco_arena=arena, mujoco_robots=[r], mujoco_objects=[cube, can]).get_xml()


case("table_arena", lambda: TableArena().get_xml())
case("bins_arena", lambda: BinsArena().get_xml())
case("empty_arena", lambda: EmptyArena().get_xml())
for gripper in (PandaGripper, RethinkGripper, JacoThreeFingerGripper, Robotiq140Gripper):
    case(gripper.__name__, lambda g=gripper: g(idn=0).get_xml())
case("rethink_mount", lambda: RethinkMount(idn=0).get_xml())
case("can", lambda: in_world(CanObject(name="can")))
case("milk", lambda: in_world(MilkObject(name="milk")))
case("bread", lambda: in_world(BreadObject(name="bread")))
case("box", lambda: in_world(BoxObject(name="box", size=[0.02, 0.03, 0.04], rgba=[1, 0, 0, 1])))
case("cylinder", lambda: in_world(CylinderObject(name="cyl", size=[0.02, 0.05])))
case("ball", lambda: in_world(BallObject(name="ball", size=[0.03])))
case("panda_gripper_mount", lambda: robot(Panda, PandaGripper).get_xml())
case("sawyer_gripper_mount", lambda: robot(Sawyer, RethinkGripper, idn=1).get_xml())
case("lift_task", lift_task)

if "--env" in sys.argv:

    def lift_env():
        env = robosuite.make(
            "Lift", robots="Panda", has_renderer=False, has_offscreen_renderer=False,
            use_camera_obs=False, horizon=20,
        )
        env.reset()
        steps = 0
        for _ in range(10):
            env.step(np.zeros(env.action_dim))
            steps += 1
        return json.dumps({"nbody": int(env.sim.model.nbody), "steps": steps})

    case("lift_env", lift_env)

with open(out_path, "w") as f:
    json.dump(out, f)
