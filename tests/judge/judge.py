#!/usr/bin/env python3
"""The judge: real MuJoCo decides whether two MJCF files describe the same model.

Both files are compiled with ``mujoco.MjModel.from_xml_path`` and the compiled
models are compared field by field:

* every int attribute of MjModel (the sizes nq, nv, nbody, ngeom, nmeshvert, ...
  and the flg_* flags), but for the exclusions below;
* every numpy array attribute of MjModel (found with dir()): exact equality for
  integer/bool arrays, ``numpy.allclose(rtol=1e-9, atol=1e-12)`` for floats,
  reporting the array, the first differing index and both values;
* the custom text data (``text_data``, a bytes attribute, not an array) and
  the textures' content_type strings (kept in the ``paths`` buffer);
* every field of the option, visual (with its sub-structs) and statistic structs;
* names: for every object type that has names (one ``name_<type>adr`` array per
  type, read from the ``names`` buffer), B's names must equal
  ``[prefix + n if n else "" for n in names of A]``.  The world body (body 0)
  is always called "world" by MuJoCo and is never prefixed; the model name
  (<mujoco model=...>) must be equal, unprefixed.

A file that does not compile is a difference that quotes MuJoCo's error.

Library:  compare(path_a, path_b, prefix="") -> list[str]   ([] = equivalent)
CLI:      python tests/judge/judge.py A.xml B.xml [--prefix P]
          prints the differences, exits 1 if any (2 on bad usage).
Batch:    python tests/judge/judge.py --pairs FILE.tsv [--json] [--verbose]
          each non-blank line not starting with '#' is A<TAB>B[<TAB>PREFIX
          [<TAB>MODE]] (paths relative to the current directory; prefix may be
          empty or left out). MODE "same" (the default) compares as above;
          MODE "a-rejected" passes when this MuJoCo rejects A, and says so
          otherwise: a case written for another MuJoCo version, whose input
          has no meaning under this one, must really be rejected by it.  All pairs run in one process.  Prints one summary line per
          pair (with --json: one JSON object per line, keys a, b, prefix, ok,
          differences), then a final line "N passed, M failed"; exits 1 when
          any pair failed.
"""
from __future__ import annotations

import argparse
import functools
import json
import re
import sys
from pathlib import Path

import mujoco
import numpy as np

RTOL = 1e-9
ATOL = 1e-12

# How many differing names to spell out per object type (the rest are counted).
MAX_NAME_DIFFS_PER_TYPE = 5

# ---------------------------------------------------------------------------
# Exclusions: MjModel attributes that legitimately differ between two files
# describing the same model once files are moved/renamed or names prefixed.
# Everything not listed here is compared.
# ---------------------------------------------------------------------------
EXCLUDED_INTS = {
    # Size in bytes of the `names` buffer: grows with every prefix character.
    # (The names themselves are compared one by one, see compare_names.)
    "nnames": "length of the names buffer; names are compared one by one",
    # Size in bytes of the `paths` buffer (the asset file paths as the
    # compiler resolved them, absolute here): differs as soon as a model or
    # its assets live in another directory. The asset *contents* (mesh_vert,
    # tex_data, hfield_data, skin_*) are compared.
    "npaths": "length of the paths buffer (asset file names)",
    # Total size in bytes of the model buffer: includes nnames and npaths.
    "nbuffer": "total model buffer size, includes the names and paths buffers",
}

EXCLUDED_ARRAYS = {
    # Hash table from name to id: the slots depend on the hash of each name
    # string, so any prefix/rename shuffles it. Names are compared directly.
    "names_map": "hash table of names, depends on the name strings",
}
# Arrays excluded by pattern (see excluded_array()):
#   name_*adr  - offsets of each object's name in the `names` buffer: shift
#                with every prefix character. Names are compared directly.
#   *_pathadr  - offsets of each asset's file name in the `paths` buffer
#                (mesh, skin, hfield, texture): shift when files are moved.
#   tex_contenttypeadr - offset of each texture's content_type string, which
#                MuJoCo also stores in the `paths` buffer, after the file
#                names: shifts when files are moved. The content_type strings
#                themselves are compared (see PATHS_STRINGS).
_EXCLUDED_ARRAY_RE = re.compile(r"^(name_\w+adr|\w+_pathadr|tex_contenttypeadr)$")

