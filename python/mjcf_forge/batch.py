"""Worlds of a scene for batched simulators: :class:`WorldBatch`.

A scene's superset (:class:`Superset`, ``ModelCache(scene, superset=True)``) is one model
holding every object any slot can hold; a variant is that model patched, the objects it
does not place parked out of reach. A batched simulator runs many worlds of one model
whose per-world fields differ: world ``w`` holds variant ``variants[w]``, and this module
gives its fields in the shapes each simulator takes:

- :meth:`WorldBatch.to_mjwarp`: a ready ``mujoco_warp`` ``Model`` and ``Data`` (fields
  whose spec starts with ``*`` get one row per world, read at ``worldid % rows``);
- :meth:`WorldBatch.to_mjx`: an MJX model whose per-world leaves have a leading world
  axis, the ``in_axes`` to ``jax.vmap`` it, and a batched ``Data``;
- :attr:`WorldBatch.arrays` and :meth:`WorldBatch.mujoco_models`: plain per-world arrays,
  and per-world ``MjModel`` s for MuJoCo's own batch API (``mujoco.batch.Batch``);
- :meth:`WorldBatch.assign`: other variants in some worlds, at reset, without rebuilding
  the simulator's model.

``mujoco_warp`` and ``jax`` are optional: imported only by the method that needs them
(each simulator's side is a mixin of its own module: ``_warp.py``, ``_mjx.py``).

The superset keeps every candidate's collision flags as authored, so the pairs of geoms
a batched simulator fixes once (``put_model``) hold in every world; parking is geometric
(each parked candidate in its own cell high above the world, gravity compensated), and
checked here: a parked geom in contact with anything at a world's initial pose is an error
naming it. What parked bodies still change in a world is in docs/compiled.md.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from ._cache import ModelCache, apply_world, body_ids_of, mujoco_of, plan_of
from ._errors import error
from ._mjcf_forge import (
    BODY_MODEL_WRITES,
    FROM_GEOMS,
    LAYOUTS_KEPT,
    SET_CONST_DERIVED,
    STATISTIC_NAMES,
    WorldRows,
    patchable_arrays,
    target_array,
)
from ._mjx import MjxWorlds
from ._progress import progress_of
from ._warp import WarpWorlds

# The split tier's field facts (mjcf_forge::split, through the extension): the arrays
# mj_setConst derives from values a patch writes (SET_CONST_DERIVED: they follow the
# variant even when no patch entry names them), and what a world's patch writes besides
# its own arrays (BODY_MODEL_WRITES: a body model's copy and the same-frame flags).
# What the tree-by-tree derivation writes from the geoms, as mj_setConst does
# (FROM_GEOMS, mjcf_forge::split's): a world's geom margins move its bodies' margins.
# A model's keyframe arrays (each world's rows: WorldBatch.keys): its arrays of prefix
# key_.
_KEY_PREFIX = "key_"
class _Index(NamedTuple):
    """What a superset ModelCache reads of a variant: its index."""

    index: int


def _patched_arrays(patch: Sequence) -> set[str]:
    """The MjModel arrays a superset patch writes (``matid`` included)."""
    targets = (target_array(obj, field) for obj, _name, field, _value in patch)
    return {t for t in targets if t is not None}


class WorldBatch(WarpWorlds, MjxWorlds):
    """``nworld`` worlds of one scene, world ``w`` holding variant ``variants[w]``, as
    per-world fields of the scene's superset model (see the module).

    ``source`` is a :class:`Scene` (or the path of a scene file) or a
    ``ModelCache(scene, superset=True)``; ``variants`` are variant indices (or variants).
    ``progress``: ``True`` (a ``tqdm`` bar, or a line on standard error every second
    without ``tqdm``), a ``tqdm``-like object with ``update(n)`` or a callable ``f(n)``,
    told per world built; ``None`` (default) or ``False`` for none. ``key``: a
    keyframe's name or id: every world starts at its own rows of it (:meth:`initial`;
    None: at ``qpos0``). Raises :class:`MjcfError` for zero worlds, an unknown keyframe,
    a variant the superset cannot express (it randomizes a structural value), or a parked
    object within reach of another geom; all before any simulator array is built.

    Attributes: ``model`` (the superset ``MjModel``, patched for world 0: every shared
    field), ``arrays`` (per-world field -> ``(nworld, ...)`` array in MuJoCo's dtypes;
    ``stat.<name>`` for the statistics), ``per_world`` (their names), ``world_variant``
    (``(nworld,)`` variant index per world), ``qpos0`` and ``qpos`` (``(nworld, nq)``: the
    worlds' reference and initial joint positions), ``keys`` (every world's keyframe
    rows), ``parked_geoms`` (``(nworld, ngeom)`` bool: the geoms of objects the world
    parks).
    """

    def __init__(
        self, source: Any, variants: Sequence[Any], progress: Any = None, key: Any = None
    ) -> None:
        if isinstance(source, ModelCache):
            cache = source
        else:
            cache = ModelCache(source, superset=True)
        if cache.superset is None:
            raise ValueError("WorldBatch needs ModelCache(scene, superset=True) or a Scene")
        indices = [int(getattr(v, "index", v)) for v in variants]
        if not indices:
            raise error("a batch needs at least one world: no variant was given (0 worlds)")
        self.cache = cache
        self.superset = cache.superset
        # A variant the superset cannot express fails (in its patch), with its index. The
        # worlds are patched into the cache's own model (it is the cache's to patch: no
        # copy of a superset that may hold hundreds of megabytes of meshes); a copy of
        # world 0 keeps the shared fields.
        self._scratch = cache.model(_Index(indices[0]))
        self.model = copy.copy(self._scratch)
        self._count_every_gravcomp(self.superset.patch(indices[0]))
        #: The keyframe every world starts at (its id), or None: ``qpos0``.
        self.key = self._key_id(key)
        self._patched = _patched_arrays(self.superset.patch(indices[0]))
        model = self.model
        fields = patchable_arrays(model)
        self._candidates = sorted((self._patched | set(SET_CONST_DERIVED)) & set(fields))
        others = set(fields) - set(self._candidates)
        keys = [
            n for n in dir(model) if n.startswith(_KEY_PREFIX) and isinstance(getattr(model, n), np.ndarray)
        ] if model.nkey else []
        # Every world's rows of the candidates (and keyframes); of every other field, only
        # where a world differs from the batch's first (no superset patch makes one differ;
        # checked anyway): split::WorldRows, the rule ModelCache.batch keeps too.
        self._rows_of = WorldRows(model, self._scratch, self._candidates + keys, fields + keys)
        self._data: Any = None
        self._root_of_geom = model.body_rootid[model.geom_bodyid]
        # A patch of each layout Superset.worlds has given, by layout.
        self._layouts: dict[tuple, Any] = {}
        self._written = [n for n in BODY_MODEL_WRITES if n in others]
        self._flags = [n for n in self._written if n.endswith("_sameframe")]
        self._from_geoms = [n for n in FROM_GEOMS if n in others]
        #: Worlds whose derived values came tree by tree (the others: mj_setConst; see
        #: ``mjcf_forge::split::TreeDerivation``: the same bits).
        self.derived_by_tree = 0
        bar = progress_of(progress, len(indices), "worlds")
        parked = []
        try:
            for world in self._worlds(indices):
                compare, mask = self._patch(world)
                self._rows_of.push(compare)
                parked.append(mask)
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
        kept = self._rows_of.arrays()
        varying = sorted(n for n in kept if n in others)
        self.per_world = self._candidates + varying + [f"stat.{s}" for s in STATISTIC_NAMES]
        self.arrays = {n: kept[n] for n in self.per_world}
        self.parked_geoms = np.stack(parked)
        #: Every world's keyframes as its own patched model holds them (a key's rows for
        #: an object's free joint are its pose in that world, placed or parked):
        #: ``key_qpos`` ``(nworld, nkey, nq)``, ``key_qvel``, ``key_act``, ``key_ctrl``,
        #: ``key_mpos``, ``key_mquat``, ``key_time``; empty without keyframes.
        self.keys = {n: kept[n] for n in keys}
        self.world_variant = np.array(indices, dtype=np.int64)
        self._warp: Any = None
        self._mjx: Any = None
        self._mjx_shared: Any = None
        self._mjx_impl: str | None = None

    def _count_every_gravcomp(self, patch: Any) -> None:
        """The shared model counts every body any world may compensate for gravity: MuJoCo
        (and MuJoCo Warp and MJX, from the shared model) applies gravity compensation only
        when ``ngravcomp``, which ``mj_setConst`` counts from ``body_gravcomp`` and nothing
        else can set, is not zero; a world 0 that places every object counts none, and the
        parked objects of the other worlds would fall. Every candidate body (a parked one is
        compensated) gets a nonzero ``body_gravcomp`` here, counted by ``mj_setConst``
        (per-world rows hold each world's own); nothing else of the model may change."""
        model = self.model
        ids = [model.body(e[1]).id for e in patch if e[0] == "body" and e[2] == "gravcomp"]
        missing = [b for b in ids if model.body_gravcomp[b] <= 0]  # counted: > 0
        if not missing:
            return
        fields = [
            n for n in dir(model)
            if not n.startswith("_") and n != "body_gravcomp" and isinstance(getattr(model, n, None), np.ndarray)
        ]
        before = {n: getattr(model, n).tobytes() for n in fields}
        model.body_gravcomp[missing] = 1.0
        mujoco = mujoco_of(self.cache)
        mujoco.mj_setConst(model, mujoco.MjData(model))
        changed = [n for n in fields if getattr(model, n).tobytes() != before[n]]
        if changed:
            raise error(f"counting gravity compensation changed the shared model's {changed}")

    @property
    def nworld(self) -> int:
        return len(self.world_variant)

    @property
    def qpos0(self) -> np.ndarray:
        return self.arrays["qpos0"]

    @property
    def qpos(self) -> np.ndarray:
        """The worlds' initial joint positions: each world's ``qpos0`` (an object's pose is
        its free joint's ``qpos0``, as in the variant's own model), or with ``key`` each
        world's row of that keyframe."""
        return self.initial()["qpos"]

    def _key_id(self, key: Any) -> int | None:
        if key is None:
            return None
        model = self.model
        if isinstance(key, str):
            mujoco = mujoco_of(self.cache)
            i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, key)
            if i < 0:
                names = [model.key(k).name for k in range(model.nkey)]
                raise error(f"the scene has no keyframe '{key}' (its keyframes: {names})")
            return int(i)
        i = int(key)
        if not 0 <= i < model.nkey:
            raise error(f"keyframe {i} is out of range: the scene has {model.nkey}")
        return i

    def initial(self) -> dict[str, np.ndarray]:
        """Each world's initial state, one row per world, as ``mj_resetData`` (or with
        ``key``, ``mj_resetDataKeyframe``) sets it in the world's own model: ``qpos``,
        ``qvel``, ``act``, ``ctrl``, ``mocap_pos``, ``mocap_quat``, ``time``."""
        m, n = self.model, self.nworld
        k = self.key
        if k is not None:
            keys = self.keys
            return {
                "qpos": keys["key_qpos"][:, k].copy(),
                "qvel": keys["key_qvel"][:, k].copy(),
                "act": keys["key_act"][:, k].copy(),
                "ctrl": keys["key_ctrl"][:, k].copy(),
                "mocap_pos": keys["key_mpos"][:, k].reshape(n, -1, 3).copy(),
                "mocap_quat": keys["key_mquat"][:, k].reshape(n, -1, 4).copy(),
                "time": keys["key_time"][:, k].copy(),
            }
        mocap = m.body_mocapid >= 0
        order = np.argsort(m.body_mocapid[mocap])
        pos = self.arrays["body_pos"] if "body_pos" in self.arrays else np.broadcast_to(m.body_pos, (n,) + m.body_pos.shape)
        quat = self.arrays["body_quat"] if "body_quat" in self.arrays else np.broadcast_to(m.body_quat, (n,) + m.body_quat.shape)
        return {
            "qpos": self.arrays["qpos0"].copy(),
            "qvel": np.zeros((n, m.nv)),
            "act": np.zeros((n, m.na)),
            "ctrl": np.zeros((n, m.nu)),
            "mocap_pos": pos[:, mocap][:, order].copy(),
            "mocap_quat": quat[:, mocap][:, order].copy(),
            "time": np.zeros(n),
        }

    def _worlds(self, indices: Sequence[int]) -> Any:
        """Each variant of ``indices`` as ``(index, numbers, strings, parked, patch0)``
        (:meth:`Superset.worlds`, made in parallel a chunk at a time; ``patch0``: a patch
        of the world's layout)."""
        chunk = 256
        for start in range(0, len(indices), chunk):
            part = list(indices[start : start + chunk])
            layouts, worlds = self.superset.worlds(part)
            first = {}
            for index, (layout, *_rest) in zip(part, worlds):
                first.setdefault(layout, index)
            patches = {}
            for layout, index in first.items():
                key = layouts[layout]
                if key not in self._layouts:
                    if len(self._layouts) >= LAYOUTS_KEPT:
                        self._layouts.clear()
                    self._layouts[key] = self.superset.patch(index)
                patches[layout] = self._layouts[key]
            for index, (layout, numbers, strings, parked) in zip(part, worlds):
                yield index, numbers, strings, parked, patches[layout]

    def _patch(self, world: tuple) -> tuple[list[str] | None, np.ndarray]:
        """The superset patched for one world (``_worlds``) into the scratch model: which
        arrays beyond the candidates it may have written (``None``: any, ``mj_setConst``
        ran), and its parked geoms; a parked geom that touches anything at the initial
        pose is an error."""
        index, numbers, strings, parked_names, patch0 = world
        cache = self.cache
        parked_roots = body_ids_of(cache, self._scratch, parked_names)
        before = cache.by_tree
        model = apply_world(cache, self._scratch, (index, numbers, strings, parked_names), patch0)
        by_tree = cache.by_tree != before
        self.derived_by_tree += by_tree
        # mj_setConst may write any field (none differs for a superset patch); derived
        # tree by tree, only the patch and its body models write.
        compare: list[str] | None
        if not by_tree:
            compare = None
        elif self._plan_of_scratch().body_models:
            compare = self._written + self._from_geoms
        else:
            compare = self._flags + self._from_geoms
        mujoco = mujoco_of(self.cache)
        parked = np.isin(self._root_of_geom, parked_roots)
        # The initial pose's contacts: positions and collision only. The statistics left
        # the patch's scratch data at qpos0's positions; mocap bodies take theirs from
        # the data, so a model with some starts from a reset.
        if model.nmocap:
            if self._data is None:
                self._data = mujoco.MjData(model)
            data = self._data
            mujoco.mj_resetData(model, data)
            mujoco.mj_kinematics(model, data)
        else:
            data = self._plan_of_scratch().data
        mujoco.mj_collision(model, data)
        pairs = data.contact.geom[: data.ncon]
        if parked[pairs].any():
            g1, g2 = (int(g) for g in pairs[np.flatnonzero(parked[pairs].any(axis=1))[0]])
            a, b = (g1, g2) if parked[g1] else (g2, g1)
            raise error(
                f"variant {index}: parked geom '{model.geom(a).name or a}' (object "
                f"'{model.body(int(self._root_of_geom[a])).name}') touches geom "
                f"'{model.geom(b).name or b}': its parking cell is within reach"
            )
        return compare, parked

    def _plan_of_scratch(self) -> Any:
        return plan_of(self.cache, self._scratch)

    def assign(self, worlds: Sequence[int], variants: Sequence[Any]) -> np.ndarray:
        """World ``worlds[k]`` holds variant ``variants[k]`` from now on: its rows of
        :attr:`arrays` are the new variant's and, when built, the MuJoCo Warp model's rows
        are written and those worlds' data reset (``mujoco_warp.reset_data``); MJX is
        functional: :meth:`to_mjx` then gives the model with the new rows (no new
        ``put_model``) and :meth:`mjx_reset` the data. Returns the ``(nworld,)`` mask of the
        reassigned worlds. Raises :class:`MjcfError` when a new variant differs from the
        batch in a field that is shared by all worlds (none for a superset patch)."""
        worlds = [int(w) for w in worlds]
        indices = [int(getattr(v, "index", v)) for v in variants]
        if len(worlds) != len(indices):
            raise ValueError("assign() needs one variant per world")
        for w in worlds:
            if not 0 <= w < self.nworld:
                raise error(f"world {w} is not in the batch (0 to {self.nworld - 1})")
        for w, i, world in zip(worlds, indices, self._worlds(indices)):
            compare, parked = self._patch(world)
            differing = self._rows_of.differing(compare)
            if differing:
                raise error(
                    f"variant {i}: field {differing[0]} differs from the batch's, where all "
                    "worlds share one value (build a new WorldBatch)"
                )
            row = self._rows_of.row()
            for n in self.per_world:
                self.arrays[n][w] = row[n] if n in row else getattr(self.model, n)
            for n in self.keys:
                self.keys[n][w] = row[n]
            self.parked_geoms[w] = parked
            self.world_variant[w] = i
        mask = np.zeros(self.nworld, dtype=bool)
        mask[worlds] = True
        if self._warp is not None:
            self._warp_reassigned(mask)
        return mask

    # ---------------------------------------------------------------- MuJoCo (CPU)
    def mujoco_models(self, worlds: Sequence[int] | None = None) -> list[Any]:
        """One ``MjModel`` per world: the superset patched for the world's variant (what
        ``ModelCache(scene, superset=True).model`` gives), for
        ``mujoco.batch.Batch.set_models`` or a loop of ``mj_step``; or only for the given
        ``worlds``, in their order (each model is a whole copy of the superset: 64 worlds
        of ``benches/scenes/lift5.toml``'s 124 MB superset take 7.9 GB).

        >>> import mjcf_forge
        >>> from mjcf_forge.batch import WorldBatch
        >>> cache = mjcf_forge.ModelCache(mjcf_forge.Scene.load("corpora/scenes/patch/boxes.toml"), superset=True)
        >>> batch = WorldBatch(cache, range(4))
        >>> [m.nbody for m in batch.mujoco_models([3, 0])] == [batch.model.nbody] * 2
        True
        """
        chosen = self.world_variant if worlds is None else [self.world_variant[w] for w in worlds]
        return [copy.copy(self.cache.apply(_Index(int(i)), self._scratch)) for i in chosen]

