#!/usr/bin/env python3
"""Same-run comparison: compiled variants of a fixed-structure scene ready to step, made by
compiling each variant's XML against patching one compiled model in place (ModelCache).

For SCENE (default benches/scenes/lift5_fixed.toml: robosuite's Lift with five fixed
objects, random poses, colours, frictions, link masses and light), in one process:

  compile   mujoco.MjModel.from_xml_string(variant.xml), then MjData: what a training
            loop pays per new scene today (asset files in the OS cache after the first);
  variant   scene.variant(i) and its .patch (the XML and the patch, in Rust);
  apply     cache.apply(variant, model) on the environment's own model, then
            mj_resetData: the model patched in place (mj_setConst and the compiler's
            statistics included) and ready to step;
  ready     variant + apply: a new randomized variant ready to step, end to end.

Best and median of RUNS (compile: COMPILES) per item, after one warm-up; a sample of the
patched models is checked bit for bit against compiling their XML before timing (a
failure stops the script). Prints one JSON line, then the ratios.

With --superset (default scene then benches/scenes/lift5.toml: five slots of six
robosuite objects), the scene's superset instead: its size against a variant's own model,
its compile, a variant patched into it (`cache.model(variant)`), and the simulation speed
of the superset model against the variant's own (mj_step, STEPS steps from the initial
pose, best of 3).

Usage: python benches/compare/bench_model_cache.py [--scene S] [--runs N] [--compiles K] [--superset]
(run with .cache/venv's Python for MuJoCo 3.17.0, .cache/venv-mj4's for 4.0.0).
"""
from __future__ import annotations

import os

# Misses are timed as compiles: no model store unless the caller sets one.
os.environ.setdefault("MJCF_FORGE_STORE", "off")

import argparse
import json
import sys
import time
from pathlib import Path

import mujoco
import numpy as np

import mjcf_forge
from mjcf_forge._mjcf_forge import MASS_DERIVED
from timing import each_ms, summary  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]






def steps_per_second(model, steps: int) -> float:
    data = mujoco.MjData(model)
    best = float("inf")
    for _ in range(3):
        mujoco.mj_resetData(model, data)
        t = time.perf_counter()
        mujoco.mj_step(model, data, nstep=steps)
        best = min(best, time.perf_counter() - t)
    return steps / best


def superset(args) -> int:
    scene = mjcf_forge.Scene.load(args.scene)
    t = time.perf_counter()
    cache = mjcf_forge.ModelCache(scene, superset=True)
    first = scene.variant(0)
    model = cache.model(first)
    compile_ms = (time.perf_counter() - t) * 1e3
    own = mujoco.MjModel.from_xml_string(first.xml)
    variants = [scene.variant(i) for i in range(args.runs + 1)]
    patch_ms = summary(each_ms(lambda i: cache.model(variants[i]), args.runs))
    cache.model(first)
    result = {
        "scene": args.scene,
        "mujoco": mujoco.__version__,
        "superset": {"nbody": model.nbody, "nv": model.nv, "ngeom": model.ngeom,
                     "compile_ms": compile_ms},
        "variant_0": {"nbody": own.nbody, "nv": own.nv, "ngeom": own.ngeom},
        "patch": patch_ms,
        "steps_per_second": {"superset": steps_per_second(model, args.steps),
                             "own_model": steps_per_second(own, args.steps)},
    }
    print(json.dumps(result))
    sp = result["steps_per_second"]
    print(f"superset: {model.nbody} bodies / {model.nv} dofs against {own.nbody} / {own.nv}; "
          f"compiled once in {compile_ms:.0f} ms; a variant patched in {patch_ms['median_ms']:.3f} ms "
          f"median; mj_step {sp['superset']:.0f}/s against {sp['own_model']:.0f}/s on the variant's "
          f"own model ({sp['superset'] / sp['own_model']:.2f}x)")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default=None)
    ap.add_argument("--runs", type=int, default=300)
    ap.add_argument("--compiles", type=int, default=15)
    ap.add_argument("--superset", action="store_true")
    ap.add_argument("--steps", type=int, default=2000)
    args = ap.parse_args()
    if args.superset:
        args.scene = args.scene or str(ROOT / "benches" / "scenes" / "lift5.toml")
        return superset(args)
    args.scene = args.scene or str(ROOT / "benches" / "scenes" / "lift5_fixed.toml")

    scene = mjcf_forge.Scene.load(args.scene)
    cache = mjcf_forge.ModelCache(scene)
    first = scene.variant(0)
    model = mujoco.MjModel.from_xml_string(first.xml)
    data = mujoco.MjData(model)

    # Exactness first: patched equals compiled, bit for bit, on a sample (what follows from
    # mass properties a unit model combines within 1e-12 relative: docs/compiled.md).
    bounded = set(MASS_DERIVED)
    for i in (1, 2, 3):
        v = scene.variant(i)
        if v.structure_key != first.structure_key:
            print(f"variant {i} has another structure: not a fixed-structure scene", file=sys.stderr)
            return 1
        cache.apply(v, model)
        ref = mujoco.MjModel.from_xml_string(v.xml)
        for name in dir(ref):
            a = getattr(ref, name, None)
            if isinstance(a, np.ndarray) and not np.array_equal(a, getattr(model, name), equal_nan=True):
                b = getattr(model, name)
                scale = max(float(np.max(np.abs(a))), 1e-300)
                within = np.all(np.abs(a - b) <= 1e-12 * np.maximum(np.maximum(np.abs(a), np.abs(b)), scale))
                if name in bounded and within:
                    continue
                print(f"variant {i}: {name} differs from MuJoCo's compile", file=sys.stderr)
                return 1

    variants = [scene.variant(i) for i in range(args.runs + 1)]
    for v in variants:
        v.patch  # noqa: B018 (made once here; the variant item below times it)

    def compile_one(i: int) -> None:
        m = mujoco.MjModel.from_xml_string(variants[i].xml)
        mujoco.MjData(m)

    def variant_one(i: int) -> None:
        v = scene.variant(10_000 + i)
        v.patch  # noqa: B018

    def apply_one(i: int) -> None:
        cache.apply(variants[i], model)
        mujoco.mj_resetData(model, data)

    def ready_one(i: int) -> None:
        v = scene.variant(20_000 + i)
        cache.apply(v, model)
        mujoco.mj_resetData(model, data)

    result = {
        "scene": str(Path(args.scene).relative_to(ROOT)) if args.scene.startswith(str(ROOT)) else args.scene,
        "mujoco": mujoco.__version__,
        "python": sys.version.split()[0],
        "patch_entries": len(first.patch),
        "compile": summary(each_ms(compile_one, args.compiles)),
        "variant": summary(each_ms(variant_one, args.runs)),
        "apply": summary(each_ms(apply_one, args.runs)),
        "ready": summary(each_ms(ready_one, args.runs)),
    }
    print(json.dumps(result))
    c, r = result["compile"], result["ready"]
    print(
        f"ready to step per variant: patched {r['median_ms']:.3f} ms median ({1e3 / r['median_ms']:.0f}/s), "
        f"compiled {c['median_ms']:.1f} ms median ({1e3 / c['median_ms']:.1f}/s): "
        f"{c['median_ms'] / r['median_ms']:.0f}x (best against best {c['best_ms'] / r['best_ms']:.0f}x); "
        f"of which apply {result['apply']['median_ms']:.3f} ms, variant {result['variant']['median_ms']:.3f} ms"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
