"""MuJoCo's last loaded XML model, as stock leaves it, whatever the package compiles.

MuJoCo keeps one parsed model per process: every ``mj_loadXML`` (the Python bindings'
``MjModel.from_xml_string`` and ``MjModel.from_xml_path``) replaces it, and
``mj_saveLastXML(filename, m)`` writes it out with ``m``'s values copied back into it
(``mj_copyBack``). That text is what robosuite's ``MjModel.get_xml()`` returns, and so what
``DataCollectionWrapper``, robomimic and MimicGen save with every demonstration.

Two things could make that text differ from stock's, and neither does:

- **Our own compiles** (the caches' structures, body models, skeletons, a part compiled
  alone for its inertia) go through :func:`compile_xml`: ``MjSpec.from_string(xml)
  .compile()``, MuJoCo's parser and compiler without ``mj_loadXML``, which leave the slot
  as it was (the same model, bit for bit: the caches' judges compare it with
  ``from_xml_string``'s). A MuJoCo without ``MjSpec`` (before 3.2) compiles through
  ``from_xml_string``; the slot is then owed what it held before, and given it back when
  someone reads it.
- **Loads stock makes that the model cache serves instead** (a hard reset's
  ``MjSim.from_xml_string`` under the robosuite switch, ``MujocoXML.get_model``): the
  slot is owed that load (:func:`owe`, which costs nothing). ``mujoco.mj_saveLastXML``
  first pays what is owed: it loads the XML through the bindings' own
  ``from_xml_string``, the call stock made, unless the slot already holds that XML as
  loaded; then MuJoCo writes it. A recording loop over one scene pays once: every later
  hard reset owes the XML the slot already holds.

"As loaded" matters because ``mj_copyBack`` is not a pure overwrite: it copies the
model's statistics (``meaninertia``, ``meanmass``, ``meansize``, ``extent``, ``center``)
only where they differ from the compiler's own, and a value copied stays in the parsed
model. So a write with a model whose statistics differ from the slot's compile marks the
slot as no longer fresh, and the next load owed of the same XML loads it again, as stock
did. Every other field ``mj_copyBack`` copies is overwritten by each write.

To know the order of loads, :func:`install` wraps the user's ``mujoco``: ``MjModel
.from_xml_string`` and ``from_xml_path`` (a load by anyone else is the last load, and
cancels what is owed), ``mj_saveLastXML`` (pays first) and ``mj_freeLastXML`` (empties the
slot; nothing is owed after it). Each wrapper calls MuJoCo's own function with the same
arguments and returns or raises what it does. Loads that run at the same time on several
threads leave the slot to whichever MuJoCo finished last, as under stock; what it holds is
then taken as unknown, and the next load owed is loaded. Where the slot cannot be given
stock's content (a MuJoCo without ``MjSpec`` whose slot held a model loaded before the
wrappers were installed), ``mj_saveLastXML`` raises :class:`LastXmlError` naming itself,
never writing another model. docs/compiled.md, "What a client reads", lists every piece
of MuJoCo's process-wide state and why the switch leaves it as stock does.
"""

from __future__ import annotations

import copy
import functools
import sys
import threading
from typing import Any, Callable, Optional, Union

import numpy as np

from . import _asset_cache
from ._copied_back import copied_back, rewrites_as
from ._mujoco import VISUAL, restored_arrays, struct_fields

__all__ = ["LastXmlError", "compile_xml", "install", "owe", "state"]


class LastXmlError(RuntimeError):
    """``mujoco.mj_saveLastXML`` cannot give the XML stock would write (see the module)."""


# What MuJoCo's slot holds, as a key: ("xml", text, assets), ("path", filename, assets),
# or one of these.
_UNKNOWN = ("unknown",)  # loaded before the wrappers, or by loads that overlapped
_EMPTY = ("empty",)  # nothing (mj_freeLastXML)
_OURS = ("ours",)  # a compile of ours (a MuJoCo without MjSpec)
_LOST = ("lost",)  # owed, but not known: cannot be given back

Source = Union[str, Callable[[], str]]


