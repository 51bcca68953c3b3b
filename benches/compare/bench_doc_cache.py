#!/usr/bin/env python3
"""Same-run comparison: a robosuite-sized document as a compiled model, compiled by MuJoCo
against a DocumentCache hit (the cached model of the document's structure, patched).

The documents are the variants of SCENE (default benches/scenes/lift5_fixed.toml:
robosuite's table arena, Panda with gripper and mount, five objects; random poses,
colours, frictions, link masses and light) taken as plain documents
(``scene.variant(i).document``): the cache is told nothing, it reads each one. They are
made before timing. In one process:

  compile   mujoco.MjModel.from_xml_string(doc.to_xml()): what a training loop pays per
            new document today (mesh and texture files decoded once per process by
            MuJoCo's own asset cache: the first compile is far slower, see `first`);
  split     doc._split(): the structure key and the patch's numbers, read in Rust;
  hit       cache.model(doc) for a document of a cached structure: split, the snapshot
            written back, the patch written, mj_setConst and the compiler's statistics;
  text_hit  cache.model(xml) for the same document as MJCF text (read first);
  into_hit  cache.model(doc, into=model) with a model the caller holds and hands back
            (what a robosuite hard reset that keeps its simulation asks);
  copy      copy.copy(model): what returning a copy per call would add (why the cache
            writes back what it restores instead, see docs/compiled.md).

Best and median of RUNS per item (compile: COMPILES), after one warm-up; every model of
the sample is checked against compiling its XML (the judge, then bit for bit) before
timing. Prints one JSON line, then the ratio.

Usage: python benches/compare/bench_doc_cache.py [--scene S] [--runs N] [--compiles K]
(run with .cache/venv's Python for MuJoCo 3.17.0, .cache/venv-mj4's for 4.0.0).
"""
from __future__ import annotations

import os

# Misses are timed as compiles: no model store unless the caller sets one.
os.environ.setdefault("MJCF_FORGE_STORE", "off")

import argparse
import copy
import json
import statistics
import sys
import time
from pathlib import Path

import mujoco
import numpy as np

import mjcf_forge
from timing import each_ms, summary  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]






def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default=str(ROOT / "benches" / "scenes" / "lift5_fixed.toml"))
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--compiles", type=int, default=10)
    args = ap.parse_args()

    sys.path.insert(0, str(ROOT / "tests" / "judge"))
    import judge

    scene = mjcf_forge.Scene.load(args.scene)
    n = max(args.runs, args.compiles) + 1
    docs = [scene.variant(i).document for i in range(n)]
    xmls = [d.to_xml() for d in docs]
    keys = {d.structure_key for d in docs}

    t = time.perf_counter()
    first = mujoco.MjModel.from_xml_string(xmls[0])
    first_ms = (time.perf_counter() - t) * 1e3

    cache = mjcf_forge.DocumentCache(max_models=len(keys) + 1)
    for i in range(0, n, max(1, n // 8)):
        ref = mujoco.MjModel.from_xml_string(xmls[i])
        got = cache.model(docs[i])
        diffs = judge.compare_models(ref, got)
        floats = [
            a for a in dir(ref)
            if isinstance(getattr(ref, a, None), np.ndarray)
            and not np.array_equal(getattr(ref, a), getattr(got, a), equal_nan=True)
        ]
        if diffs or floats:
            print(f"document {i} differs: {diffs[:3]} {floats[:3]}", file=sys.stderr)
            return 1

    compile_ms = each_ms(lambda i: mujoco.MjModel.from_xml_string(xmls[i]), args.compiles)
    split_ms = each_ms(lambda i: docs[i]._split(), args.runs)
    hit_ms = each_ms(lambda i: cache.model(docs[i]), args.runs)
    text_ms = each_ms(lambda i: cache.model(xmls[i]), args.runs)
    model = cache.model(docs[0])
    into_ms = each_ms(lambda i: cache.model(docs[i], into=model), args.runs)
    copy_ms = each_ms(lambda i: copy.copy(model), min(args.runs, 20))
    out = {
        "scene": str(Path(args.scene).relative_to(ROOT)) if args.scene.startswith(str(ROOT)) else args.scene,
        "mujoco": mujoco.__version__,
        "structures": len(keys),
        "nbody": model.nbody,
        "ngeom": model.ngeom,
        "model_mb": round(model.nbuffer / 1e6, 1),
        "patch_entries": len(docs[0].patch),
        "first_compile_ms": round(first_ms, 1),
        "compile": summary(compile_ms, 4),
        "split": summary(split_ms, 4),
        "hit": summary(hit_ms, 4),
        "text_hit": summary(text_ms, 4),
        "into_hit": summary(into_ms, 4),
        "copy": summary(copy_ms, 4),
        "compiles": cache.compiles,
        "patches": cache.patches,
    }
    print(json.dumps(out))
    ratio = statistics.median(compile_ms) / statistics.median(hit_ms)
    print(
        f"compile {statistics.median(compile_ms):.1f} ms, hit {statistics.median(hit_ms):.3f} ms "
        f"(median): a hit is {ratio:.0f}x faster; from text {statistics.median(text_ms):.3f} ms"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
