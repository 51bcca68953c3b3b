#!/usr/bin/env python3
"""Where a scene's worlds in MuJoCo Warp part from CPU MuJoCo, measured.

For SCENE's variants 0..WORLDS-1, after STEPS steps, the largest distance (per axis) of any
placed body between:

  superset-vs-alone   a world of the superset batch (WorldBatch.to_mjwarp) and the same
                      variant's own model alone in MuJoCo Warp (the superset's claim);
  alone-vs-cpu        the variant's own model in MuJoCo Warp and on CPU MuJoCo (what
                      Warp's float32 solve differs by, with no superset involved);
  superset-vs-cpu     the superset world and CPU MuJoCo.

--option NAME=VALUE (repeatable) sets a model.opt value on every model (Warp and CPU alike)
before building them (e.g. iterations=100 tolerance=1e-12 ls_iterations=50 cone=1
impratio=10), to see whether a solver setting brings Warp to CPU.

Usage (in .cache/venv-sim):
  python benches/compare/sim_gap.py [--scene benches/scenes/lift5.toml] [--worlds 8] [--steps 500]
                            [--option iterations=100 ...]
Prints one JSON line.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
os.environ.setdefault("WARP_CACHE_PATH", str(ROOT / ".cache" / "warp-kernels"))

import mujoco  # noqa: E402
import mujoco_warp as mjw  # noqa: E402
import warp as wp  # noqa: E402

import mjcf_forge  # noqa: E402
from mjcf_forge.batch import WorldBatch  # noqa: E402


def set_options(model, options: dict[str, float]) -> None:
    for name, value in options.items():
        current = getattr(model.opt, name)
        setattr(model.opt, name, type(current)(value))


def warp_tolerance(m, tolerance: float | None) -> None:
    """put_model raises opt.tolerance to at least 1e-6 for float32; set it back."""
    if tolerance is not None:
        m.opt.tolerance.fill_(tolerance)


def warp_run(model, nworld: int, steps: int, tolerance: float | None = None, **make_data) -> np.ndarray:
    m = mjw.put_model(model)
    warp_tolerance(m, tolerance)
    d = mjw.make_data(model, nworld=nworld, **make_data)
    mjw.reset_data(m, d)
    for _ in range(steps):
        mjw.step(m, d)
    wp.synchronize()
    return d.xpos.numpy().astype(np.float64)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default=str(ROOT / "benches" / "scenes" / "lift5.toml"))
    ap.add_argument("--worlds", type=int, default=8)
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--option", action="append", default=[])
    ap.add_argument("--warp-tolerance", type=float, default=None,
                    help="opt.tolerance in Warp after put_model (which raises it to 1e-6)")
    ap.add_argument("--nconmax", type=int, default=256)
    ap.add_argument("--njmax", type=int, default=1024)
    args = ap.parse_args()
    wp.config.quiet = True
    options = {k: float(v) for k, v in (o.split("=") for o in args.option)}

    scene = mjcf_forge.Scene.load(args.scene)
    t0 = time.perf_counter()
    batch = WorldBatch(scene, range(args.worlds))
    set_options(batch.model, options)
    m, d = batch.to_mjwarp(nconmax=args.nconmax, njmax=args.njmax)
    warp_tolerance(m, args.warp_tolerance)
    mjw.reset_data(m, d)
    most_contacts = most_rows = 0
    for k in range(args.steps):
        mjw.step(m, d)
        if k % 10 == 9:
            n = min(int(d.nacon.numpy()[0]), d.contact.worldid.shape[0])
            per_world = np.bincount(d.contact.worldid.numpy()[:n], minlength=args.worlds)
            most_contacts = max(most_contacts, int(per_world.max()))
            most_rows = max(most_rows, int(d.nefc.numpy().max()))
    wp.synchronize()
    overflow = int(np.bitwise_or.reduce(d.overflow.numpy()))
    xs = d.xpos.numpy().astype(np.float64)
    out = {"scene": Path(args.scene).stem, "worlds": args.worlds, "steps": args.steps,
           "options": options, "warp_tolerance": float(m.opt.tolerance.numpy()[0]), "most_contacts_per_world": most_contacts,
           "most_rows_per_world": most_rows, "overflow": overflow, "per_world": []}
    for w in range(args.worlds):
        v = scene.variant(w)
        own = mujoco.MjModel.from_xml_string(v.xml)
        set_options(own, options)
        alone = warp_run(own, 1, args.steps, args.warp_tolerance, nconmax=args.nconmax, njmax=args.njmax)[0]
        data = mujoco.MjData(own)
        for _ in range(args.steps):
            mujoco.mj_step(own, data)
        tags = batch.superset.names(w)
        row = {"variant": w, "superset_vs_alone": 0.0, "alone_vs_cpu": 0.0, "superset_vs_cpu": 0.0}
        for o in v.params["objects"]:
            body = o["body"]
            name = next((t + body for p, t in tags if body.startswith(p)), body)
            s = xs[w, batch.model.body(name).id]
            a = alone[own.body(body).id]
            c = data.body(body).xpos
            for key, x, y in (("superset_vs_alone", s, a), ("alone_vs_cpu", a, c), ("superset_vs_cpu", s, c)):
                row[key] = max(row[key], float(np.abs(x - y).max()))
        out["per_world"].append(row)
    for key in ("superset_vs_alone", "alone_vs_cpu", "superset_vs_cpu"):
        out[key] = max(r[key] for r in out["per_world"])
    out["seconds"] = round(time.perf_counter() - t0, 1)
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
