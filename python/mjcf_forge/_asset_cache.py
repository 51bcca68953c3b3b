"""MuJoCo's asset cache, as stock's process would hold it: what the last loaded XML model
(``mj_saveLastXML``, robosuite's ``get_xml()``) depends on besides the text loaded.

MuJoCo keeps one asset cache per process (500 MB): a mesh read from its file by any
compile is kept, and a later compile of a model naming the same file takes it from there.
On some MuJoCo versions (3.3.1 and 3.9.0 among them, not 3.17.0 or 4.0.0) where a mesh
came from is written: one read from its file gets a ``content_type`` in MuJoCo's parsed
model, one taken from the cache does not, and ``mj_saveLastXML`` writes what the parsed
model holds. So the text stock saves depends on which of the model's mesh files an earlier
compile had read. (Textures and height fields are read from their files by every compile
of those versions, and written alike either way: only mesh files are kept here.)

The package compiles otherwise than stock (a structure once, a model loaded from the model
store and compiled by no one), so its process's cache can hold other files than stock's.
This module keeps both: the mesh files stock's compiles would have read by now (every load
stock made, including those the model cache served instead) and those this process's
MuJoCo has read (every compile and load here). Before the last loaded XML model is loaded
again to give stock's text (``_last_xml``), :func:`match` makes this process's cache hold
the model's files as stock's did at that load: it compiles the model first (without
touching the slot) where stock's had them all, or empties the cache where stock's had none
of them. Where stock's held some and not others, no compile here can give that state, and
:func:`match` raises. Both records ignore the cache's size: past 500 MB of assets MuJoCo
stops keeping new ones, in either process, in its own order (docs/compiled.md).
"""

from __future__ import annotations

import glob
import os
import tempfile
import threading
from typing import Any, Callable, Iterable, Optional

_LOCK = threading.Lock()
_STOCK: set = set()  # files stock's process has read by now
_OURS: set = set()  # files this process's MuJoCo has read (since the cache was emptied)
_FILES: dict = {}  # text -> its files, the last few texts
_WRITES_WHERE: list = []  # [bool]: whether this MuJoCo writes where an asset came from


def files_of(text: str) -> frozenset:
    """The mesh files a model written as ``text`` reads (``Document.files("mesh")``); none
    where it cannot be read (MuJoCo then refuses it, and caches nothing)."""
    with _LOCK:
        files = _FILES.get(text)
    if files is None:
        from ._mjcf_forge import Document

        try:
            files = frozenset(Document.from_string(text).files("mesh"))
        except Exception:  # noqa: BLE001 - MuJoCo's own load says what is wrong
            files = frozenset()
        with _LOCK:
            if len(_FILES) >= 8:
                _FILES.pop(next(iter(_FILES)))
            _FILES[text] = files
    return files


def files_of_path(path: Any) -> frozenset:
    """The mesh files the model file ``path`` reads (see :func:`files_of`)."""
    from ._mjcf_forge import Document

    try:
        return frozenset(Document.load(os.fspath(path)).files("mesh"))
    except Exception:  # noqa: BLE001 - as files_of
        return frozenset()


def _reads(record: set, files: Iterable[str]) -> frozenset:
    files = frozenset(files)
    with _LOCK:
        cold = files - record
        record.update(files)
    return cold


def stock_reads(files: Iterable[str]) -> frozenset:
    """Stock's process compiles a model reading ``files`` now: returns those it reads from
    disk (no earlier compile read them), and records them read."""
    return _reads(_STOCK, files)


def our_reads(files: Iterable[str]) -> frozenset:
    """This process's MuJoCo compiles a model reading ``files`` now: returns those it reads
    from disk, and records them read."""
    return _reads(_OURS, files)


def both_read(files: Iterable[str]) -> tuple:
    """A load both processes make (one by the user's code, not served by the cache):
    ``(stock's cold files, ours)``."""
    return stock_reads(files), our_reads(files)


