#!/usr/bin/env python3
"""Same-run speed of a scene's superset against compiling each variant (docs/speed.md).

For SCENE (default benches/scenes/lift5.toml), in one process:

  compile   mujoco.MjModel.from_xml_string(variant.xml) and its MjData: a variant made
            ready by compiling it. Timed on a sample of SAMPLE variants (their median),
            and extrapolated to WORLDS variants (WORLDS x the median: said so in the output);
  superset  ModelCache(scene, superset=True): its one compile (paid once per scene);
  ready     scene.variant(i), cache.model(variant) (the superset patched for it) and
            mj_resetData: a variant ready to step on CPU MuJoCo through the superset
            (best and median of RUNS, after one warm-up);
  arrays    WorldBatch(cache, range(WORLDS)): the per-world arrays of WORLDS worlds
            (every per-world field, statistics, parked geoms, and each world's initial
            pose checked for parked contacts), timed whole, once.

Ratios: compile median / ready median (the issue asks >= 50x), and extrapolated compiles
of WORLDS variants / arrays (>= 100x for 4,096 lift5 worlds). Prints one JSON line.

Usage: python benches/compare/bench_superset.py [--scene S] [--worlds 4096] [--sample 8] [--runs 200]
(any venv with mujoco and mjcf_forge: .cache/venv-sim for MuJoCo 4.0.0).
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import mujoco

import mjcf_forge
from mjcf_forge import ModelCache
from mjcf_forge.batch import WorldBatch

ROOT = Path(__file__).resolve().parents[2]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default=str(ROOT / "benches" / "scenes" / "lift5.toml"))
    ap.add_argument("--worlds", type=int, default=4096)
    ap.add_argument("--sample", type=int, default=8)
    ap.add_argument("--runs", type=int, default=200)
    args = ap.parse_args()
    scene = mjcf_forge.Scene.load(args.scene)

    # Variants far from the ones timed below, so no cache of ours is warm for them.
    compile_ms = []
    mujoco.MjData(mujoco.MjModel.from_xml_string(scene.variant(10**6).xml))  # asset files in the OS cache
    for i in range(args.sample):
        xml = scene.variant(10**6 + 1 + i).xml
        t = time.perf_counter()
        model = mujoco.MjModel.from_xml_string(xml)
        mujoco.MjData(model)
        compile_ms.append((time.perf_counter() - t) * 1e3)

    t = time.perf_counter()
    cache = ModelCache(scene, superset=True)
    model = cache.model(scene.variant(0))
    superset_ms = (time.perf_counter() - t) * 1e3
    data = mujoco.MjData(model)

    def ready(i: int) -> None:
        m = cache.model(scene.variant(i))
        mujoco.mj_resetData(m, data)

    ready(1)
    ready_ms = []
    for i in range(2, args.runs + 2):
        t = time.perf_counter()
        ready(i)
        ready_ms.append((time.perf_counter() - t) * 1e3)

    t = time.perf_counter()
    batch = WorldBatch(cache, range(args.worlds))
    arrays_ms = (time.perf_counter() - t) * 1e3

    compile_med = statistics.median(compile_ms)
    ready_med = statistics.median(ready_ms)
    out = {
        "scene": Path(args.scene).stem,
        "mujoco": mujoco.__version__,
        "superset": {"nbody": model.nbody, "nv": model.nv, "ngeom": model.ngeom},
        "compile_ms": {"best": min(compile_ms), "median": compile_med, "sample": len(compile_ms)},
        "superset_compile_ms": superset_ms,
        "ready_ms": {"best": min(ready_ms), "median": ready_med, "runs": len(ready_ms)},
        "ready_speedup": compile_med / ready_med,
        "worlds": args.worlds,
        "per_world_fields": len(batch.per_world),
        "arrays_ms": arrays_ms,
        "compile_all_ms_extrapolated": compile_med * args.worlds,
        "arrays_speedup": compile_med * args.worlds / arrays_ms,
        "arrays_speedup_with_superset_compile": compile_med * args.worlds / (arrays_ms + superset_ms),
    }
    print(json.dumps(out))
    print(
        f"{out['scene']}: a variant ready through the superset {ready_med:.2f} ms (median) against "
        f"compiling it {compile_med:.0f} ms: {out['ready_speedup']:.0f}x; per-world arrays of "
        f"{args.worlds} worlds {arrays_ms / 1e3:.1f} s against {args.worlds} compiles "
        f"(extrapolated from {len(compile_ms)}) {compile_med * args.worlds / 1e3:.0f} s: "
        f"{out['arrays_speedup']:.0f}x ({out['arrays_speedup_with_superset_compile']:.0f}x "
        "with the superset's own compile)",
        file=sys.stderr,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
