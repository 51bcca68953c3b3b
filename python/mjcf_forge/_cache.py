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
import weakref
from typing import Any

import numpy as np

from ._mjcf_forge import (
    LAYOUTS_KEPT,
    MODEL_FIELDS,
    STATIC_PREFIXES,
    STATISTIC_NAMES,
    CacheCore,
    PatchPlan,
    Scene,
)
from ._progress import progress_of
from ._trees import TreeDerivation


def copy_value(value: Any) -> Any:
    return value.copy() if hasattr(value, "copy") else value


def _bodies_from_geoms(model: Any) -> None:
    """What ``mj_setConst`` also derives from the geoms and no tree derivation does: each
    body's ``contype`` and ``conaffinity`` (its geoms' flags or-ed) and ``margin`` (their
    largest margin, 0 without geoms). A body's geoms are contiguous, in body order."""
    num = model.body_geomnum
    has = np.flatnonzero(num > 0)
    if not len(has):
        return
    starts = model.body_geomadr[has]
    model.body_margin[has] = np.maximum(np.maximum.reduceat(model.geom_margin, starts), 0.0)
    model.body_contype[has] = np.bitwise_or.reduceat(model.geom_contype, starts)
    model.body_conaffinity[has] = np.bitwise_or.reduceat(model.geom_conaffinity, starts)


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

    >>> import mjcf_forge
    >>> scene = mjcf_forge.Scene.demo()
    >>> cache = mjcf_forge.ModelCache(scene, max_models=4)
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
        #: Superset patches whose derived values came tree by tree (not mj_setConst).
        self.by_tree = 0
        # The rules (misses, patches, a caller's model checked, the bound) are the split
        # tier's cache core, the C face's too; this class is its face. The derivation it
        # calls back holds the cache weakly (no cycle through the core).
        ref = weakref.ref(self)

        def derive(plan: PatchPlan, parked: list, patches: int) -> Any:
            cache = ref()
            return None if cache is None else cache._tree_derive(plan, parked, patches)

        self._core = CacheCore(
            mujoco, max_models, max_bytes, list(scene.fixed_statistics), self.superset,
            derive if superset else None,
        )

    def __len__(self) -> int:
        return len(self._core)

    @property
    def nbytes(self) -> int:
        """Bytes held: every cached model, and every model's scratch ``MjData``."""
        return self._core.nbytes

    @property
    def compiles(self) -> int:
        """Models compiled (misses) so far."""
        return self._core.compiles

    @property
    def patches(self) -> int:
        """Patches applied so far."""
        return self._core.patches

    def model(self, variant: Any) -> Any:
        """A compiled model equal to MuJoCo's compile of ``variant.xml`` (see the class);
        with ``superset=True``, the superset model patched for the variant."""
        return self._core.model(variant)

    def apply(self, variant: Any, model: Any) -> Any:
        """Patches ``model`` (of ``variant``'s structure) in place into ``variant``'s
        compiled model; returns it. Raises :class:`MjcfError` when its structure differs."""
        return self._core.apply(variant, model)

    # Superset: derive what mj_setConst does tree by tree (see _trees; the same bits)
    # where a patch allows. False: always the whole mj_setConst (the tests compare both).
    _by_tree = True

    def _tree_derive(self, plan: PatchPlan, parked: Any, patches: int) -> Any:
        """Superset: ``derive(model, data, layout)`` for ``PatchPlan.finish``, deriving
        tree by tree (:class:`TreeDerivation`, per plan and patch layout) what
        ``mj_setConst`` would, or None (``mj_setConst``): no superset, or turned off.
        ``patches``: the cache's count of patches before this one."""
        if self.superset is None or not self._by_tree or parked is None:
            return None
        derivations = plan.derivations
        roots = set(self._body_ids_of(plan.model, parked))

        def derive(model: Any, data: Any, layout: list) -> bool:
            entry = derivations.get(id(layout))
            if entry is None or entry[0] is not layout:
                if len(derivations) >= LAYOUTS_KEPT:
                    derivations.clear()
                entry = derivations[id(layout)] = (layout, TreeDerivation.build(self._mujoco, model, layout))
            derivation = entry[1]
            # mj_setConst also counts the bodies with gravity compensation (ngravcomp,
            # which the engines read only to apply it at all: zero or not), a size the
            # bindings cannot set and no tree derivation writes: where the patch turns
            # that count to or from zero (objects parked after a variant that placed them
            # all), mj_setConst itself.
            compensated = bool((model.body_gravcomp > 0).any())  # as mj_setConst counts
            if derivation is None or compensated != bool(model.ngravcomp):
                self._mujoco.mj_setConst(model, data)
                return False
            if plan.derived_at != patches:
                derivation.forget()  # patched another way since this plan's last derivation
            self.by_tree += 1
            # The caller counts this patch next (patches + 1): nothing between.
            plan.derived_at = patches + 1
            fresh = derivation(model, data, roots)
            _bodies_from_geoms(model)
            return fresh

        return derive

    def _body_ids_of(self, model: Any, names: Any) -> list[int]:
        """Superset: the ids of the bodies ``names`` in ``model`` (of the superset's one
        structure), looked up once per name."""
        ids = self._body_ids
        out = []
        for name in names:
            i = ids.get(name)
            if i is None:
                i = ids[name] = model.body(name).id
            out.append(i)
        return out

    def _apply_world(self, model: Any, world: tuple, patch0: list) -> Any:
        """Superset: ``model`` patched for one world as :meth:`Superset.worlds` gives it
        (``world``: its index, numbers, strings and parked roots; ``patch0``: a patch of its
        layout, resolved once), as :meth:`apply` patches it."""
        return self._core.apply_world(model, world, patch0)

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
        names = [
            n
            for n in dir(model)
            if not n.startswith("_")
            and isinstance(getattr(model, n, None), np.ndarray)
            and not n.startswith(STATIC_PREFIXES)
        ]
        rows: dict[str, list[np.ndarray]] = {n: [] for n in names}
        stats = {f"stat.{s}": [] for s in STATISTIC_NAMES}
        try:
            for v in variants:
                self.apply(v, model)
                for n in names:
                    rows[n].append(getattr(model, n).copy())
                for s in stats:
                    stats[s].append(np.array(getattr(model.stat, s[5:]), dtype=np.float64))
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
        out = {}
        for n, r in rows.items():
            stacked = np.stack(r)
            if n == "qpos0" or not (stacked == stacked[0]).all():
                out[n] = stacked
        out.update((s, np.stack(r)) for s, r in stats.items())
        return out


# The batch tier's access to a superset cache (batch.py, _warp.py): functions of this
# module, so that no other module reads a cache's private state.
def mujoco_of(cache: ModelCache) -> Any:
    """The ``mujoco`` module ``cache`` compiles and patches with."""
    return cache._mujoco


def body_ids_of(cache: ModelCache, model: Any, names: Any) -> list[int]:
    """The ids of the bodies ``names`` in ``model``, of ``cache``'s superset structure."""
    return cache._body_ids_of(model, names)


def apply_world(cache: ModelCache, model: Any, world: tuple, patch0: list) -> Any:
    """``model`` patched in place for one world of ``Superset.worlds`` (``world``: its
    index, numbers, strings and parked roots; ``patch0``: a patch of its layout)."""
    return cache._apply_world(model, world, patch0)


def plan_of(cache: ModelCache, model: Any) -> PatchPlan:
    """The patch plan ``cache`` keeps for ``model`` (one it patched)."""
    plan = cache._core.plan(model)
    if plan is None:
        raise KeyError("the cache keeps no plan of this model")
    return plan
