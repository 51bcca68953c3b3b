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

import functools
import sys
import threading
from typing import Any, Callable, Optional, Union

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
        self.owed: Any = None  # the key stock's slot holds, where it differs from held
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


def _loaded(key: tuple, model: Any, began_alone: bool) -> None:
    """A load of ``key`` finished (under the slot's lock)."""
    slot = _SLOT
    slot.loading -= 1
    if began_alone and not slot.overlapped:
        slot.held, slot.fresh, slot.stat = key, True, _stat(model)
    else:
        slot.held, slot.fresh, slot.stat = _UNKNOWN, False, None
    if slot.loading == 0:
        slot.overlapped = False
    slot.owed = None


def _load(loader: Any, key: tuple, *args: Any, **kwargs: Any) -> Any:
    """MuJoCo's own ``loader(*args, **kwargs)``, recorded as the slot's last load."""
    slot = _SLOT
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
        _loaded(key, model, began_alone)
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
            _pay("mujoco.mj_saveLastXML")
            result = save(filename, m, *args, **kwargs)
            with _SLOT.lock:
                if _SLOT.fresh and (_SLOT.stat is None or _stat(m) != _SLOT.stat):
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


def owe(source: Source, assets: Any = None) -> None:
    """Records that stock would have loaded ``source`` (MJCF text, or a function that
    writes it, called only if the slot is read) with ``mujoco.MjModel.from_xml_string``
    now, and that the model cache served that load instead."""
    if not _installed():
        return
    slot = _SLOT
    with slot.lock:
        if isinstance(source, str):
            key = _xml_key(source, assets)
            slot.owed = None if (slot.fresh and _same(slot.held, key)) else key
        else:
            slot.owed = ("lazy", source, None if assets is None else dict(assets))


def _same(held: tuple, key: tuple) -> bool:
    return held[0] == "xml" and held[1] == key[1] and held[2] == key[2]


def _pay(api: str) -> None:
    """Gives the slot what stock's holds, before ``api`` reads it."""
    slot = _SLOT
    with slot.lock:
        owed = slot.owed
    if owed is None:
        return
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
        owed = _xml_key(owed[1](), owed[2])
    with slot.lock:
        if slot.fresh and _same(slot.held, owed):
            slot.owed = None
            return
    kind, text, assets = owed
    loader = _ORIGINAL["from_xml_string" if kind == "xml" else "from_xml_path"]
    args = (text,) if assets is None else (text, assets)
    try:
        _load(loader, owed, *args)
    except ValueError as e:
        raise LastXmlError(
            f"{api}: the model stock would hold there no longer compiles: {e}"
        ) from None


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
    model = loader(xml)
    with slot.lock:
        slot.held, slot.fresh, slot.stat = _OURS, False, None
    return model


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
    ``"unknown"``, ``"empty"``, ``"ours"``), whether it is fresh, whether a load is owed."""
    with _SLOT.lock:
        return {
            "held": _SLOT.held[0],
            "fresh": _SLOT.fresh,
            "owed": None if _SLOT.owed is None else _SLOT.owed[0],
            "installed": bool(_ORIGINAL),
        }
