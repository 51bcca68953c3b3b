"""Compiled models of any documents at patch cost: :class:`DocumentCache`.

A document splits into its *structure* (``doc.structure_key``: everything that cannot be
written into a compiled model exactly, and where the rest lands) and its *patch*
(``doc.patch``: colours, frictions, poses, masses, gains, option values... as compiled
values), found by reading the document (in Rust). The cache compiles a structure the first
time it sees it and from then on writes the patch into that model, then ``mj_setConst``
and the compiler's statistics, as :class:`ModelCache` does for a scene's variants: the
model MuJoCo compiles from the document, every array and size, at patch cost.
"""

from __future__ import annotations

import copy
import os
import sys
import threading
from typing import Any

import numpy as np

from ._cache import copy_value
from ._errors import error
from ._last_xml import compile_xml
from ._mujoco import VISUAL, restored_arrays, struct_fields
from ._mjcf_forge import Document, MjcfError, ModelStore, PatchPlan

class _Snapshot:
    """A structure's values as MuJoCo compiled them, of everything a patch or a caller may
    change (every array but the bulk data, ``model.opt``, ``model.vis``): taken once, after
    the compile, and written back into a model of the structure before each patch, so that
    what a caller changed in a model it was given does not outlive the next call."""

    def __init__(self, mujoco: Any, model: Any) -> None:
        self.arrays = {n: getattr(model, n).copy() for n in restored_arrays(mujoco, model)}
        self.structs: dict[tuple[str, ...], dict[str, Any]] = {}
        for path in [("opt",)] + [("vis", v) for v in VISUAL]:
            obj = _walk(model, path)
            if obj is not None:
                self.structs[path] = {n: copy_value(getattr(obj, n)) for n in struct_fields(obj)}
        self.nbytes = sum(a.nbytes for a in self.arrays.values())


def _walk(model: Any, path: tuple[str, ...]) -> Any:
    obj = model
    for part in path:
        obj = getattr(obj, part, None)
    return obj


class _Working:
    """One model of a structure that a thread is given: its plan (scratch data, where
    each entry lands) and its views of what the snapshot restores."""

    def __init__(self, mujoco: Any, model: Any, structure: "_Structure") -> None:
        self.model = model
        snap = structure.snapshot
        self.arrays = [(getattr(model, n), saved) for n, saved in snap.arrays.items()]
        self.structs = []
        for path, values in snap.structs.items():
            obj = _walk(model, path)
            for name, saved in values.items():
                if isinstance(saved, np.ndarray):
                    self.arrays.append((getattr(obj, name), saved))
                else:
                    self.structs.append((obj, name, saved))
        # The plan reads the model as compiled (a copy of another model may hold its patch).
        self.restore()
        self.plan = PatchPlan(mujoco, model, structure.key, structure.fixed)
        self.plan.resolve(list(structure.layout))
        # The references the cache itself holds (this object's views and plan), counted
        # by calibrate() once the model's maker has let go of it.
        self.own = sys.maxsize

    def calibrate(self) -> None:
        self.own = sys.getrefcount(self.model)

    def held(self) -> bool:
        """Whether anyone but the cache still holds the model (a simulation made on it, one
        of its arrays): such a model is never patched again (CPython's reference count, the
        same expression as in calibrate())."""
        return sys.getrefcount(self.model) > self.own

    def restore(self) -> None:
        """Writes back what the snapshot holds."""
        for view, saved in self.arrays:
            np.copyto(view, saved)
        for obj, name, saved in self.structs:
            setattr(obj, name, saved)

    def patch(self, values: np.ndarray, materials: list, bodies: list) -> None:
        self.restore()
        self.plan.write(values, materials, bodies)
        self.plan.finish()


# Models of one structure a thread keeps: one to patch while a simulation made on the
# previous one is still alive (robosuite makes its next simulation before it drops the
# last), and room for a few environments in one process.
_POOL = 4


