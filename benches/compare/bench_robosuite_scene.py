#!/usr/bin/env python3
"""Same-run speed baseline: robosuite assembling its Lift scene (the scene of
benches/tools/assemble_scene.rs and benches/model.rs) with its own model classes.

Prints one JSON object on stdout:
  scenes_per_s, ms_per_scene (best run), runs, what, mode, median_ms_per_scene,
  mean_ms_per_scene, parse_ms_per_scene, output_chars, stubs, robosuite, python.

Setup: scripts/setup_robosuite.sh, then
  .cache/venv-robosuite/bin/python benches/compare/bench_robosuite_scene.py [--runs N]
  [--mode auto|classes|merge] [--minimal]

What is timed (one scene per run, best of --runs, default 20):

--mode classes (what --mode auto, the default, runs when the classes import):
  robosuite 1.5.2's own classes, in the order robosuite.robots.Robot.load_model and
  robosuite.environments.manipulation.lift.Lift._load_model use them:
    robot = create_robot("Panda", idn=0)                            (Panda, prefix robot0_)
    robot.add_base(robot_base_factory(robot.default_base, idn=0))   (RethinkMount, fixed_mount0_)
    robot.update_joints(); robot.update_actuators()
    gripper = gripper_factory(robot.default_gripper["right"], idn="0_right")
                                                                    (PandaGripper, gripper0_right_)
    robot.add_gripper(gripper, robot.eef_name["right"])             (into robot0_right_hand)
    robot.set_base_xpos(robot.base_xpos_offset["table"](0.8))
    arena = TableArena(table_full_size=(0.8, 0.8, 0.05), table_friction=(1.0, 5e-3, 1e-4),
                       table_offset=(0, 0, 0.8)); arena.set_origin([0, 0, 0])
    objects = CanObject("object0"), MilkObject("object1"), BreadObject("object2"),
              CerealObject("object3"), LemonObject("object4")       (prefixes object0_..object4_)
    task = ManipulationTask(mujoco_arena=arena, mujoco_robots=[robot], mujoco_objects=objects)
    task.get_xml()
  robosuite offers no way to build these models from already-parsed XML: every
  constructor takes a path and runs ET.parse on it, then inlines default classes,
  makes asset paths absolute, prefixes names and recolors collision geoms. So the
  timed region includes parsing 10 files (base.xml of ManipulationTask's world,
  table_arena.xml, panda/robot.xml, rethink_mount.xml, panda_gripper.xml and the 5
  object files); parse_ms_per_scene reports, separately, the best-of-N time of just
  ET.parse on those 10 files, so that share can be subtracted. mjcf-forge's
  assemble_scene starts from documents already loaded (it clones them per scene).
  Not timed (not XML assembly): Robot.load_model's robot_model.set_mujoco_model()
  (a MuJoCo compile), and Lift's cube, placement sampler and MjSim.
  Lift's cube (a generated BoxObject) is replaced by the 5 XML objects above.
  --minimal leaves out the four cheap Lift steps mjcf-forge has no counterpart for:
  update_joints, update_actuators, set_base_xpos, set_origin.
  Naming differs from mjcf-forge only in length: robosuite's mount prefix is
  fixed_mount0_ (mjcf-forge: mount0_) and Lift's gripper prefix gripper0_right_
  (mjcf-forge: gripper0_). robosuite also adds a free joint to each object and
  visual copies of collision geoms (MujocoXMLObject's duplicate_collision_geoms),
  so its output is a little larger.

--mode merge (the fallback --mode auto takes when the classes cannot be imported,
  and selectable to compare): robosuite's MujocoXML / MujocoXMLModel with minimal
  subclasses giving only what MujocoXMLModel needs (naming_prefix, collision colour,
  the _important_* names), doing exactly mjcf-forge's steps: robot0_, gripper0_
  and mount0_ instances, gripper merged into robot0_right_hand, mount into
  robot0_base, robot and object0_..object4_ merged into MujocoXML(table_arena.xml),
  then get_xml(). Parses 9 files per scene (no base.xml).

Imports: robosuite's code comes from the unpacked wheel .cache/corpus/robosuite-1.5.2
(robosuite/__init__.py, which imports every environment, is skipped, as in
benches/compare/bench_robosuite.py). Importing the model classes also imports modules that
need numba, mujoco and cv2, which the light venv lacks; for those this script puts
minimal stand-ins in sys.modules, only when the real package is not installed, and
lists them under "stubs". None of them runs during assembly:
  numba: robosuite.utils.numba imports it to JIT transform_utils; with the stub,
    robosuite's own switch macros.ENABLE_NUMBA is set False, so transform_utils'
    functions stay plain numpy (none of them is called in the timed steps).
  mujoco (MjModel, MjData): only type annotations in models/tasks/task.py and
    models/robots/robot_model.py, and class set-up in utils/binding_utils.py
    (simulation bindings); get_model()/set_mujoco_model() compile with MuJoCo and
    are not called.
  mujoco.viewer, cv2: robosuite.renderers.viewer (on-screen viewers), imported by
    models/grippers/gripper_tester.py (a simulation test harness).
"""
from __future__ import annotations