# Strings stored in the `paths` buffer that are model content, not file
# locations: compared as strings (adr -1 = none = "").
PATHS_STRINGS = {"tex_contenttypeadr": "texture content_type"}

# Bytes attributes: `names` and `paths` are excluded (see above); `text_data`
# is compared (custom text is model content).
COMPARED_BYTES = ("text_data",)


def excluded_array(name: str) -> bool:
    return name in EXCLUDED_ARRAYS or bool(_EXCLUDED_ARRAY_RE.match(name))


# Readable label for each name_<key>adr array (MjModel's abbreviations).
_NAME_LABEL = {
    "jnt": "joint",
    "cam": "camera",
    "eq": "equality",
    "mat": "material",
    "tex": "texture",
}


class CompileError(Exception):
    pass


_warnings_silenced = False


def _silence_warnings() -> None:
    """MuJoCo writes warnings to MUJOCO_LOG.TXT in the cwd unless a handler is set."""
    global _warnings_silenced
    if not _warnings_silenced:
        mujoco.set_mju_user_warning(lambda _msg: None)
        _warnings_silenced = True


@functools.lru_cache(maxsize=16)
def _load_cached(path: str, _mtime_ns: int) -> mujoco.MjModel | CompileError:
    return _compile(path)


def _compile(path: str) -> mujoco.MjModel | CompileError:
    try:
        return mujoco.MjModel.from_xml_path(path)
    except Exception as e:  # ValueError from MuJoCo's parser/compiler
        msg = " ".join(l.strip() for l in str(e).splitlines() if l.strip())
        return CompileError(msg or type(e).__name__)


def load(path: str | Path, cache: bool = False) -> mujoco.MjModel:
    """Compile a file; raise CompileError on failure.

    cache=True (batch mode) reuses the model compiled from the same path with
    the same mtime. Only the file itself is checked, not what it includes: a
    caller that rewrites included files between compares must not cache.
    """
    _silence_warnings()
    p = Path(path).resolve()
    try:
        r = _load_cached(str(p), p.stat().st_mtime_ns) if cache else _compile(str(p))
    except OSError:
        r = _compile(str(p))  # unreadable: MuJoCo says what is wrong (not cached)
    if isinstance(r, CompileError):
        raise r
    return r


# ---------------------------------------------------------------------------
# value formatting / array comparison
# ---------------------------------------------------------------------------
def _fmt(v) -> str:
    if isinstance(v, (np.floating, float)):
        return repr(float(v))
    if isinstance(v, (np.integer, np.bool_)):
        return repr(v.item())
    return repr(v)


def _idx(ix: tuple[int, ...]) -> str:
    return "[" + ",".join(str(int(i)) for i in ix) + "]"


def diff_array(name: str, a: np.ndarray, b: np.ndarray) -> str | None:
    """One readable line for the first difference of two arrays, or None."""
    a = np.asarray(a)
    b = np.asarray(b)
    if a.shape != b.shape:
        return f"{name}: shape {a.shape} != {b.shape}"
    if a.size == 0:
        return None
    if np.issubdtype(a.dtype, np.floating) or np.issubdtype(b.dtype, np.floating):
        af = a.astype(np.float64)
        bf = b.astype(np.float64)
        if np.allclose(af, bf, rtol=RTOL, atol=ATOL, equal_nan=True):
            return None
        bad = ~np.isclose(af, bf, rtol=RTOL, atol=ATOL, equal_nan=True)
    else:
        if np.array_equal(a, b):
            return None
        bad = a != b
    where = np.argwhere(bad)
    first = tuple(where[0])
    more = f" ({len(where) - 1} more)" if len(where) > 1 else ""
    return f"{name}{_idx(first)}: {_fmt(a[first])} != {_fmt(b[first])}{more}"


def diff_value(name: str, a, b) -> str | None:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return diff_array(name, a, b)
    if isinstance(a, float) or isinstance(b, float):
        if np.isclose(a, b, rtol=RTOL, atol=ATOL, equal_nan=True):
            return None
    elif a == b:
        return None
    return f"{name}: {_fmt(a)} != {_fmt(b)}"


def _fields(obj) -> list[str]:
    return sorted(
        n for n in dir(obj) if not n.startswith("_") and not callable(getattr(obj, n))
    )