class _Structure:
    """A compiled structure: its snapshot, the layout of its patch, the statistics its
    ``<statistic>`` fixes, and per thread that asked for it the models it was given."""

    def __init__(self, mujoco: Any, key: str, model: Any, doc: Any, fixed: list) -> None:
        self.key = key
        self.layout = doc.patch
        self.fixed = [(s, copy_value(getattr(model.stat, s))) for s in fixed]
        self.snapshot = _Snapshot(mujoco, model)
        self.models: dict[int, list[_Working]] = {}

    @property
    def nbytes(self) -> int:
        return self.snapshot.nbytes + sum(w.plan.nbytes for w in self.workings())

    def workings(self) -> list[_Working]:
        return [w for pool in self.models.values() for w in pool]

    def free(self, me: int) -> _Working | None:
        """A model of this thread that no one but the cache holds."""
        for working in self.models.get(me, ()):
            if not working.held():
                return working
        return None

    def keep(self, me: int, working: _Working) -> None:
        """Adds ``working`` to this thread's models; beyond ``_POOL`` of them the cache
        forgets the oldest held ones (their holders keep them)."""
        pool = self.models.setdefault(me, [])
        pool.append(working)
        for old in [w for w in pool if w is not working and w.held()]:
            if len(pool) <= _POOL:
                break
            pool.remove(old)


