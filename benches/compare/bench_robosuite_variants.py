#!/usr/bin/env python3
"""Same-run speed baseline: robosuite building the randomized scene of
benches/scenes/lift5.toml, one variant at a time, with its own classes, as a
robosuite environment does on a hard reset (Lift._load_model + _reset_internal's
placement sampling), up to task.get_xml().

Prints one JSON object on stdout:
  variants_per_s (1 / best), ms_per_variant (best), median_ms_per_variant,
  variants_per_s_median, mean_ms_per_variant, cpu_ms_per_variant (best),
  median_cpu_ms_per_variant, mean_cpu_ms_per_variant (process CPU time,
  time.process_time, less sensitive than wall time to other processes on a shared
  machine), runs, seed, what, output_chars_mean,
  placements_checked, stubs, robosuite, python, numpy.

Setup: scripts/setup_robosuite.sh, then
  .cache/venv-robosuite/bin/python benches/compare/bench_robosuite_variants.py [--runs N]
  [--seed S] [--dump DIR]

What is timed, per variant i (one variant per run, --runs distinct variants,
default 50, after one untimed variant for imports and caches):
    rng = np.random.default_rng([seed, i])        (all randomness of variant i)
    robot = create_robot("Panda", idn=0)                          (prefix robot0_)
    robot.add_base(robot_base_factory(robot.default_base, idn=0)) (RethinkMount)
    robot.update_joints(); robot.update_actuators()
    gripper = gripper_factory(robot.default_gripper["right"], idn="0_right")
    robot.add_gripper(gripper, robot.eef_name["right"])           (PandaGripper)
    robot.set_base_xpos(robot.base_xpos_offset["table"](0.8))
    arena = TableArena(table_full_size=(0.8, 0.8, 0.05), table_friction=(1.0, 5e-3, 1e-4),
                       table_offset=(0, 0, 0.8)); arena.set_origin([0, 0, 0])
    objects: 5 classes drawn with replacement, uniformly, by rng.integers from
      CanObject, MilkObject, BreadObject, CerealObject, LemonObject, BottleObject,
      named object0..object4 (as lift5's 5 slots draw from its pool of 6 files)
    every geom of every object (robosuite's collision geoms and the visual copies
      its duplicate_collision_geoms adds): rgba = (uniform(0,1) x 3, 1)
    sampler = UniformRandomSampler("ObjectSampler", mujoco_objects=objects,
        x_range=[-0.3, 0.3], y_range=[-0.3, 0.3], rotation=None (uniform [0, 2pi)),
        rotation_axis="z", ensure_object_boundary_in_range=False,
        ensure_valid_placement=True, reference_pos=(0, 0, 0.8), z_offset=0.01, rng=rng)
    for pos, quat, obj in sampler.sample().values():
        obj.get_obj().set("pos", array_to_string(pos))
        obj.get_obj().set("quat", array_to_string(quat))
    task = ManipulationTask(mujoco_arena=arena, mujoco_robots=[robot], mujoco_objects=objects)
    task.get_xml()
  This is what Lift's _load_model does (robot, arena, objects, sampler, task) with
  its cube replaced by the 5 drawn XML objects, plus the placement of
  _reset_internal. robosuite has no way to build these models from already-parsed
  XML: each constructor parses its file (10 files per variant: base.xml of the task,
  the arena, robot, mount, gripper and the 5 objects), inlines defaults, makes paths
  absolute, prefixes names; all of that is inside the timed region, as it is on a
  robosuite hard reset.

Not included (not XML assembly, or not done at XML level by robosuite):
  - Compiling with MuJoCo (robot_model.set_mujoco_model(), the env's
    _initialize_sim) and creating MjSim: mjcf-forge's streamed figure has no
    compile either.
  - robosuite's environments put free-jointed objects at their sampled pose after
    the compile, through sim.data.set_joint_qpos. Without a compiled model that is
    not possible, so the pose is written into each object's root body (whose free
    joint then starts there, which is what mjcf-forge writes); robosuite's own code
    writes root-body poses this way for fixtures (two_arm_peg_in_hole) and robots
    (RobotModel.set_base_xpos).
  - Colours: robosuite randomizes colours only on the compiled model
    (utils/mjmod.py's TextureModder, DomainRandomizationWrapper); the XML-level
    equivalent of lift5's rgba randomizer is the plain ElementTree loop above.
  - Writing the XML anywhere: get_xml() returns a string, nothing is written.
  - No manifest of sampled values (mjcf-forge's stream carries a JSON per variant).

Imports: as in benches/compare/bench_robosuite_scene.py (whose helpers this uses): robosuite's
code from the unpacked wheel .cache/corpus/robosuite-1.5.2 without running
robosuite/__init__.py, and stand-ins in sys.modules for numba, mujoco and cv2 only
when they are not installed (listed under "stubs"). None of them runs in the timed
steps (transform_utils.quat_multiply is not called: XML objects have no init_quat).

--dump DIR writes variants 0 and 1 as DIR/robosuite-variant-0.xml and -1.xml (for
example to compile them with MuJoCo from .cache/venv); the XML references robosuite's
asset files by absolute path.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import platform
import statistics
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_robosuite_scene import import_robosuite_package, install_stubs  # noqa: E402
from robosuite_models import N_OBJECTS, lift5_builder  # noqa: E402

def check_variant(xml: str, placements) -> None:
    """The output has the 5 objects at their sampled poses (fails loudly otherwise)."""
    root = ET.fromstring(xml)
    bodies = {b.get("name"): b for b in root.find("worldbody")}
    if len(placements) != N_OBJECTS:
        raise SystemExit(f"bench_robosuite_variants: {len(placements)} placements, expected {N_OBJECTS}")
    for pos, quat, obj in placements.values():
        body = bodies.get(obj.root_body)
        if body is None:
            raise SystemExit(f"bench_robosuite_variants: {obj.root_body} missing from the worldbody")
        got = [float(v) for v in body.get("pos").split()] + [float(v) for v in body.get("quat").split()]
        want = list(pos) + list(quat)
        if any(abs(a - b) > 1e-9 for a, b in zip(got, want)) or len(got) != 7:
            raise SystemExit(f"bench_robosuite_variants: {obj.root_body} at {got}, sampled {want}")
        if body.find("freejoint") is None and not any(
            j.get("type") == "free" for j in body.findall("joint")
        ):
            raise SystemExit(f"bench_robosuite_variants: {obj.root_body} has no free joint")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=50, help="time this many variants, one each (default 50)")
    ap.add_argument("--seed", type=int, default=1, help="variant i draws from default_rng([seed, i]) (default 1)")
    ap.add_argument("--dump", type=Path, help="write variants 0 and 1 into this folder")
    args = ap.parse_args()
    if args.runs < 1:
        ap.error("--runs must be at least 1")

    # robosuite logs its macro warnings at import; keep stdout for the JSON.
    with contextlib.redirect_stdout(sys.stderr):
        import_robosuite_package()
        stubs = install_stubs()
        build = lift5_builder()
        # Untimed: one variant outside the timed indices (imports, caches).
        xml, placements = build(args.seed, args.runs)
    check_variant(xml, placements)

    times, cpu_times, chars = [], [], []
    for i in range(args.runs):
        c0, t0 = time.process_time(), time.perf_counter()
        xml, placements = build(args.seed, i)
        times.append(time.perf_counter() - t0)
        cpu_times.append(time.process_time() - c0)
        chars.append(len(xml))
        if args.dump is not None and i < 2:
            args.dump.mkdir(parents=True, exist_ok=True)
            (args.dump / f"robosuite-variant-{i}.xml").write_text(xml)
        # Every variant, outside the timed region.
        check_variant(xml, placements)

    import numpy

    best, median = min(times), statistics.median(times)
    print(json.dumps({
        "variants_per_s": round(1.0 / best, 2),
        "ms_per_variant": round(best * 1e3, 3),
        "median_ms_per_variant": round(median * 1e3, 3),
        "variants_per_s_median": round(1.0 / median, 2),
        "mean_ms_per_variant": round(statistics.fmean(times) * 1e3, 3),
        "cpu_ms_per_variant": round(min(cpu_times) * 1e3, 3),
        "median_cpu_ms_per_variant": round(statistics.median(cpu_times) * 1e3, 3),
        "mean_cpu_ms_per_variant": round(statistics.fmean(cpu_times) * 1e3, 3),
        "runs": args.runs,
        "seed": args.seed,
        "what": ("robosuite 1.5.2 classes, per variant (hard reset up to get_xml): Panda + RethinkMount + "
                 "PandaGripper, TableArena, 5 objects drawn from Can/Milk/Bread/Cereal/Lemon/BottleObject, "
                 "random rgba on their geoms, UniformRandomSampler poses written into their root bodies, "
                 "ManipulationTask, get_xml(); includes parsing 10 XML files"),
        "output_chars_mean": round(statistics.fmean(chars)),
        "placements_checked": args.runs + 1,
        "stubs": stubs,
        "robosuite": "1.5.2 (unpacked wheel)",
        "python": platform.python_version(),
        "numpy": numpy.__version__,
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