def diff_struct(label: str, a, b) -> list[str]:
    """All fields of an MjOption/MjVisual/MjStatistic, recursing into sub-structs."""
    out: list[str] = []
    for f in _fields(a):
        va, vb = getattr(a, f), getattr(b, f)
        if isinstance(va, (int, float, np.ndarray, bool)):
            d = diff_value(f"{label}.{f}", va, vb)
            if d:
                out.append(d)
        else:
            out.extend(diff_struct(f"{label}.{f}", va, vb))
    return out


# ---------------------------------------------------------------------------
# names
# ---------------------------------------------------------------------------
def _name_arrays(m: mujoco.MjModel) -> list[str]:
    return sorted(n for n in dir(m) if n.startswith("name_") and n.endswith("adr"))


def _strings(buf: bytes, adrs) -> list[str]:
    """NUL-terminated strings of a names/paths buffer at the given offsets (-1: "")."""
    out = []
    for adr in adrs:
        adr = int(adr)
        if adr < 0:
            out.append("")
            continue
        end = buf.index(b"\0", adr)
        out.append(buf[adr:end].decode("utf-8", "replace"))
    return out


def names_of(m: mujoco.MjModel, adr_attr: str) -> list[str]:
    return _strings(m.names, getattr(m, adr_attr))


def model_name(m: mujoco.MjModel) -> str:
    """<mujoco model="..."> (MuJoCo's default: "MuJoCo Model"): first string of `names`."""
    return _strings(m.names, [0])[0]


def _label(adr_attr: str) -> str:
    key = adr_attr[len("name_") : -len("adr")]
    return _NAME_LABEL.get(key, key)


def compare_names(a: mujoco.MjModel, b: mujoco.MjModel, prefix: str) -> list[str]:
    out: list[str] = []
    # The model name is never prefixed.
    if model_name(a) != model_name(b):
        out.append(f"model name: {model_name(a)!r} != {model_name(b)!r}")
    for attr in _name_arrays(a):
        label = _label(attr)
        na, nb = names_of(a, attr), names_of(b, attr)
        want = [prefix + n if n else "" for n in na]
        if label == "body" and na and na[0] == "world":
            want[0] = "world"  # MuJoCo names the world body; never prefixed
        if len(nb) != len(want):
            out.append(f"{label} names: count {len(want)} != {len(nb)}")
            continue
        bad = [i for i, (w, g) in enumerate(zip(want, nb)) if w != g]
        for i in bad[:MAX_NAME_DIFFS_PER_TYPE]:
            out.append(f"{label} name {i}: {want[i]!r} != {nb[i]!r}")
        if len(bad) > MAX_NAME_DIFFS_PER_TYPE:
            out.append(f"{label} names: {len(bad) - MAX_NAME_DIFFS_PER_TYPE} more differ")
    return out


# ---------------------------------------------------------------------------
# models
# ---------------------------------------------------------------------------
def compare_models(a: mujoco.MjModel, b: mujoco.MjModel, prefix: str = "") -> list[str]:
    out: list[str] = []
    ints, arrays = [], []
    for n in dir(a):
        if n.startswith("_"):
            continue
        v = getattr(a, n)
        if isinstance(v, np.ndarray):
            if not excluded_array(n):
                arrays.append(n)
        elif isinstance(v, int) and not isinstance(v, bool):
            if n not in EXCLUDED_INTS:
                ints.append(n)

    # Sizes first: when one differs, the arrays it sizes differ in shape too.
    for n in ints:
        d = diff_value(n, getattr(a, n), getattr(b, n))
        if d:
            out.append(d)
    for n in arrays:
        d = diff_array(n, getattr(a, n), getattr(b, n))
        if d:
            out.append(d)
    for n in COMPARED_BYTES:
        va, vb = getattr(a, n), getattr(b, n)
        if va != vb:
            i = next((k for k, (x, y) in enumerate(zip(va, vb)) if x != y), min(len(va), len(vb)))
            out.append(f"{n}[{i}]: {va[i:i + 20]!r} != {vb[i:i + 20]!r} (lengths {len(va)}, {len(vb)})")
    for n, label in PATHS_STRINGS.items():
        if not hasattr(a, n):  # MuJoCo before 3.2.7 (robosuite's 3.9.0 venv) has none
            continue
        sa, sb = _strings(a.paths, getattr(a, n)), _strings(b.paths, getattr(b, n))
        if len(sa) == len(sb):  # else the size difference is already reported
            for i, (x, y) in enumerate(zip(sa, sb)):
                if x != y:
                    out.append(f"{label} {i}: {x!r} != {y!r}")
    out.extend(diff_struct("opt", a.opt, b.opt))
    out.extend(diff_struct("vis", a.vis, b.vis))
    out.extend(diff_struct("stat", a.stat, b.stat))
    out.extend(compare_names(a, b, prefix))
    return out