def match(files: frozenset, stock_cold: frozenset, warm: Callable[[], Any]) -> None:
    """Makes the next compile here of a model reading ``files`` read from disk exactly
    ``stock_cold`` (the files stock's compile read from disk), where this MuJoCo writes
    where an asset came from: ``warm()`` compiles the model without touching the last
    loaded XML model, where stock's cache held every file; the cache is emptied where it
    held none.

    Raises:
        RuntimeError: stock's cache held some of the files and not others, and this
            process's does not hold just those
    """
    with _LOCK:
        ours_cold = files - _OURS
    if ours_cold == stock_cold or not writes_where_assets_came_from():
        return
    if not stock_cold:
        warm()
        our_reads(files)
    elif stock_cold == files:
        empty()
    else:
        raise RuntimeError(
            f"MuJoCo's asset cache held {len(files) - len(stock_cold)} of this model's "
            f"{len(files)} mesh files in stock's process when it was loaded (the others, such as "
            f"{sorted(stock_cold)[0]!r}, were read from disk), and this MuJoCo writes which "
            "into the XML; this process's cache cannot be brought to that state"
        )


def empty() -> None:
    """Empties MuJoCo's asset cache (every later compile reads its files from disk)."""
    import mujoco

    if hasattr(mujoco, "mj_clearCache") and hasattr(mujoco, "mj_getCache"):
        mujoco.mj_clearCache(mujoco.mj_getCache())
    else:
        # Before 3.4 the bindings do not reach the cache: MuJoCo's exported C functions do.
        # A smaller bound drops every entry over it; then the default bound again.
        lib = _library(mujoco)
        import ctypes

        lib.mj_globalCache.restype = ctypes.c_void_p
        lib.mj_setCacheSize.argtypes = [ctypes.c_void_p, ctypes.c_size_t]
        cache = lib.mj_globalCache()
        lib.mj_setCacheSize(cache, 0)
        lib.mj_setCacheSize(cache, 500 << 20)
    with _LOCK:
        _OURS.clear()


def _library(mujoco: Any) -> Any:
    import ctypes

    folder = os.path.dirname(mujoco.__file__)
    for pattern in ("libmujoco.so*", "libmujoco*.dylib", "mujoco.dll"):
        found = sorted(glob.glob(os.path.join(folder, pattern)))
        if found:
            return ctypes.CDLL(found[0])
    raise RuntimeError(f"MuJoCo's library is not in {folder}")


def writes_where_assets_came_from() -> bool:
    """Whether this MuJoCo's ``mj_saveLastXML`` writes a ``content_type`` for a mesh read
    from its file and none for one taken from the cache: found once, by loading a model of
    one mesh twice. It replaces MuJoCo's last loaded XML model: called only right before a
    load of it."""
    if _WRITES_WHERE:
        return _WRITES_WHERE[0]
    import mujoco

    from . import _last_xml

    load = _last_xml._ORIGINAL.get("from_xml_string", mujoco.MjModel.from_xml_string)
    save = _last_xml._ORIGINAL.get("mj_saveLastXML", mujoco.mj_saveLastXML)
    with tempfile.TemporaryDirectory() as folder:
        mesh = os.path.join(folder, "probe.obj")
        with open(mesh, "w") as f:
            f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
        xml = f'<mujoco><asset><mesh name="probe" file="{mesh}"/></asset></mujoco>'
        written = []
        for _ in range(2):  # the first reads the file, the second takes it from the cache
            model = load(xml)
            out = os.path.join(folder, "probe.xml")
            save(out, model)
            with open(out) as f:
                written.append("content_type" in f.read())
    # MuJoCo's slot now holds the probe: known to hold nothing of anyone's.
    _last_xml.forget_held()
    _WRITES_WHERE.append(written[0] != written[1])
    return _WRITES_WHERE[0]


def state() -> Optional[dict]:
    """The two records' sizes, and whether this MuJoCo writes where assets came from
    (``None`` until found), for tests."""
    with _LOCK:
        return {
            "stock": len(_STOCK), "ours": len(_OURS),
            "writes": _WRITES_WHERE[0] if _WRITES_WHERE else None,
        }