class _Slot:
    """The bookkeeping of MuJoCo's one slot: what it holds, what stock's would hold."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.held: tuple = _UNKNOWN
        self.fresh = False  # no write since the load left a statistic copied in it
        self.stat: Optional[tuple] = None  # the held model's statistics as compiled
        # The held compile's _signature: mj_copyBack writes only into a model of its sizes.
        self.signature: Optional[tuple] = None
        self.owed: Any = None  # the key stock's slot holds, where it differs from held
        # The statistics and _signature of the model served for it.
        self.owed_stat: Optional[tuple] = None
        # The files the held load and the owed one read, and of those, the ones each read
        # from disk rather than MuJoCo's asset cache (some MuJoCo versions write which).
        self.held_cold: Optional[frozenset] = None
        self.owed_files: frozenset = frozenset()
        self.owed_cold: frozenset = frozenset()
        self.paid = 0  # loads made to pay what was owed
        self.rewritten = 0  # writes through the held load instead (see _rewrites_as)
        self.loading = 0  # wrapped loads running now
        self.overlapped = False  # two of them ran at once (reset when none runs)


_SLOT = _Slot()
# MuJoCo's own functions, once wrapped: {"from_xml_string": ..., "from_xml_path": ...,
# "mj_saveLastXML": ..., "mj_freeLastXML": ...}.
_ORIGINAL: dict = {}
_INSTALL_LOCK = threading.Lock()


def _stat(model: Any) -> tuple:
    s = model.stat
    return (
        float(s.meaninertia), float(s.meanmass), float(s.meansize), float(s.extent),
        tuple(float(c) for c in s.center),
    )


def _xml_key(xml: str, assets: Any) -> tuple:
    return ("xml", xml, None if assets is None else dict(assets))


def _loaded(key: tuple, model: Any, began_alone: bool, reads: tuple) -> None:
    """A load of ``key`` finished (under the slot's lock); ``reads``: its files, the ones
    stock's load of it read from disk (``None`` for a load stock did not make) and ours."""
    slot = _SLOT
    slot.loading -= 1
    files, stock_cold, our_cold = reads
    if began_alone and not slot.overlapped:
        slot.held, slot.fresh, slot.stat = key, True, _stat(model)
        slot.signature = _signature(model)
        slot.held_cold = our_cold
    else:
        slot.held, slot.fresh, slot.stat, slot.signature = _UNKNOWN, False, None, None
        slot.held_cold = None
    if slot.loading == 0:
        slot.overlapped = False
    slot.owed = None
    if stock_cold is not None and stock_cold != our_cold and slot.held is key:
        # Stock's load read other files from disk: the slot owes stock's load of it.
        slot.owed, slot.owed_stat = key, None
        slot.owed_files, slot.owed_cold = files, stock_cold


def forget_held() -> None:
    """MuJoCo's slot was loaded by no one's load the bookkeeping knows (the asset cache's
    probe): what it holds is unknown from now on."""
    slot = _SLOT
    with slot.lock:
        slot.held, slot.fresh, slot.stat, slot.signature = _UNKNOWN, False, None, None
        slot.held_cold = None


def _files(key: tuple) -> frozenset:
    kind, source, _assets = key
    return _asset_cache.files_of(source) if kind == "xml" else _asset_cache.files_of_path(source)


def _load(loader: Any, key: tuple, *args: Any, stock: bool = True, **kwargs: Any) -> Any:
    """MuJoCo's own ``loader(*args, **kwargs)``, recorded as the slot's last load (one
    stock's process makes too, unless ``stock`` is false: a load that pays what is owed)."""
    slot = _SLOT
    files = _files(key)
    if stock:
        stock_cold, our_cold = _asset_cache.both_read(files)
    else:
        stock_cold, our_cold = None, _asset_cache.our_reads(files)
    with slot.lock:
        began_alone = slot.loading == 0
        slot.loading += 1
        if not began_alone:
            slot.overlapped = True
    try:
        model = loader(*args, **kwargs)
    except BaseException:
        with slot.lock:
            slot.loading -= 1
            if slot.loading == 0:
                slot.overlapped = False
        raise
    with slot.lock:
        _loaded(key, model, began_alone, (files, stock_cold, our_cold))
    return model


def _key_of(args: tuple, kwargs: dict, kind: str) -> tuple:
    first = args[0] if args else kwargs.get("xml" if kind == "xml" else "filename")
    assets = args[1] if len(args) > 1 else kwargs.get("assets")
    if kind == "xml":
        return _xml_key(first, assets)
    return ("path", first, None if assets is None else dict(assets))


def install(mujoco: Any) -> None:
    """Wraps ``mujoco``'s loaders and ``mj_saveLastXML`` / ``mj_freeLastXML`` (see the
    module); once per process, and a no-op after."""
    with _INSTALL_LOCK:
        if _ORIGINAL:
            return
        model_class = mujoco.MjModel
        from_string = model_class.from_xml_string
        from_path = model_class.from_xml_path
        save = mujoco.mj_saveLastXML
        # Not every version's bindings have it.
        free = getattr(mujoco, "mj_freeLastXML", None)

        def from_xml_string(*args: Any, **kwargs: Any) -> Any:
            return _load(from_string, _key_of(args, kwargs, "xml"), *args, **kwargs)

        def from_xml_path(*args: Any, **kwargs: Any) -> Any:
            return _load(from_path, _key_of(args, kwargs, "path"), *args, **kwargs)

        def mj_saveLastXML(filename: Any, m: Any, *args: Any, **kwargs: Any) -> Any:
            with _WRITE_LOCK:
                written = _pay("mujoco.mj_saveLastXML", m)
                result = save(filename, written, *args, **kwargs)
                with _SLOT.lock:
                    if _SLOT.fresh and (_SLOT.stat is None or _stat(written) != _SLOT.stat):
                        _SLOT.fresh = False
            return result

        def mj_freeLastXML(*args: Any, **kwargs: Any) -> Any:
            result = free(*args, **kwargs)
            with _SLOT.lock:
                _SLOT.held, _SLOT.fresh, _SLOT.stat, _SLOT.owed = _EMPTY, False, None, None
            return result

        for wrapper, original in (
            (from_xml_string, from_string), (from_xml_path, from_path),
            (mj_saveLastXML, save), (mj_freeLastXML, free),
        ):
            wrapper.__doc__ = getattr(original, "__doc__", None)
            wrapper.__wrapped__ = original  # type: ignore[attr-defined]
        _ORIGINAL.update(
            from_xml_string=from_string, from_xml_path=from_path,
            mj_saveLastXML=save, mj_freeLastXML=free,
        )
        model_class.from_xml_string = staticmethod(from_xml_string)
        model_class.from_xml_path = staticmethod(from_xml_path)
        mujoco.mj_saveLastXML = mj_saveLastXML
        if free is not None:
            mujoco.mj_freeLastXML = mj_freeLastXML


def _installed() -> bool:
    if not _ORIGINAL:
        module = sys.modules.get("mujoco")
        if module is None:
            return False
        install(module)
    return True


def owe(source: Source, assets: Any = None, served: Any = None, files: Any = None) -> None:
    """Records that stock would have loaded ``source`` (MJCF text, or a function that
    writes it, called only if the slot is read) with ``mujoco.MjModel.from_xml_string``
    now, and that the model cache served that load instead (``served``: the model it
    gave, MuJoCo's compile of ``source``, when the caller has it; ``files``: the mesh
    files the model reads, ``Document.files("mesh")``, read from the text when not
    given)."""
    if not _installed():
        return
    if files is None:
        files = _asset_cache.files_of(source) if isinstance(source, str) else frozenset()
    files = frozenset(files)
    cold = _asset_cache.stock_reads(files)
    slot = _SLOT
    with slot.lock:
        slot.owed_files, slot.owed_cold = files, cold
        if isinstance(source, str):
            key = _xml_key(source, assets)
            same = slot.fresh and _same(slot.held, key) and slot.held_cold == cold
            slot.owed = None if same else key
        else:
            slot.owed = ("lazy", source, None if assets is None else dict(assets))
        slot.owed_stat = (
            (_stat(served), _signature(served)) if served is not None and slot.owed is not None else None
        )


def _same(held: tuple, key: tuple) -> bool:
    return held[0] == "xml" and held[1] == key[1] and held[2] == key[2]


def _pay(api: str, model: Any = None) -> Any:
    """Gives the slot what stock's holds, before ``api`` reads it; returns the model to
    write it with: ``model``, or a copy of it whose statistics are the held load's where
    the held load writes what the owed one would (:func:`_rewrites_as`)."""
    slot = _SLOT
    with slot.lock:
        owed, owed_stat = slot.owed, slot.owed_stat
        held, fresh, held_stat, held_signature = slot.held, slot.fresh, slot.stat, slot.signature
        files, cold, same_reads = slot.owed_files, slot.owed_cold, slot.held_cold == slot.owed_cold
    if owed is None:
        return model
    if owed is _LOST:
        raise LastXmlError(
            f"{api}: MuJoCo's last loaded XML model was replaced by one of mjcf-forge's "
            "compiles (this MuJoCo has no MjSpec to compile without it) before the model "
            "it held was known; load the model again with mujoco.MjModel.from_xml_string "
            "(or import mjcf_forge before loading it)"
        )
    if owed is _EMPTY:
        _ORIGINAL["mj_freeLastXML"]()
        with slot.lock:
            slot.held, slot.fresh, slot.stat, slot.owed = _EMPTY, False, None, None
        return
    if owed[0] == "lazy":
        lazy, owed = owed, _xml_key(owed[1](), owed[2])
        with slot.lock:
            if slot.owed is lazy:  # written once: later writes compare the text itself
                slot.owed = owed
    with slot.lock:
        if slot.fresh and _same(slot.held, owed) and slot.held_cold == cold:
            slot.owed = None
            return model
    if (
        model is not None and fresh and same_reads and owed_stat is not None and held_stat is not None
        and held[0] == owed[0] == "xml" and held[2] is None and owed[2] is None
        and _stat(model) == owed_stat[0] and _signature(model) == owed_stat[1]
        and owed_stat[1] == held_signature and _rewrites_as(held[1], owed[1])
    ):
        # Written through the held load, with the held load's statistics: what stock's
        # load of the owed text writes (the slot stays owed: every write goes this way).
        written = _with_statistics(model, held_stat)
        if written is not None:
            with slot.lock:
                slot.rewritten += 1
            return written
    kind, text, assets = owed
    loader = _ORIGINAL["from_xml_string" if kind == "xml" else "from_xml_path"]
    args = (text,) if assets is None else (text, assets)
    try:
        # MuJoCo's asset cache as stock's held it for that load, then the load.
        _asset_cache.match(files, cold, lambda: _spec_compile(sys.modules["mujoco"], kind, text))
    except RuntimeError as e:
        raise LastXmlError(f"{api}: {e}") from None
    try:
        _load(loader, owed, *args, stock=False)
        with slot.lock:
            slot.paid += 1
    except ValueError as e:
        raise LastXmlError(
            f"{api}: the model stock would hold there no longer compiles: {e}"
        ) from None
    return model


class _Scratch:
    """A model of one structure that writes through the held load take their values in:
    every array but the bulk data (which neither ``mj_copyBack`` nor the writer reads, and
    which is most of a model's bytes: copying Lift's whole model takes longer than the
    write), ``opt`` and ``vis`` copied from the model written, the statistics the held
    load's. Never the caller's model: a simulation may read it on another thread."""

    def __init__(self, mujoco: Any, model: Any) -> None:
        self.model = copy.copy(model)
        self.signature = _signature(model)
        self.arrays = [(getattr(self.model, n), n) for n in restored_arrays(mujoco, model)]
        self.structs = [("opt",)] + [("vis", g) for g in VISUAL if hasattr(model.vis, g)]
        self.fields = {path: struct_fields(_walk(model, path)) for path in self.structs}

    def fill(self, model: Any, stat: tuple) -> Any:
        for view, name in self.arrays:
            np.copyto(view, getattr(model, name))
        for path in self.structs:
            source, target = _walk(model, path), _walk(self.model, path)
            for name in self.fields[path]:
                value = getattr(source, name)
                if isinstance(value, np.ndarray):
                    getattr(target, name)[...] = value
                else:
                    setattr(target, name, value)
        s = self.model.stat
        s.meaninertia, s.meanmass, s.meansize, s.extent = stat[:4]
        s.center[:] = stat[4]
        return self.model


def _walk(obj: Any, path: tuple) -> Any:
    for name in path:
        obj = getattr(obj, name)
    return obj


def _signature(model: Any) -> tuple:
    """What makes two models of one structure: every size, the names, MuJoCo's signature.
    Two texts of one structure can compile to different sizes: a free body of two box
    geoms whose sizes change the order of its principal inertias gets a rotated inertial
    frame, is no longer "simple", and MuJoCo 3.3's ``nC`` changes (Lift's cube, about one
    reset in ten). ``mj_copyBack`` checks such sizes against the held compile's, and where
    one differs MuJoCo 3.3 writes the held load unchanged, silently: a write goes through
    the held load only where the held compile, the served model and the written one have
    one signature."""
    names = _SIZES.get(type(model))
    if names is None:
        names = _SIZES[type(model)] = tuple(
            n for n in dir(model)
            if n.startswith("n") and type(getattr(model, n, None)) is int
        )
    sizes = tuple(getattr(model, n) for n in names)
    return (sizes, bytes(model.names), int(getattr(model, "signature", 0)))


_SIZES: dict = {}  # a model class -> the names of its integer sizes (nq, nbody, nbuffer...)


_SCRATCH: list = []  # the last structure's _Scratch
# Writes through the held load use the one scratch model: one at a time (MuJoCo's own
# mutex serializes the writes anyway).
_WRITE_LOCK = threading.RLock()


def _with_statistics(model: Any, stat: tuple) -> Optional[Any]:
    """A model with ``model``'s values and the statistics ``stat`` (see :class:`_Scratch`),
    or ``None`` where that cannot stand for it (height fields: their data is bulk, and
    ``mj_copyBack`` copies it back)."""
    if int(model.nhfield):
        return None
    mujoco = sys.modules["mujoco"]
    if not _SCRATCH or _SCRATCH[0].signature != _signature(model):
        _SCRATCH[:] = [_Scratch(mujoco, model)]
    return _SCRATCH[0].fill(model, stat)


_REWRITES: dict = {}  # (held text, owed text) -> answer, the last few pairs


def _rewrites_as(held: str, owed: str) -> bool:
    """Whether MuJoCo writes, from the held load of ``held``, what it writes from a load
    of ``owed`` (for a model of ``owed`` whose statistics are set to the held load's
    compile): both texts have the same elements and attributes, and differ only in values
    ``mj_copyBack`` overwrites from the model and the writer writes from there alone
    (:mod:`._copied_back`). What else a value feeds at compile time is the compiled
    statistics (meaninertia, meanmass, meansize, extent, center), which ``mj_copyBack``
    copies only where they differ from the held compile's: the written model carries the
    held compile's."""
    pair = (held, owed)
    answer = _REWRITES.get(pair)
    if answer is None:
        module = sys.modules.get("mujoco")
        answer = rewrites_as(held, owed, copied_back(getattr(module, "__version__", "")))
        if len(_REWRITES) >= 8:
            _REWRITES.pop(next(iter(_REWRITES)))
        _REWRITES[pair] = answer
    return answer


def compile_xml(mujoco: Any, xml: str) -> Any:
    """``mujoco.MjModel.from_xml_string(xml)``'s model, compiled without touching MuJoCo's
    last loaded XML model (see the module); raises the ``ValueError`` it raises.

    >>> import mujoco
    >>> from mjcf_forge import _last_xml
    >>> m = _last_xml.compile_xml(mujoco, '<mujoco><worldbody><geom size="1"/></worldbody></mujoco>')
    >>> m.ngeom
    1
    """
    if _spec_compiles(mujoco):
        _asset_cache.our_reads(_asset_cache.files_of(xml))
        return mujoco.MjSpec.from_string(xml).compile()
    # No MjSpec: the loader replaces the slot; it is owed what it held, where that can be
    # loaded again to what stock's holds (a load, or nothing, written to only as loaded).
    _installed()
    slot = _SLOT
    with slot.lock:
        if slot.owed is None and slot.held is not _OURS:
            held = slot.held
            restorable = held is _EMPTY or (held[0] in ("xml", "path") and slot.fresh)
            slot.owed = held if restorable else _LOST
    loader = _ORIGINAL.get("from_xml_string") or mujoco.MjModel.from_xml_string
    _asset_cache.our_reads(_asset_cache.files_of(xml))
    model = loader(xml)
    with slot.lock:
        slot.held, slot.fresh, slot.stat = _OURS, False, None
    return model


def _spec_compile(mujoco: Any, kind: str, source: str) -> None:
    """Compiles the text ``source`` (or the file, for ``kind`` ``"path"``) without
    touching the slot: what fills MuJoCo's asset cache with the model's files."""
    spec = mujoco.MjSpec.from_string(source) if kind == "xml" else mujoco.MjSpec.from_file(source)
    spec.compile()


@functools.lru_cache(maxsize=None)
def _spec_compiles(mujoco: Any) -> bool:
    """Whether this MuJoCo parses text into an ``MjSpec`` and compiles it (3.2 on)."""
    spec_class = getattr(mujoco, "MjSpec", None)
    if spec_class is None or not hasattr(spec_class, "from_string"):
        return False
    try:
        model = spec_class.from_string("<mujoco/>").compile()
    except (TypeError, ValueError, AttributeError):
        return False
    return getattr(model, "nbody", 0) == 1


def state() -> dict:
    """The slot's bookkeeping, for tests and docs: what it holds (``"xml"``, ``"path"``,
    ``"unknown"``, ``"empty"``, ``"ours"``), whether it is fresh, whether a load is owed,
    how many loads paid what was owed and how many writes went through the held load."""
    with _SLOT.lock:
        return {
            "held": _SLOT.held[0],
            "fresh": _SLOT.fresh,
            "owed": None if _SLOT.owed is None else _SLOT.owed[0],
            "installed": bool(_ORIGINAL),
            "paid": _SLOT.paid,
            "rewritten": _SLOT.rewritten,
        }