import argparse
import contextlib
import importlib.machinery
import importlib.util
import json
import platform
import statistics
import sys
import time
import types
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RS_DIR = ROOT / ".cache" / "corpus" / "robosuite-1.5.2"
ASSETS = RS_DIR / "robosuite" / "models" / "assets"

OBJECT_FILES = ["can", "milk", "bread", "cereal", "lemon"]


def _missing(name: str) -> bool:
    return importlib.util.find_spec(name) is None


def install_stubs() -> list[str]:
    """Stand-ins for heavy packages the model modules import but assembly never uses."""
    stubs = []
    if _missing("numba"):
        sys.modules["numba"] = types.ModuleType("numba")
        import robosuite.macros as macros

        macros.ENABLE_NUMBA = False  # jit_decorator then returns the plain function
        stubs.append("numba")
    if _missing("mujoco"):
        mj = types.ModuleType("mujoco")
        mj.__path__ = []

        class MjModel:  # type annotations only
            def __init__(self, *a, **k):
                raise RuntimeError("mujoco is stubbed: MjModel is not available")

        class MjData:  # binding_utils lists its attributes at import
            def __init__(self, *a, **k):
                raise RuntimeError("mujoco is stubbed: MjData is not available")

        mj.MjModel, mj.MjData = MjModel, MjData
        viewer = types.ModuleType("mujoco.viewer")
        mj.viewer = viewer
        sys.modules["mujoco"] = mj
        sys.modules["mujoco.viewer"] = viewer
        stubs += ["mujoco (MjModel, MjData)", "mujoco.viewer"]
    if _missing("cv2"):
        sys.modules["cv2"] = types.ModuleType("cv2")
        stubs.append("cv2")
    return stubs


def import_robosuite_package():
    """robosuite 1.5.2's unpacked wheel importable as the package ``robosuite`` (its
    modules load from there) without running its ``__init__.py``."""
    pkg_dir = RS_DIR / "robosuite"
    if not pkg_dir.is_dir():
        raise SystemExit(f"{pkg_dir} missing: run scripts/setup_robosuite.sh")
    # A package object for `robosuite` whose submodules load from the unpacked
    # wheel, without running robosuite/__init__.py.
    spec = importlib.machinery.ModuleSpec("robosuite", None, is_package=True)
    spec.submodule_search_locations = [str(pkg_dir)]
    pkg = importlib.util.module_from_spec(spec)
    pkg.__file__ = str(pkg_dir / "__init__.py")
    pkg.__version__ = "1.5.2"
    sys.modules["robosuite"] = pkg
    return pkg


def make_classes_builder(minimal: bool):
    from robosuite.models.arenas import TableArena
    from robosuite.models.bases import robot_base_factory
    from robosuite.models.grippers import gripper_factory
    from robosuite.models.objects import BreadObject, CanObject, CerealObject, LemonObject, MilkObject
    from robosuite.models.robots import create_robot
    from robosuite.models.tasks import ManipulationTask

    object_classes = [CanObject, MilkObject, BreadObject, CerealObject, LemonObject]
    table_full_size = (0.8, 0.8, 0.05)

    def build() -> str:
        robot = create_robot("Panda", idn=0)
        robot.add_base(base=robot_base_factory(robot.default_base, idn=0))
        if not minimal:
            robot.update_joints()
            robot.update_actuators()
        gripper = gripper_factory(robot.default_gripper["right"], idn="0_right")
        robot.add_gripper(gripper, robot.eef_name["right"])
        if not minimal:
            robot.set_base_xpos(robot.base_xpos_offset["table"](table_full_size[0]))
        arena = TableArena(
            table_full_size=table_full_size,
            table_friction=(1.0, 5e-3, 1e-4),
            table_offset=(0, 0, 0.8),
        )
        if not minimal:
            arena.set_origin([0, 0, 0])
        objects = [cls(name=f"object{i}") for i, cls in enumerate(object_classes)]
        task = ManipulationTask(mujoco_arena=arena, mujoco_robots=[robot], mujoco_objects=objects)
        return task.get_xml()

    parsed = ["base.xml", "arenas/table_arena.xml", "robots/panda/robot.xml",
              "bases/rethink_mount.xml", "grippers/panda_gripper.xml"]
    parsed += [f"objects/{o}.xml" for o in OBJECT_FILES]
    return build, parsed


