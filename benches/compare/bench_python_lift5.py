#!/usr/bin/env python3
"""Same-process comparison from Python: the lift5 scene's randomized variants made by
mjcf_forge (``scene.variant(i).xml``, one at a time) against robosuite 1.5.2 building the
same randomized scene with its own classes; and the cost of crossing into Python per
variant.

Run: bash benches/compare/bench_python_lift5.sh [--rounds R] [--forge N] [--robosuite M]
(which installs the package into .cache/venv-robosuite and runs this there).

The scene (benches/scenes/lift5.toml): robosuite's table arena, the Panda with its mount
and gripper, five objects drawn from robosuite's can, milk, bread, cereal, lemon and
bottle, placed on the table without overlap (x, y in [-0.3, 0.3]) with a random z
rotation, every object geom given a random colour.

robosuite, per variant, as its Lift environment builds a scene (robosuite.robots.Robot.
load_model and Lift._load_model), with the randomization the scene file describes:
    robot = create_robot("Panda", idn=0); robot.add_base(robot_base_factory(...))
    robot.update_joints(); robot.update_actuators()
    robot.add_gripper(gripper_factory(robot.default_gripper["right"], idn="0_right"), ...)
    robot.set_base_xpos(robot.base_xpos_offset["table"](0.8))
    arena = TableArena(table_full_size=(0.8, 0.8, 0.05), table_offset=(0, 0, 0.8), ...)
    5 objects drawn from the 6 classes (rng.choice), named object0..object4
    UniformRandomSampler(x_range=[-0.3, 0.3], y_range=[-0.3, 0.3], rotation=None (z),
        ensure_valid_placement=True, reference_pos=(0, 0, 0.8), z_offset=0.01).sample()
    placements written into each object's root body (pos, quat); rgba of every object
    geom drawn uniformly; ManipulationTask(...).get_xml()
robosuite has no way to build from already-parsed files: its constructors parse their
XML each time (10 to 11 files per scene), which is part of what it costs.

mjcf_forge, per variant: ``scene.variant(i).xml`` on a scene loaded once (untimed, as
robosuite's imports are), one variant at a time on the calling thread: the Rust work with
the GIL released, the Variant object, and the ``str`` of its XML.

Crossing cost: the same variants made by ``_testing.rust_seconds`` (the identical Rust calls
in a Rust loop, no Python object made) subtracted from the Python loop's time.

Rounds alternate the sides (robosuite's block, then mjcf_forge and the Rust loop in
alternating blocks of 100 identical indices) so that load on the shared machine falls on
all of them; per side the best and the median block are reported, and the ratio of each.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_robosuite_scene as rs  # noqa: E402  (robosuite import helpers, stubs)

LIFT5 = ROOT / "benches" / "scenes" / "lift5.toml"


def make_robosuite_builder(seed: int):
    """``build(index) -> xml``: lift5's variant ``index`` the robosuite way."""
    from robosuite_models import lift5_builder

    build = lift5_builder()
    return lambda index: build(seed, index)[0]


def per_variant(fn, indices) -> float:
    t = time.perf_counter()
    fn(indices)
    return (time.perf_counter() - t) / len(indices)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=10)
    ap.add_argument("--forge", type=int, default=1000, help="mjcf_forge variants per round")
    ap.add_argument("--robosuite", type=int, default=20, help="robosuite variants per round")
    args = ap.parse_args()

    with contextlib.redirect_stdout(sys.stderr):  # robosuite prints at import
        rs.import_robosuite_package()
        stubs = rs.install_stubs()
        build = make_robosuite_builder(seed=1)
        sample_xml = build(0)  # untimed: imports, caches
    import mjcf_forge
    from mjcf_forge._mjcf_forge import _testing

    scene = mjcf_forge.Scene.load(LIFT5)
    forge_xml = scene.variant(0).xml  # untimed: per-slot instances made on first use

    def forge(indices):
        for i in indices:
            scene.variant(i).xml

    def robosuite(indices):
        for i in indices:
            build(i)

    rounds = {"robosuite": [], "mjcf_forge": [], "rust_loop": []}
    block = 100  # mjcf_forge and the Rust loop alternate in blocks of the same indices
    for r in range(args.rounds):
        # Fresh indices each round: no variant is made twice by robosuite or in Python.
        rs_idx = list(range(r * args.robosuite, (r + 1) * args.robosuite))
        rounds["robosuite"].append(per_variant(robosuite, rs_idx))
        for b in range(r * args.forge, (r + 1) * args.forge, block):
            idx = list(range(b, b + block))
            rounds["mjcf_forge"].append(per_variant(forge, idx))
            rounds["rust_loop"].append(_testing.rust_seconds(scene, idx) / len(idx))

    best = {k: min(v) for k, v in rounds.items()}
    median = {k: statistics.median(v) for k, v in rounds.items()}
    out = {
        "robosuite_us_per_variant": {"best": round(best["robosuite"] * 1e6, 1), "median": round(median["robosuite"] * 1e6, 1)},
        "mjcf_forge_us_per_variant": {"best": round(best["mjcf_forge"] * 1e6, 2), "median": round(median["mjcf_forge"] * 1e6, 2)},
        "rust_loop_us_per_variant": {"best": round(best["rust_loop"] * 1e6, 2), "median": round(median["rust_loop"] * 1e6, 2)},
        "crossing_us_per_variant": {
            "best": round((best["mjcf_forge"] - best["rust_loop"]) * 1e6, 2),
            "median": round((median["mjcf_forge"] - median["rust_loop"]) * 1e6, 2),
        },
        "ratio": {
            "best": round(best["robosuite"] / best["mjcf_forge"], 1),
            "median": round(median["robosuite"] / median["mjcf_forge"], 1),
        },
        "variants_per_s": {"robosuite": round(1 / best["robosuite"], 1), "mjcf_forge": round(1 / best["mjcf_forge"], 1)},
        "rounds": args.rounds,
        "per_round": {"robosuite": args.robosuite, "mjcf_forge": args.forge},
        "xml_chars": {"robosuite": len(sample_xml), "mjcf_forge": len(forge_xml)},
        "stubs": stubs,
        "python": platform.python_version(),
        "mjcf_forge": mjcf_forge.__version__,
    }
    print(json.dumps(out))
    print(
        f"lift5 from Python, one variant at a time: mjcf_forge {out['mjcf_forge_us_per_variant']['best']} us "
        f"(Rust alone {out['rust_loop_us_per_variant']['best']} us, crossing "
        f"{out['crossing_us_per_variant']['best']} us), robosuite {out['robosuite_us_per_variant']['best'] / 1000:.2f} ms: "
        f"{out['ratio']['best']}x (median rounds {out['ratio']['median']}x)",
        file=sys.stderr,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
