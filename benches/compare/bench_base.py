#!/usr/bin/env python3
"""Same-run speed comparison of the model hierarchy: the same code, written against
robosuite's classes, run on `robosuite.models.base` (robosuite 1.5.2) and on
`mjcf_forge.base`, in one process, rounds alternating between the two.

What one scene is (robosuite's Lift parts, as `benches/compare/bench_robosuite_scene.py --mode
merge` builds them): Panda, its gripper and its mount loaded as `MujocoXMLModel`s (load,
inline default classes, absolute paths, prefix, recolour), the gripper merged into
`robot0_right_hand` and the mount into `robot0_base`, five robosuite objects loaded the
same way, all merged into `MujocoXML(table_arena.xml)`, then `get_xml()`. robosuite parses
the 9 files in every scene. Ours is measured twice: as users get it (`mjcf_forge.base`
reads through `FILE_CACHE`, so an unchanged file is a copy of its first load), and with
`FILE_CACHE = None` (every file read and parsed anew, as robosuite does).

Also: `findall` over a Panda's root with ElementPath queries, robosuite's tree
(`xml.etree`) against ours, on the same model.

Run (needs scripts/setup.sh and scripts/setup_robosuite_env.sh):
  bash benches/compare/bench_base.sh [ROUNDS]
which runs this file in .cache/venv-robosuite-env (robosuite 1.5.2, MuJoCo 3.9.0) with the
checkout's installed `mjcf_forge` on the path. Prints one JSON object per measurement and
the ratios (robosuite's time over ours: above 1 means we are faster).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path
from timing import mean_seconds  # noqa: E402
from robosuite_models import part_class  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
ASSETS = ROOT / ".cache/corpus/robosuite-1.5.2/robosuite/models/assets"
OBJECT_FILES = ["can", "milk", "bread", "cereal", "lemon"]
QUERIES = [".//geom", ".//body[@name='link7']", "./worldbody/body", ".//joint[@type]", ".//*[@pos]"]


def make_builder(base, colors):
    """The scene, written once against robosuite's API, over `base`'s classes."""

    Part = part_class(base.MujocoXMLModel, ASSETS)

    def build() -> str:
        robot = Part("robots/panda/robot.xml", "robot0", colors["robot"])
        gripper = Part("grippers/panda_gripper.xml", "gripper0", colors["gripper"])
        mount = Part("bases/rethink_mount.xml", "mount0", colors["mount"])
        robot.merge(gripper, merge_body="robot0_right_hand")
        robot.merge(mount, merge_body="robot0_base")
        objects = [Part(f"objects/{o}.xml", f"object{i}", colors["object"])
                   for i, o in enumerate(OBJECT_FILES)]
        scene = base.MujocoXML(str(ASSETS / "arenas/table_arena.xml"))
        scene.merge([robot] + objects)
        return scene.get_xml()

    return build




def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--scenes", type=int, default=5, help="scenes per round and side")
    args = ap.parse_args()

    import xml.etree.ElementTree as ET

    import mjcf_forge
    import mujoco
    import robosuite.models.base as rs_base
    from mjcf_forge import base as mf_base
    from robosuite.utils import mjcf_utils

    colors = {
        "robot": mjcf_utils.ROBOT_COLLISION_COLOR,
        "gripper": mjcf_utils.GRIPPER_COLLISION_COLOR,
        "mount": mjcf_utils.MOUNT_COLLISION_COLOR,
        "object": mjcf_utils.OBJECT_COLLISION_COLOR,
    }
    files = mf_base.FILE_CACHE

    def reading_anew(build):
        def run():
            mf_base.FILE_CACHE = None
            try:
                return build()
            finally:
                mf_base.FILE_CACHE = files

        return run

    ours = make_builder(mf_base, colors)
    sides = {
        "robosuite": make_builder(rs_base, colors),
        "mjcf_forge": ours,
        "mjcf_forge_no_file_cache": reading_anew(ours),
    }
    outputs = {name: build() for name, build in sides.items()}  # warm up; all must work
    assert outputs["mjcf_forge"] == outputs["mjcf_forge_no_file_cache"]
    scene_times = {name: [] for name in sides}
    for _ in range(args.rounds):
        for name, build in sides.items():
            scene_times[name].append(mean_seconds(build, args.scenes))

    # ElementPath over the same Panda: robosuite's tree against ours.
    panda = str(ASSETS / "robots/panda/robot.xml")
    trees = {
        "robosuite": ET.fromstring(mjcf_forge.Document.load(panda).to_xml()),
        "mjcf_forge": mjcf_forge.Document.load(panda).root,
    }
    find_times = {q: {name: [] for name in trees} for q in QUERIES}
    for q in QUERIES:
        counts = {name: len(root.findall(q)) for name, root in trees.items()}
        assert counts["robosuite"] == counts["mjcf_forge"], (q, counts)
        for _ in range(args.rounds):
            for name, root in trees.items():
                find_times[q][name].append(mean_seconds(lambda: root.findall(q), 2000))

    result = {
        "python": sys.version.split()[0],
        "mujoco": mujoco.__version__,
        "mjcf_forge": mjcf_forge.__version__,
        "rounds": args.rounds,
        "scene": {
            name: {
                "best_ms": min(t) * 1e3,
                "median_ms": statistics.median(t) * 1e3,
                "output_chars": len(outputs[name]),
            }
            for name, t in scene_times.items()
        },
        "findall_us": {
            q: {name: min(t) * 1e6 for name, t in by.items()} for q, by in find_times.items()
        },
    }
    rs, mf = scene_times["robosuite"], scene_times["mjcf_forge"]
    result["scene_ratio_best"] = min(rs) / min(mf)
    result["scene_ratio_median"] = statistics.median(rs) / statistics.median(mf)
    anew = scene_times["mjcf_forge_no_file_cache"]
    result["scene_ratio_no_file_cache_best"] = min(rs) / min(anew)
    result["scene_ratio_no_file_cache_median"] = statistics.median(rs) / statistics.median(anew)
    result["findall_ours_over_etree"] = {
        q: min(by["mjcf_forge"]) / min(by["robosuite"]) for q, by in find_times.items()
    }
    print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