class DocumentCache:
    """Compiled models of any MJCF documents, one per structure, patched per document;
    bounded in count (``max_models`` structures) and bytes (``max_bytes``: models, their
    scratch data and snapshots), least recently used first out.

    ``cache.model(source)`` takes a :class:`Document`, MJCF text (with ``base_dir``, the
    folder its relative file names resolve from) or a path, and gives a
    ``mujoco.MjModel`` equal to MuJoCo compiling it (every array, every size): the cached
    model of the document's structure (``doc.structure_key``) with the document's values
    (``doc.patch``) written in, or on a miss the document compiled. No one tells the cache
    what changed: documents built any way (robosuite's classes, your own code) are read.

    The model is the cache's, kept per structure and thread, and it is yours for as long
    as you hold it: a model that anyone still holds (a simulation made on it, one of its
    arrays) is never patched again; the next call for its structure patches another model
    of the structure (a copy of one, made once, when all are held). Once you let go of it,
    a later call may patch it. You may change it in place (domain randomization does)
    without changing what the cache gives next: before each patch every array but the
    bulk data (mesh, texture, height field, skin and bounding-volume data), ``model.opt``
    and ``model.vis`` are written back as compiled. The bulk data is shared between a
    structure's models as compiled: change it (a texture's pixels) in a ``copy.copy``.

    Two threads asking for one structure compile it once; each gets a model of its own.
    MuJoCo's error, when it refuses a document, comes as an :class:`MjcfError` at the
    element it names in the document's sources (``file:line:col: message``), and leaves
    the cache as it was.

    >>> import mjcf_forge
    >>> cache = mjcf_forge.DocumentCache(max_models=4)
    >>> xml = "<mujoco><worldbody><geom name='g' size='.1' rgba='{}'/></worldbody></mujoco>"
    >>> red = cache.model(xml.format("1 0 0 1"))     # compiled
    >>> blue = cache.model(xml.format("0 0 1 1"))    # the same structure: patched
    >>> blue.geom("g").rgba.tolist(), cache.compiles, cache.patches
    ([0.0, 0.0, 1.0, 1.0], 1, 1)
    """

    def __init__(self, max_models: int = 8, max_bytes: int | None = None) -> None:
        import mujoco

        if max_models < 1:
            raise ValueError("max_models must be at least 1")
        self._mujoco = mujoco
        self._lock = threading.Lock()
        # Compiled structures by key, least recently used first, each counting its own
        # bytes: the split tier's bound (ModelStore), the Rust caches' too.
        self._store = ModelStore(max_models, max_bytes, sized=True)
        # Structures being compiled, each with the event its waiters wait on.
        self._compiling: dict[str, threading.Event] = {}
        #: Models compiled (misses) and patches applied (hits) so far.
        self.compiles = 0
        self.patches = 0

    def __len__(self) -> int:
        return len(self._store)

    @property
    def nbytes(self) -> int:
        """Bytes held: every model, its scratch ``MjData`` and its structure's snapshot."""
        with self._lock:
            return self._store.nbytes

    def model(self, source: Any, base_dir: Any = None, *, into: Any = None) -> Any:
        """The ``mujoco.MjModel`` MuJoCo compiles from ``source`` (a :class:`Document`,
        MJCF text read from ``base_dir``, or a path); see the class.

        ``into``: a model this cache gave you that you still hold and no longer need as
        it is (a simulation about to be made again), or a list of such models. When
        ``source`` has the structure of one of them and the cache still keeps it, that
        model itself is patched and returned; otherwise the call is as without ``into``
        (``result is into`` says which).

        >>> import mjcf_forge
        >>> cache = mjcf_forge.DocumentCache()
        >>> xml = "<mujoco><worldbody><geom name='g' size='.1' rgba='{}'/></worldbody></mujoco>"
        >>> held = cache.model(xml.format("1 0 0 1"))
        >>> cache.model(xml.format("0 0 1 1"), into=held) is held, held.geom("g").rgba.tolist()
        (True, [0.0, 0.0, 1.0, 1.0])
        """
        doc = _document(source, base_dir)
        parts = doc._split()
        key, materials, bodies = parts.structure_key, parts.materials, parts.bodies
        fixed = parts.fixed_statistics
        values = np.frombuffer(parts.numbers, dtype="<f8")
        me = threading.get_ident()
        if into is not None:
            intos = into if isinstance(into, (list, tuple)) else (into,)
            with self._lock:
                structure = self._store.get(key)
                working = None
                if structure is not None:
                    working = next(
                        (w for w in structure.workings() if any(w.model is m for m in intos)), None
                    )
            if working is not None:
                return self._patched(working, doc, key, fixed, values, materials, bodies)
        while True:
            with self._lock:
                structure = self._store.get(key)
                if structure is not None:
                    working = structure.free(me)
                    if working is None:
                        other = next(iter(structure.workings()), None)
                    break
                waiting = self._compiling.get(key)
                if waiting is None:
                    self._compiling[key] = threading.Event()
            if waiting is None:
                return self._compile(doc, key, fixed)
            # Another thread compiles this structure: its model, copied, is ours.
            waiting.wait()
        if working is None:
            working = self._adopt(structure, me, other)
        return self._patched(working, doc, key, fixed, values, materials, bodies)

    def _patched(self, working: _Working, doc: Any, key: str, fixed: list, values: np.ndarray,
                 materials: list, bodies: list) -> Any:
        """``working``'s model patched for ``doc``, or ``doc`` compiled where the patch
        fails."""
        try:
            working.patch(values, materials, bodies)
        except MjcfError:
            # A value the model cannot take (a material that does not exist, a body's
            # geoms that compile to another layout): MuJoCo's own verdict. The model is
            # whole again after its next patch, which writes every entry of the structure.
            return self._compile(doc, key, fixed, replace=True)
        with self._lock:
            self.patches += 1
        return working.model

    def _adopt(self, structure: _Structure, me: int, other: _Working | None) -> _Working:
        """A model of ``structure`` for this thread: a copy of another of its models (what
        the snapshot restores is written back before its first patch; the bulk data is
        never written)."""
        if other is None:
            raise error(f"structure {structure.key} has no model to copy")
        # No local name holds the copy, so that calibrate() counts the cache's own.
        working = _Working(self._mujoco, copy.copy(other.model), structure)
        working.calibrate()
        with self._lock:
            structure.keep(me, working)
            self._store.trim()
        return working

    def _compile(self, doc: Any, key: str, fixed: list, replace: bool = False) -> Any:
        """Compiles ``doc`` (this thread registered the compile of ``key``, unless
        ``replace``), keeps it, and wakes the threads waiting for it."""
        try:
            xml = doc.to_xml(pretty=True)
            try:
                model = compile_xml(self._mujoco, xml)
            except ValueError as e:
                raise error(doc._mujoco_error(xml, str(e))) from None
            structure = _Structure(self._mujoco, key, model, doc, fixed)
            try:
                working = _Working(self._mujoco, model, structure)
            except MjcfError:
                # A patch layout this model cannot take (an element the split names that
                # the compile does not have): the compile is the answer, and nothing is
                # kept, so documents of this structure compile (as the Rust cache does).
                with self._lock:
                    self.compiles += 1
                return model
            del model  # calibrate() counts the cache's own references
            working.calibrate()
            structure.keep(threading.get_ident(), working)
            with self._lock:
                self.compiles += 1
                self._store.insert(key, structure)
                self._store.trim()
            return working.model
        finally:
            if not replace:
                with self._lock:
                    self._compiling.pop(key).set()


def _document(source: Any, base_dir: Any) -> Any:
    if isinstance(source, Document):
        return source
    if isinstance(source, str):
        return Document.from_string(source, base_dir)
    if isinstance(source, os.PathLike):
        return Document.load(source)
    raise TypeError(
        f"DocumentCache.model takes a Document, MJCF text or a path, not {type(source).__name__}"
    )