def make_merge_builder():
    from robosuite.models.base import MujocoXML, MujocoXMLModel
    from robosuite.utils.mjcf_utils import (
        GRIPPER_COLLISION_COLOR,
        MOUNT_COLLISION_COLOR,
        OBJECT_COLLISION_COLOR,
        ROBOT_COLLISION_COLOR,
    )

    from robosuite_models import part_class

    Part = part_class(MujocoXMLModel, ASSETS)

    def build() -> str:
        robot = Part("robots/panda/robot.xml", "robot0", ROBOT_COLLISION_COLOR)
        gripper = Part("grippers/panda_gripper.xml", "gripper0", GRIPPER_COLLISION_COLOR)
        mount = Part("bases/rethink_mount.xml", "mount0", MOUNT_COLLISION_COLOR)
        robot.merge(gripper, merge_body="robot0_right_hand")
        robot.merge(mount, merge_body="robot0_base")
        objects = [Part(f"objects/{o}.xml", f"object{i}", OBJECT_COLLISION_COLOR)
                   for i, o in enumerate(OBJECT_FILES)]
        scene = MujocoXML(str(ASSETS / "arenas/table_arena.xml"))
        scene.merge([robot] + objects)
        return scene.get_xml()

    parsed = ["arenas/table_arena.xml", "robots/panda/robot.xml",
              "bases/rethink_mount.xml", "grippers/panda_gripper.xml"]
    parsed += [f"objects/{o}.xml" for o in OBJECT_FILES]
    return build, parsed


def best_of(fn, runs):
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return times


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=20, help="best of this many scenes (default 20)")
    ap.add_argument("--mode", choices=("auto", "classes", "merge"), default="auto")
    ap.add_argument("--minimal", action="store_true",
                    help="classes mode: skip update_joints/update_actuators/set_base_xpos/set_origin")
    args = ap.parse_args()

    stubs: list[str] = []
    import_error = None
    # robosuite logs its macro warnings at import; keep stdout for the JSON.
    with contextlib.redirect_stdout(sys.stderr):
        import_robosuite_package()
        mode = args.mode
        if mode in ("auto", "classes"):
            stubs = install_stubs()
            try:
                build, parsed = make_classes_builder(args.minimal)
                mode = "classes"
            except ImportError as e:
                if args.mode == "classes":
                    raise
                import_error = f"{type(e).__name__}: {e}"
                mode = "merge"
        if mode == "merge":
            build, parsed = make_merge_builder()
        # Untimed: first scene (imports, caches).
        xml = build()
    ET.fromstring(xml)  # the output is well-formed XML

    times = best_of(build, args.runs)
    paths = [str(ASSETS / p) for p in parsed]
    parse_times = best_of(lambda: [ET.parse(p) for p in paths], args.runs)
    best = min(times)

    if mode == "classes":
        what = ("robosuite 1.5.2 classes, per scene: Panda + RethinkMount + PandaGripper, "
                "TableArena, Can/Milk/Bread/Cereal/LemonObject, ManipulationTask, get_xml(); "
                "includes parsing 10 XML files" +
                ("; --minimal (no update_joints/update_actuators/set_base_xpos/set_origin)"
                 if args.minimal else "; with Lift's update_joints/update_actuators/set_base_xpos/set_origin"))
    else:
        what = ("robosuite 1.5.2 MujocoXML/MujocoXMLModel merge path (minimal subclasses), per scene: "
                "robot0_/gripper0_/mount0_/object0_..4_ instances merged into MujocoXML(table_arena.xml), "
                "get_xml(); includes parsing 9 XML files")
    import numpy

    out = {
        "scenes_per_s": round(1.0 / best, 2),
        "ms_per_scene": round(best * 1e3, 3),
        "runs": args.runs,
        "what": what,
        "mode": mode,
        "median_ms_per_scene": round(statistics.median(times) * 1e3, 3),
        "mean_ms_per_scene": round(statistics.fmean(times) * 1e3, 3),
        "parse_ms_per_scene": round(min(parse_times) * 1e3, 3),
        "parsed_files": len(paths),
        "output_chars": len(xml),
        "stubs": stubs,
        "robosuite": "1.5.2 (unpacked wheel)",
        "python": platform.python_version(),
        "numpy": numpy.__version__,
    }
    if import_error:
        out["classes_import_error"] = import_error
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
