#!/usr/bin/env python3
"""Judges the wider URDF corpus (.cache/urdf-wide/corpus/, made by scripts/urdf_wide.sh)
under the installed MuJoCo (run it with each venv's Python).

For every URDF file (shipped, or a xacro expansion):
- as shipped, where MuJoCo's importer reads it: ours (``Document.load``, ``package://``
  resolved) against MuJoCo's import;
- prepared for MuJoCo (scripts/list_urdf.py's ``prepare``: its meshes beside a copy that
  says ``<compiler strippath="true">``), where MuJoCo reads the copy: ours read from the
  copy, and ours read from the file as shipped, each against MuJoCo's import of the copy.

Every array of the compiled models is compared (tests/judge/judge.py). Writes
.cache/urdf-wide/result-<version>.json (each file's outcome) and prints the counts and
every exception.
"""
from __future__ import annotations

import concurrent.futures as cf
import json
import os
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
sys.path.insert(0, str(ROOT / "tests" / "judge"))

import list_urdf  # noqa: E402

WIDE = ROOT / ".cache" / "urdf-wide"
CORPUS = WIDE / "corpus"


def judged(path: str) -> dict:
    import judge
    import mujoco

    from mjcf_forge import Document, MjcfError

    import warnings

    said: list[str] = []
    mujoco.set_mju_user_warning(said.append)
    urdf = Path(path)
    corpus = CORPUS / urdf.relative_to(CORPUS).parts[0]
    out: dict = {"file": str(urdf.relative_to(CORPUS))}

    def printing(load):
        """``load()``, with the ``WARNING: ...`` lines MuJoCo's URDF importer prints to
        standard error itself (a repeated geom name) put before ``said``."""
        import ctypes
        import tempfile

        sys.stderr.flush()
        saved = os.dup(2)
        with tempfile.TemporaryFile() as printed:
            os.dup2(printed.fileno(), 2)
            try:
                return load()
            finally:
                ctypes.CDLL(None).fflush(None)  # MuJoCo's printf, buffered
                os.dup2(saved, 2)
                os.close(saved)
                printed.seek(0)
                lines = printed.read().decode(errors="replace").splitlines()
                said[:0] = [x.removeprefix("WARNING: ") for x in lines if x.startswith("WARNING: ")]

    def theirs(f: Path):
        try:
            return printing(lambda: mujoco.MjModel.from_xml_path(str(f))), None
        except Exception as e:  # MuJoCo raises ValueError
            return None, str(e).strip().splitlines()[0][:200]

    def ours(f: Path, reference) -> object:
        try:
            with warnings.catch_warnings():  # judged apart, below
                warnings.simplefilter("ignore", UserWarning)
                model = mujoco.MjModel.from_xml_string(Document.load(f).to_xml())
        except MjcfError as e:
            return "refused: " + str(e).splitlines()[0][:300]
        except Exception as e:
            return "ours does not compile: " + str(e).strip().splitlines()[0][:200]
        return judge.compare_models(reference, model)[:3] or "equal"

    said.clear()
    reference, out["mujoco_shipped"] = theirs(urdf)
    if reference is not None:
        out["shipped"] = ours(urdf, reference)
        # MuJoCo's importer warnings (its compiler's, given for our output too, aside)
        # against the UserWarnings of our load, messages in order.
        importer = list(said)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                doc = Document.load(urdf)
                said.clear()
                printing(lambda: mujoco.MjModel.from_xml_string(doc.to_xml()))
                for w in said:
                    if w in importer:
                        importer.remove(w)
            except Exception:  # judged above
                pass
        mine = [str(c.message).split(": ", 1)[-1] for c in caught if c.category is UserWarning]
        out["warned"] = len(mine)
        if mine != importer:
            out["warnings"] = f"ours {mine}, MuJoCo's {importer}"
    copy, why = list_urdf.prepare(urdf, corpus)
    if copy is None:
        out["prepared"] = "not prepared: " + why
        return out
    reference, error = theirs(copy)
    if reference is None:
        out["prepared"] = "MuJoCo rejects the prepared copy: " + error
        return out
    out["prepared"] = "ok"
    out["prepared_read_as_prepared"] = ours(copy, reference)
    out["prepared_read_as_shipped"] = ours(urdf, reference)
    return out


def main() -> int:
    import mujoco

    version = mujoco.__version__
    if not CORPUS.is_dir():
        print(f"urdf_wide: {CORPUS} missing: run scripts/urdf_wide.sh", file=sys.stderr)
        return 1
    list_urdf.URDF = CORPUS
    list_urdf.PREPARED = WIDE / f"prepared-{version}"
    files = sorted(str(f) for f in CORPUS.rglob("*.urdf"))
    with cf.ProcessPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        results = list(pool.map(judged, files, chunksize=1))
    (WIDE / f"result-{version}.json").write_text(json.dumps(results, indent=1))
    packages = Counter(r["file"].split("/")[0] for r in results if r.get("prepared") == "ok")
    print(
        f"urdf_wide: MuJoCo {version}: {len(results)} URDF files "
        f"({sum(r['file'].endswith('.xacro.urdf') for r in results)} xacro expansions) "
        f"from {len({r['file'].split('/')[0] for r in results})} wheels; MuJoCo reads "
        f"{sum(r['mujoco_shipped'] is None for r in results)} as shipped and "
        f"{len([r for r in results if r.get('prepared') == 'ok'])} prepared copies "
        f"(from {len(packages)} wheels)"
    )
    status = 0
    for key in ("shipped", "prepared_read_as_prepared", "prepared_read_as_shipped"):
        have = [r for r in results if key in r]
        equal = [r for r in have if r[key] == "equal"]
        print(f"urdf_wide: MuJoCo {version}: {key}: {len(equal)} of {len(have)} equal MuJoCo's import")
        for r in have:
            if r[key] != "equal":
                status = 1
                print(f"  {r['file']}: {r[key]}")
    warned = [r for r in results if r.get("warned")]
    print(f"urdf_wide: MuJoCo {version}: importer warnings: {len(warned)} files warned, "
          f"{sum(r['warned'] for r in warned)} warnings, every one as MuJoCo's"
          if not any("warnings" in r for r in results) else "urdf_wide: warnings differ:")
    for r in results:
        if "warnings" in r:
            status = 1
            print(f"  {r['file']}: {r['warnings']}")
    reasons = Counter(r["prepared"].split(":")[0] + ": " + r["prepared"].split(":")[1].split("'")[0].strip()
                      for r in results if r.get("prepared") != "ok")
    for reason, n in reasons.most_common():
        print(f"urdf_wide: not judged prepared: {n} x {reason}")
    return status


if __name__ == "__main__":
    sys.exit(main())
