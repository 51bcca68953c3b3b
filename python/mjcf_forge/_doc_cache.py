"""Compiled models of any documents at patch cost: :class:`DocumentCache`.

A document splits into its *structure* (``doc.structure_key``: everything that cannot be
written into a compiled model exactly, and where the rest lands) and its *patch*
(``doc.patch``: colours, frictions, poses, masses, gains, option values... as compiled
values), found by reading the document (in Rust). The cache compiles a structure the first
time it sees it and from then on writes the patch into that model, then ``mj_setConst``
and the compiler's statistics, as :class:`ModelCache` does for a scene's variants: the
model MuJoCo compiles from the document, every array and size, at patch cost.

The rules (per-thread pools of the models given out, held models, ``into=``, snapshots
written back, one compile per structure across threads, the bound) are the split tier's
document cache, ``mjcf_forge::split::DocumentCore``, run over the user's ``mujoco`` by the
extension's ``DocumentCore``: this module is its face.
"""

from __future__ import annotations

import os
from typing import Any

from ._mjcf_forge import Document, DocumentCore


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

    Across processes, a structure compiled once is kept in a store, a folder (``store``: a
    folder; ``False`` none; ``None``, the default, or ``True``: the environment's
    ``MJCF_FORGE_STORE``, a folder or ``off``, and when it is unset the user cache folder,
    ``$XDG_CACHE_HOME/mjcf-forge/models``), keyed by the structure, the MuJoCo version and
    the bytes of every file the model reads: a later process loads it and patches it
    (``loads`` counts those misses). A corrupt entry or an unwritable folder gives a
    ``RuntimeWarning`` and a compile. The process's model cache (``get_model``, the
    robosuite and LIBERO switch) keeps its structures in the environment's store too.

    Two threads asking for one structure compile it once; each gets a model of its own.
    MuJoCo's error, when it refuses a document, comes as an :class:`MjcfError` at the
    element it names in the document's sources (``file:line:col: message``), and leaves
    the cache as it was.

    >>> import mjcf_forge
    >>> cache = mjcf_forge.DocumentCache(max_models=4, store=False)  # in this process only
    >>> xml = "<mujoco><worldbody><geom name='g' size='.1' rgba='{}'/></worldbody></mujoco>"
    >>> red = cache.model(xml.format("1 0 0 1"))     # compiled
    >>> blue = cache.model(xml.format("0 0 1 1"))    # the same structure: patched
    >>> blue.geom("g").rgba.tolist(), cache.compiles, cache.patches
    ([0.0, 0.0, 1.0, 1.0], 1, 1)
    """

    def __init__(
        self, max_models: int = 8, max_bytes: int | None = None, *, store: Any = None
    ) -> None:
        import mujoco

        if max_models < 1:
            raise ValueError("max_models must be at least 1")
        self._core = DocumentCore(mujoco, max_models, max_bytes, store)

    def __len__(self) -> int:
        return len(self._core)

    @property
    def compiles(self) -> int:
        """Misses so far: models compiled, or loaded from the store."""
        return self._core.compiles

    @property
    def loads(self) -> int:
        """Of the misses, the models loaded from the store (another process compiled them)."""
        return self._core.loads

    @property
    def store(self) -> Any:
        """The folder structures are kept in across processes, or ``None``."""
        return self._core.store

    @property
    def patches(self) -> int:
        """Patches applied (hits) so far."""
        return self._core.patches

    @property
    def nbytes(self) -> int:
        """Bytes held: every model, its scratch ``MjData`` and its structure's snapshot."""
        return self._core.nbytes

    def model(self, source: Any, base_dir: Any = None, *, into: Any = None) -> Any:
        """The ``mujoco.MjModel`` MuJoCo compiles from ``source`` (a :class:`Document`,
        MJCF text read from ``base_dir``, or a path); see the class.

        ``into``: a model this cache gave you that you still hold and no longer need as
        it is (a simulation about to be made again), or a list of such models. When
        ``source`` has the structure of one of them and the cache still keeps it, that
        model itself is patched and returned; otherwise the call is as without ``into``
        (``result is into`` says which).

        >>> import mjcf_forge
        >>> cache = mjcf_forge.DocumentCache(store=False)
        >>> xml = "<mujoco><worldbody><geom name='g' size='.1' rgba='{}'/></worldbody></mujoco>"
        >>> held = cache.model(xml.format("1 0 0 1"))
        >>> cache.model(xml.format("0 0 1 1"), into=held) is held, held.geom("g").rgba.tolist()
        (True, [0.0, 0.0, 1.0, 1.0])
        """
        return self._core.model(_document(source, base_dir), into)

    def _pool_len(self, source: Any, base_dir: Any = None) -> int:
        """How many models this thread's pool of ``source``'s structure holds (tests)."""
        return self._core.pool_len(_document(source, base_dir))


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
