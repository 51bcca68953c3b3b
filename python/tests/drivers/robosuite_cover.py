"""Builds every model class and environment of robosuite with robosuite's own code, with
robosuite as it is or on mjcf_forge.base (``mjcf_forge.robosuite.use()``): run by
test_robosuite_cover.py in the robosuite venv (.cache/venv-robosuite-env: robosuite 1.5.2,
MuJoCo 3.9.0), once each way per group of cases.

    python robosuite_cover.py {robosuite|forge|forge-mujoco} OUT.json {models|envs} [CASE ...]

(``forge``: ``use()``, robosuite's rules; ``forge-mujoco``: ``use(rules="mujoco")``.)

OUT.json maps a case name to a record: ``{"xml": ...}`` (the model's ``get_xml()``; for
robots also ``"parts"``: each gripper's), or ``{"error": "<type>: <message>"}`` when
robosuite's code raised. Cases:

- models: ``robot/<name>`` (every registered robot with its default base and grippers, as
  robosuite's ``Robot.load_model`` adds them), ``gripper/<key>`` (every entry of
  ``GRIPPER_MAPPING``), ``base/<name>`` (every entry of ``BASE_MAPPING``),
  ``object/<class>`` (every object class of ``robosuite.models.objects``, put into a world
  as ``Task.merge_objects`` does), ``arena/<class>`` (every arena class);
- envs: ``env/<Env>`` (every environment with Panda, two Pandas for the two-arm ones) and
  ``lift/<robot>`` (Lift with every robot): made with ``seed=0``, reset, and stepped with
  ``STEPS`` actions drawn uniformly from the action space (within [-1, 1]) by
  ``np.random.default_rng(0)``; the record holds the XML robosuite compiled
  (``env.model.get_xml()`` after the reset), the XML of its arena and robots alone
  (``"parts"``), and the observations after the reset and after each step (``"obs"``: a
  list of ``{key: list of floats}``), with the rewards.

Given CASE names, only those run (any group).
"""
from __future__ import annotations

import inspect
import json
import sys
import traceback

mode, out_path, group = sys.argv[1], sys.argv[2], sys.argv[3]
only = set(sys.argv[4:])
import mujoco  # noqa: E402

# robosuite 1.5.2's environments run on MuJoCo 3.9.0 only (see
# scripts/requirements-robosuite-env.txt): another MuJoCo here means a path shadowed it.
assert mujoco.__version__ == "3.9.0", (mujoco.__version__, mujoco.__file__)
if mode.startswith("forge"):
    import mjcf_forge.robosuite

    mjcf_forge.robosuite.use(rules="mujoco" if mode == "forge-mujoco" else "robosuite")

import numpy as np  # noqa: E402
import robosuite  # noqa: E402
import robosuite.models.arenas as arenas  # noqa: E402
import robosuite.models.objects as objects  # noqa: E402
from robosuite.models.bases import BASE_MAPPING, robot_base_factory  # noqa: E402
from robosuite.models.grippers import GRIPPER_MAPPING, gripper_factory  # noqa: E402
from robosuite.models.robots import create_robot  # noqa: E402
from robosuite.models.world import MujocoWorldBase  # noqa: E402
from robosuite.robots import ROBOT_CLASS_MAPPING  # noqa: E402

STEPS = 20
TWO_ARM = {"TwoArmHandover", "TwoArmLift", "TwoArmPegInHole", "TwoArmTransport"}

out: dict[str, dict] = {}


# What a part's elements compile to alone (row 5 of the differences): by the MuJoCo of
# this venv, the one whose compile a merge wrote out (another MuJoCo computes a mesh's
# inertia a few ulps apart).
OWN = {
    "body_mass": "mjOBJ_BODY", "body_inertia": "mjOBJ_BODY", "body_ipos": "mjOBJ_BODY",
    "body_iquat": "mjOBJ_BODY", "jnt_range": "mjOBJ_JOINT", "geom_pos": "mjOBJ_GEOM",
    "geom_quat": "mjOBJ_GEOM",
}


def own_values(part_xml):
    """``{array: {name: values}}`` of the part compiled alone (without its materials, as a
    merge compiles it), or the compiler's error."""
    from mjcf_forge._mjcf_utils import without_materials as _without_materials

    try:
        model = mujoco.MjModel.from_xml_string(_without_materials(part_xml))
    except ValueError as e:
        return {"error": str(e)}
    values = {}
    for array, kind in OWN.items():
        obj = getattr(mujoco.mjtObj, kind)
        rows = getattr(model, array)
        values[array] = {
            mujoco.mj_id2name(model, obj, i): np.asarray(rows[i], dtype=float).ravel().tolist()
            for i in range(len(rows))
            if mujoco.mj_id2name(model, obj, i)
        }
    return values


def case(name, build):
    if only and name not in only:
        return
    np.random.seed(0)  # what robosuite draws from numpy's global generator
    try:
        out[name] = build()
        if "parts" in out[name] and mode == "forge-mujoco":
            out[name]["parts_own"] = [own_values(x) for x in out[name]["parts"]]
    except Exception as e:  # noqa: BLE001 - written out and compared
        traceback.print_exc()
        out[name] = {"error": f"{type(e).__name__}: {e}"}