def compare(path_a: str | Path, path_b: str | Path, prefix: str = "",
            cache: bool = False) -> list[str]:
    """Differences between the models compiled from two MJCF files ([] = equivalent).

    B's names must be A's with `prefix` in front. cache: see load().
    """
    out: list[str] = []
    models = []
    for tag, p in (("A", path_a), ("B", path_b)):
        try:
            models.append(load(p, cache))
        except CompileError as e:
            out.append(f"{tag} ({p}) does not compile: {e}")
    if out:
        return out
    return compare_models(models[0], models[1], prefix)


# ---------------------------------------------------------------------------
# CLI
# ---------------------------------------------------------------------------
MODES = ("same", "a-rejected")


def _read_pairs(path: str) -> list[tuple[str, str, str, str]]:
    pairs = []
    for lineno, line in enumerate(Path(path).read_text().splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        cols = line.split("\t")
        if len(cols) < 2 or len(cols) > 4 or not cols[0] or not cols[1] \
                or (len(cols) == 4 and cols[3] not in MODES):
            raise SystemExit(f"{path}:{lineno}: expected A<TAB>B[<TAB>PREFIX[<TAB>MODE]] "
                             f"with MODE one of {MODES}, got {line!r}")
        cols += [""] * (3 - len(cols)) + (["same"] if len(cols) < 4 else [])
        pairs.append((cols[0], cols[1], cols[2], cols[3]))
    return pairs


def rejected(path_a: str | Path) -> list[str]:
    """[] when this MuJoCo rejects A, else the difference to report."""
    try:
        load(path_a, True)
    except CompileError:
        return []
    return [f"A ({path_a}) compiles under MuJoCo {mujoco.__version__}, "
            "but the case says this version rejects it"]


def _batch(pairs_file: str, as_json: bool, verbose: bool) -> int:
    passed = failed = 0
    for a, b, prefix, mode in _read_pairs(pairs_file):
        if mode == "a-rejected":
            diffs = rejected(a)
        else:
            diffs = compare(a, b, prefix, cache=True)  # an A often recurs across pairs
        ok = not diffs
        passed += ok
        failed += not ok
        if as_json:
            print(json.dumps({"a": a, "b": b, "prefix": prefix, "mode": mode, "ok": ok,
                              "differences": diffs}))
        else:
            what = f"{a} {b}" + (f" (prefix {prefix!r})" if prefix else "") \
                + (f" [{mode}]" if mode != "same" else "")
            if ok:
                print(f"ok   {what}")
            else:
                print(f"FAIL {what}: {len(diffs)} difference(s): {diffs[0]}"
                      + (" ..." if len(diffs) > 1 else ""))
                if verbose:
                    for d in diffs:
                        print(f"    {d}")
        sys.stdout.flush()
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", nargs="?", help="reference MJCF file")
    ap.add_argument("b", nargs="?", help="MJCF file to check against A")
    ap.add_argument("--prefix", default="", help="prefix B's names must carry")
    ap.add_argument("--pairs", metavar="FILE.tsv", help="batch: A<TAB>B<TAB>PREFIX per line")
    ap.add_argument("--json", action="store_true", help="batch: one JSON object per pair")
    ap.add_argument("--verbose", "-v", action="store_true", help="batch: list every difference")
    args = ap.parse_args(argv)

    if args.pairs:
        if args.a or args.b:
            ap.error("give either A B or --pairs, not both")
        return _batch(args.pairs, args.json, args.verbose)
    if not (args.a and args.b):
        ap.error("need A and B (or --pairs FILE.tsv)")
    diffs = compare(args.a, args.b, args.prefix)
    if args.json:
        print(json.dumps({"a": args.a, "b": args.b, "prefix": args.prefix,
                          "ok": not diffs, "differences": diffs}))
    else:
        for d in diffs:
            print(d)
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main())
