#!/usr/bin/env python3
"""Same-run speed baseline: robosuite's own MJCF handling.

Times ``robosuite.models.base.MujocoXML(path).get_xml()`` (parse, inline the
default classes, resolve asset paths, serialize) over every robosuite model in
.cache/corpus/models.txt, best of N runs, and prints JSON on stdout:

  files, bytes (sum of the input XML file sizes), runs, seconds (best run),
  seconds_all, mb_per_s (= bytes / 1e6 / seconds), failed (files MujocoXML
  rejects; they are left out of files/bytes/seconds), versions.

Setup: scripts/setup_robosuite.sh, then
  .cache/venv-robosuite/bin/python benches/compare/bench_robosuite.py [--runs N]

--import-mode stub (default): robosuite's code comes from the unpacked wheel
  .cache/corpus/robosuite-1.5.2; only robosuite/__init__.py is skipped (it
  imports every environment and with them numba, scipy, opencv, mink, ...).
  MujocoXML, mjcf_utils and macros run unchanged.
--import-mode installed: plain `import robosuite.models.base` from a full
  `pip install robosuite==1.5.2`.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import platform
import sys
import time
from pathlib import Path

from bench_robosuite_scene import import_robosuite_package

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT / ".cache" / "corpus"
MODELS_TXT = CORPUS / "models.txt"


def import_mujoco_xml(mode: str):
    """robosuite.models.base.MujocoXML; robosuite's import-time log lines go to stderr."""
    with contextlib.redirect_stdout(sys.stderr):
        if mode == "stub":
            import_robosuite_package()
        import robosuite  # noqa: F401
        import robosuite.models.base as base
    return base.MujocoXML, getattr(robosuite, "__version__", "?"), base.__file__


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=20, help="best of this many runs (default 20)")
    ap.add_argument("--import-mode", choices=("stub", "installed"), default="stub")
    args = ap.parse_args()

    if not MODELS_TXT.exists():
        raise SystemExit("bench_robosuite: no .cache/corpus/models.txt: run scripts/setup.sh")
    rel = [l for l in MODELS_TXT.read_text().splitlines() if "/robosuite-" in l]
    paths = [str(ROOT / p) for p in rel]

    MujocoXML, rs_version, rs_file = import_mujoco_xml(args.import_mode)

    # One untimed pass: finds the files MujocoXML rejects, and warms caches.
    ok, failed = [], []
    for p, r in zip(paths, rel):
        try:
            MujocoXML(p).get_xml()
            ok.append(p)
        except Exception as e:
            failed.append({"path": r, "error": f"{type(e).__name__}: {e}"})
    total_bytes = sum(os.path.getsize(p) for p in ok)

    times = []
    out_bytes = 0
    for _ in range(args.runs):
        t0 = time.perf_counter()
        n = 0
        for p in ok:
            n += len(MujocoXML(p).get_xml())
        times.append(time.perf_counter() - t0)
        out_bytes = n
    best = min(times)

    import numpy

    print(json.dumps({
        "bench": "robosuite.models.base.MujocoXML(path).get_xml()",
        "files": len(ok),
        "bytes": total_bytes,
        "output_chars": out_bytes,
        "runs": args.runs,
        "seconds": round(best, 6),
        "seconds_all": [round(t, 6) for t in times],
        "mb_per_s": round(total_bytes / 1e6 / best, 3),
        "failed": failed,
        "import_mode": args.import_mode,
        "robosuite": rs_version,
        "robosuite_file": os.path.relpath(rs_file, ROOT),
        "python": platform.python_version(),
        "numpy": numpy.__version__,
    }, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