def xml(model):
    return {"xml": model.get_xml()}


def robot(name):
    """robosuite's Robot.load_model: the robot, its default base, a default gripper per arm.
    The grippers' own XML is kept too (``"parts"``)."""
    model = create_robot(name, idn=0)
    model.add_base(base=robot_base_factory(model.default_base, idn=0))
    model.update_joints()
    model.update_actuators()
    parts = []
    for arm in model.arms:
        gripper = gripper_factory(model.default_gripper[arm], idn=f"0_{arm}")
        parts.append(gripper.get_xml())
        model.add_gripper(gripper, model.eef_name[arm])
    return {**xml(model), "parts": parts}


def in_world(*parts):
    """Objects as robosuite's Task.merge_objects puts them into a world."""
    world = MujocoWorldBase()
    for obj in parts:
        world.merge_assets(obj)
        world.worldbody.append(obj.get_obj())
    return xml(world)


# The abstract object classes, and the arguments the concrete ones need besides a name.
ABSTRACT_OBJECTS = {"MujocoObject", "MujocoXMLObject", "MujocoGeneratedObject", "CompositeBodyObject",
                    "CompositeObject", "PrimitiveObject", "ObjectGroup"}


# Ball and capsule draw a missing size from an unseeded np.random.default_rng(): given here.
OBJECT_ARGS = {"BallObject": dict(size=[0.05]), "CapsuleObject": dict(size=[0.02, 0.04])}


def an_object(cls):
    kwargs = dict(OBJECT_ARGS.get(cls.__name__, {}))
    if "rng" in inspect.signature(cls.__init__).parameters:
        kwargs["rng"] = np.random.default_rng(0)
    if cls is objects.TransportGroup:  # as TwoArmTransport makes it
        group = cls(
            name="transport",
            payload=objects.HammerObject(name="payload", rng=np.random.default_rng(0)),
            trash=objects.BoxObject(name="trash", size=[0.02, 0.02, 0.02]),
        )
        return in_world(*group.objects.values())
    return in_world(cls(name="obj", **kwargs))


ARENAS = {
    "MultiTableArena": dict(table_offsets=np.array(((0, -0.6, 0.8), (0, 0.6, 0.8)))),
    # The default table_offset (0 0 0) makes legs of negative size (see the test).
    "PegsArena": dict(table_offset=(0, 0, 0.8)),
}


def models():
    for name in sorted(ROBOT_CLASS_MAPPING):
        case(f"robot/{name}", lambda n=name: robot(n))
    for key, cls in GRIPPER_MAPPING.items():
        case(f"gripper/{key}", lambda c=cls: xml(c(idn=0)))
    for key, cls in BASE_MAPPING.items():
        case(f"base/{key}", lambda c=cls: xml(c(idn=0)))
    for name, cls in sorted(vars(objects).items()):
        if isinstance(cls, type) and issubclass(cls, (objects.MujocoObject, objects.ObjectGroup)):
            if name not in ABSTRACT_OBJECTS:
                case(f"object/{name}", lambda c=cls: an_object(c))
    for name, cls in sorted(vars(arenas).items()):
        if isinstance(cls, type) and issubclass(cls, arenas.Arena) and cls is not arenas.Arena:
            case(f"arena/{name}", lambda c=cls, n=name: xml(c(**ARENAS.get(n, {}))))
    case("arena/PegsArena_default", lambda: xml(arenas.PegsArena()))


def run_env(env_name, robots):
    np.random.seed(0)
    env = robosuite.make(
        env_name, robots=robots, has_renderer=False, has_offscreen_renderer=False,
        use_camera_obs=False, seed=0, horizon=STEPS + 5,
    )
    obs = [env.reset()]
    # The arena and the robots as they went into the task, each alone.
    parts = [env.model.mujoco_arena.get_xml()] + [r.robot_model.get_xml() for r in env.robots]
    record = {"xml": env.model.get_xml(), "parts": parts, "obs": [], "reward": []}
    # Some robots' spaces are unbounded (GR1's): actions within [-1, 1] there.
    low, high = (np.clip(bound, -1.0, 1.0) for bound in env.action_spec)
    actions = np.random.default_rng(0)
    for _ in range(STEPS):
        o, reward, _, _ = env.step(actions.uniform(low, high))
        obs.append(o)
        record["reward"].append(float(reward))
    record["obs"] = [{k: np.asarray(v, dtype=float).ravel().tolist() for k, v in o.items()} for o in obs]
    env.close()
    return record


def envs():
    for name in sorted(robosuite.ALL_ENVIRONMENTS):
        robots = ["Panda", "Panda"] if name in TWO_ARM else "Panda"
        case(f"env/{name}", lambda n=name, r=robots: run_env(n, r))
    for name in sorted(ROBOT_CLASS_MAPPING):
        if name != "Panda":  # env/Lift
            case(f"lift/{name}", lambda n=name: run_env("Lift", n))


if group in ("models", "all"):
    models()
if group in ("envs", "all"):
    envs()

with open(out_path, "w") as f:
    json.dump(out, f)
