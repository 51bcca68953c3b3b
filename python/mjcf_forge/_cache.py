"""Compiled variants at patch cost: :class:`ModelCache`.

A variant splits into its *structure* (``variant.structure_key``: which objects are placed
in which slot, and every value that cannot be written into a compiled model exactly) and
its *patch* (``variant.patch``: poses, colours, frictions, masses... as compiled values).
Variants with the same key compile to models that differ only in the patched values and in
what MuJoCo's ``mj_setConst`` derives from them. So the cache compiles each structure once
and turns that model into any variant of the structure by writing the patch into its arrays
and calling ``mj_setConst``: what MuJoCo would compile from the variant's XML, in a fraction
of a millisecond instead of the compile's tens of milliseconds.
"""

from __future__ import annotations

import copy
import os
from typing import Any

import numpy as np

from ._mjcf_forge import CacheCore, PatchPlan, Scene, WorldRows
from ._progress import progress_of


class ModelCache:
    """Compiled models of a :class:`Scene`'s variants, one per structure, patched per
    variant (``scene`` is a :class:`Scene` or the path of a scene file); bounded in count (``max_models``) and bytes (``max_bytes``: the models, their
    scratch data included), least recently used first out.

    ``cache.model(variant)`` gives a model equal to what MuJoCo compiles from
    ``variant.xml``: the cached model of the variant's structure, patched in place, or on
    a miss the variant compiled (and kept). The model belongs to the cache: the next call
    for the same structure patches it again (``copy.copy`` it to keep one).
    ``cache.apply(variant, model)`` patches a model of your own in place (an environment's
    ``reset``: no allocation, no copy); it must have the variant's structure, else an
    :class:`MjcfError` says so.

    With ``superset=True`` every variant is a patch of one model, the scene's
    :class:`Superset` (every object any slot can hold; those a variant does not place are
    parked: out of reach, each in its own cell high above the world, invisible, held
    still; collision flags stay as authored): ``cache.model(variant)``
    is that model patched, and ``cache.batch(variants)`` gives the per-world arrays that
    batched simulators (MJX, MuJoCo Warp, MuJoCo's batch API) take
    (:class:`mjcf_forge.batch.WorldBatch` gives them in each simulator's own form).

    Across processes, a structure compiled once is kept in the model store as
    :class:`DocumentCache` keeps it (``store``: a folder, ``False`` none, ``None`` or
    ``True`` the environment's ``MJCF_FORGE_STORE``, else the user cache folder; never
    for a superset): a later process's miss loads it and patches it into the variant
    asked for (``loads`` counts those misses).

    >>> import mjcf_forge
    >>> scene = mjcf_forge.Scene.demo()
    >>> cache = mjcf_forge.ModelCache(scene, max_models=4, store=False)
    >>> model = cache.model(scene.variant(0))
    >>> model.nbody > 1
    True
    """

    def __init__(
        self,
        scene: Any,
        max_models: int = 8,
        max_bytes: int | None = None,
        superset: bool = False,
        *,
        store: Any = None,
    ) -> None:
        import mujoco

        if isinstance(scene, (str, os.PathLike)):
            scene = Scene.load(scene)
        elif not hasattr(scene, "fixed_statistics"):  # a Scene, or code that stands for one
            raise TypeError(
                f"ModelCache(scene): a Scene or the path of a scene file, not {type(scene).__name__}"
            )
        if max_models < 1:
            raise ValueError("max_models must be at least 1")
        self._mujoco = mujoco
        self._scene = scene
        #: The scene's :class:`Superset` when every variant is a patch of it, else None.
        self.superset = scene.superset() if superset else None
        # Superset: body ids by name (one structure).
        self._body_ids: dict[str, int] = {}
        # The rules (misses, patches, a caller's model checked, the bound, a superset's
        # worlds derived tree by tree) are the split tier's cache core, the C face's too;
        # this class is its face.
        self._core = CacheCore(
            mujoco, max_models, max_bytes, list(scene.fixed_statistics), self.superset, store
        )

    def __len__(self) -> int:
        return len(self._core)

    @property
    def nbytes(self) -> int:
        """Bytes held: every cached model, and every model's scratch ``MjData``."""
        return self._core.nbytes

    @property
    def compiles(self) -> int:
        """Models compiled (misses) so far: compiled, or loaded from the store."""
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
        """Patches applied so far."""
        return self._core.patches

    @property
    def by_tree(self) -> int:
        """Superset patches whose derived values came tree by tree (not ``mj_setConst``)."""
        return self._core.by_tree

    @property
    def derive_by_tree(self) -> bool:
        """Superset: whether a patch derives what ``mj_setConst`` would tree by tree where
        its layout allows (``mjcf_forge::split::TreeDerivation``: the same bits, at a
        fraction of the cost for a large superset). ``False``: ``mj_setConst`` always."""
        return self._core.derive_by_tree

    @derive_by_tree.setter
    def derive_by_tree(self, value: bool) -> None:
        self._core.derive_by_tree = bool(value)

    def model(self, variant: Any) -> Any:
        """A compiled model equal to MuJoCo's compile of ``variant.xml`` (see the class);
        with ``superset=True``, the superset model patched for the variant."""
        return self._core.model(variant)

    def apply(self, variant: Any, model: Any) -> Any:
        """Patches ``model`` (of ``variant``'s structure) in place into ``variant``'s
        compiled model; returns it. Raises :class:`MjcfError` when its structure differs."""
        return self._core.apply(variant, model)

    def batch(self, variants: Any, progress: Any = None) -> dict[str, np.ndarray]:
        """Per-world arrays for batched simulation (``superset=True``): for every field of
        the superset model that differs between the given variants, and always for
        ``qpos0`` and the statistics, one row per variant (``{"geom_rgba": (n, ngeom, 4),
        "qpos0": (n, nq), "stat.meaninertia": (n,), ...}``), each row what the patched
        superset model holds for that variant: the form MJX and MuJoCo Warp take for
        per-world model fields. Every other field is left out: the superset model's
        value is every variant's. The rule of the Rust ``ModelCache::worlds``
        (docs/compiled.md, "Per-world arrays").

        ``progress``: ``True`` (a ``tqdm`` bar, or a line on standard error every second
        without ``tqdm``), a ``tqdm``-like object with ``update(n)``, or a callable ``f(n)``,
        told per variant; ``None`` (default) or ``False`` for none."""
        if self.superset is None:
            raise ValueError("batch() needs ModelCache(scene, superset=True)")
        variants = list(variants)
        bar = progress_of(progress, len(variants), "variants")
        if not variants:
            if bar is not None:
                bar.close()
            return {}
        model = copy.copy(self.model(variants[0]))
        rows = WorldRows(model, model, ["qpos0"])
        try:
            for v in variants:
                self.apply(v, model)
                rows.push()
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
        return rows.arrays()


# The batch tier's access to a superset cache (batch.py, _warp.py): functions of this
# module, so that no other module reads a cache's private state.
def mujoco_of(cache: ModelCache) -> Any:
    """The ``mujoco`` module ``cache`` compiles and patches with."""
    return cache._mujoco


def body_ids_of(cache: ModelCache, model: Any, names: Any) -> list[int]:
    """The ids of the bodies ``names`` in ``model``, of ``cache``'s superset structure
    (looked up once per name)."""
    ids = cache._body_ids
    return [ids[n] if n in ids else ids.setdefault(n, model.body(n).id) for n in names]


def apply_world(cache: ModelCache, model: Any, world: tuple, patch0: list) -> Any:
    """``model`` patched in place for one world of ``Superset.worlds`` (``world``: its
    index, numbers, strings and parked roots; ``patch0``: a patch of its layout, resolved
    once), as :meth:`ModelCache.apply` patches a variant."""
    return cache._core.apply_world(model, world, patch0)


def plan_of(cache: ModelCache, model: Any) -> PatchPlan:
    """The patch plan ``cache`` keeps for ``model`` (one it patched)."""
    plan = cache._core.plan(model)
    if plan is None:
        raise KeyError("the cache keeps no plan of this model")
    return plan
