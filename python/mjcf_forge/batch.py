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

``mujoco_warp`` and ``jax`` are optional: imported only by the method that needs them.

The superset keeps every candidate's collision flags as authored, so the pairs of geoms
a batched simulator fixes once (``put_model``) hold in every world; parking is geometric
(each parked candidate in its own cell high above the world, gravity compensated), and
checked here: a parked geom in contact with anything at a world's initial pose is an error
naming it. What parked bodies still change in a world is in docs/compiled.md.
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from ._cache import _STATIC_PREFIXES, ModelCache, _error
from ._progress import progress_of
from ._trees import TreeDerivation

# Fields mj_setConst derives from values a patch writes (so they follow the variant even
# when no patch entry names them).
_DERIVED = (
    "body_subtreemass",
    "body_invweight0",
    "dof_invweight0",
    "dof_M0",
    "tendon_length0",
    "tendon_invweight0",
    "actuator_acc0",
    "actuator_length0",
    "cam_pos0",
    "cam_poscom0",
    "cam_mat0",
    "light_pos0",
    "light_poscom0",
    "light_dir0",
    "dof_length",
)
# Bounds a simulator reads only to cull collision candidates (the narrow phase reads the
# geoms' own margins): where a simulator holds one for all worlds, the largest of the
# worlds' values is exact.
_BOUNDS = ("body_margin",)
# Shortcuts MJX takes per body, geom or site where its frame is its body's or inertial
# frame (kept as static arrays by put_model): where the worlds differ, the general
# computation (0, mjSAMEFRAME_NONE) serves every world (the same numbers where a frame
# is exactly its body's; MuJoCo's flags allow 1e-6 of difference for a shortcut).
_FLAGS = ("body_sameframe", "geom_sameframe", "site_sameframe")
# Fields MuJoCo Warp holds for all worlds but reads only when sleeping is enabled (a
# rotational dof's length is its body's size, which for a massless root body depends on
# where the body stands: parked or placed).
_WARP_SLEEP_ONLY = ("dof_length",)
# Contacts a placed free object may have at once in MuJoCo Warp's default sizes (a box on
# a table: 4; lift5's worlds: at most 24 for 5 objects and the gripper, measured).
_CONTACTS_PER_OBJECT = 16
# What a world's patch writes besides its own arrays: a body's little model
# (_cache.compiled_body) and the same-frame flags (_trees).
_WRITTEN = (
    "geom_size", "geom_rbound", "geom_aabb", "geom_pos", "geom_quat",
    "body_mass", "body_inertia", "body_ipos", "body_iquat",
    "body_sameframe", "geom_sameframe", "site_sameframe",
)
# A model's keyframe arrays (each world's rows: WorldBatch.keys).
_KEYS = ("key_qpos", "key_qvel", "key_act", "key_ctrl", "key_mpos", "key_mquat", "key_time")
# The compiler's statistics, per world (``stat.<name>`` in :attr:`WorldBatch.arrays`).
_STATS = ("meaninertia", "meanmass", "meansize", "extent", "center")
# A patch entry's object -> the prefix of its MjModel arrays (as ModelCache resolves them).
_ARRAY_PREFIX = {
    "body": "body_", "joint": "jnt_", "geom": "geom_", "site": "site_", "camera": "cam_",
    "light": "light_", "material": "mat_", "actuator": "actuator_",
}
_JOINT_ARRAYS = {
    "damping": "dof_damping", "armature": "dof_armature", "frictionloss": "dof_frictionloss",
    "qpos0": "qpos0", "qpos_spring": "qpos_spring",
}


class _Index(NamedTuple):
    """What a superset ModelCache reads of a variant: its index."""

    index: int


def _patched_arrays(patch: Sequence) -> set[str]:
    """The MjModel arrays a superset patch writes (``matid`` included)."""
    out = set()
    for obj, _name, field, _value in patch:
        if obj == "option":
            continue
        if obj == "joint" and field in _JOINT_ARRAYS:
            out.add(_JOINT_ARRAYS[field])
        elif obj in _ARRAY_PREFIX:
            out.add(_ARRAY_PREFIX[obj] + field)
    return out


class WorldBatch:
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

    # Derive what mj_setConst does tree by tree where a patch allows (False: always the
    # whole mj_setConst; the tests compare both ways).
    _by_tree = True

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
            raise _error("a batch needs at least one world: no variant was given (0 worlds)")
        self.cache = cache
        self.superset = cache.superset
        # A variant the superset cannot express fails (in its patch), with its index. The
        # worlds are patched into the cache's own model (it is the cache's to patch: no
        # copy of a superset that may hold hundreds of megabytes of meshes); a copy of
        # world 0 keeps the shared fields.
        self._scratch = cache.model(_Index(indices[0]))
        self.model = copy.copy(self._scratch)
        #: The keyframe every world starts at (its id), or None: ``qpos0``.
        self.key = self._key_id(key)
        self._patched = _patched_arrays(self.superset.patch(indices[0]))
        model = self.model
        self._fields = [
            n
            for n in dir(model)
            if not n.startswith("_")
            and isinstance(getattr(model, n, None), np.ndarray)
            and not n.startswith(_STATIC_PREFIXES)
        ]
        self._candidates = sorted((self._patched | set(_DERIVED)) & set(self._fields))
        # Every other field as the batch's first world holds it: a world's row of one is
        # kept only when it differs (no superset patch makes one differ; checked anyway).
        self._others = {
            n: getattr(model, n).tobytes() for n in self._fields if n not in self._candidates
        }
        self._data: Any = None
        self._root_of_geom = model.body_rootid[model.geom_bodyid]
        # mj_setConst per tree (see _trees): per patch layout, its derivation (None: the
        # whole mj_setConst), and the body ids of parked objects' names.
        self._derivations: dict[int, tuple[list, TreeDerivation | None]] = {}
        # A patch of each layout Superset.worlds has given, by layout.
        self._layouts: dict[tuple, Any] = {}
        self._written = [n for n in _WRITTEN if n in self._others]
        self._flags = [n for n in self._written if n.endswith("_sameframe")]
        self._body_ids: dict[str, int] = {}
        # The cache's patch count after this batch's last patch (another count: the
        # scratch model was patched by someone else since, see _rows).
        self._patches_seen = -1
        self._parked_ids: set[int] = set()
        #: Worlds whose derived values came tree by tree (the others: mj_setConst).
        self.derived_by_tree = 0
        bar = progress_of(progress, len(indices), "worlds")
        try:
            rows = []
            for world in self._worlds(indices):
                rows.append(self._rows(world))
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
        varying = sorted({n for r in rows for n in r if n in self._others})
        self.per_world = self._candidates + varying + [f"stat.{s}" for s in _STATS]
        self.arrays = {
            n: np.stack([r[n] if n in r else getattr(model, n) for r in rows]) for n in self.per_world
        }
        self.parked_geoms = np.stack([r["parked_geoms"] for r in rows])
        #: Every world's keyframes as its own patched model holds them (a key's rows for
        #: an object's free joint are its pose in that world, placed or parked):
        #: ``key_qpos`` ``(nworld, nkey, nq)``, ``key_qvel``, ``key_act``, ``key_ctrl``,
        #: ``key_mpos``, ``key_mquat``, ``key_time``; empty without keyframes.
        self.keys = {n: np.stack([r[n] for r in rows]) for n in _KEYS if n in rows[0]}
        self.world_variant = np.array(indices, dtype=np.int64)
        self._warp: Any = None
        self._mjx: Any = None
        self._mjx_shared: Any = None
        self._mjx_impl: str | None = None

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
            i = self.cache._mujoco.mj_name2id(model, self.cache._mujoco.mjtObj.mjOBJ_KEY, key)
            if i < 0:
                names = [model.key(k).name for k in range(model.nkey)]
                raise _error(f"the scene has no keyframe '{key}' (its keyframes: {names})")
            return int(i)
        i = int(key)
        if not 0 <= i < model.nkey:
            raise _error(f"keyframe {i} is out of range: the scene has {model.nkey}")
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
                    if len(self._layouts) >= 64:
                        self._layouts.clear()
                    self._layouts[key] = self.superset.patch(index)
                patches[layout] = self._layouts[key]
            for index, (layout, numbers, strings, parked) in zip(part, worlds):
                yield index, numbers, strings, parked, patches[layout]

    def _rows(self, world: tuple) -> dict[str, np.ndarray]:
        """Every field of the superset patched for one world (``_worlds``), its
        statistics, its parked geoms; a parked geom that touches anything at the initial
        pose is an error."""
        index, numbers, strings, parked_names, patch0 = world
        ids = self._body_ids
        parked_roots = []
        for name in parked_names:
            i = ids.get(name)
            if i is None:
                i = ids[name] = self._scratch.body(name).id
            parked_roots.append(i)
        self._parked_ids = set(parked_roots)
        by_tree = self.derived_by_tree
        if self.cache.patches != self._patches_seen:
            self._forget()  # the model was patched by someone else since
        model = self.cache._apply_world(
            self._scratch, (index, numbers, strings, parked_names), patch0, self._derive
        )
        self._patches_seen = self.cache.patches
        out = {n: getattr(model, n).copy() for n in self._candidates}
        # mj_setConst may write any field (none differs for a superset patch); derived
        # tree by tree, only the patch and its bodies' little models write.
        if self.derived_by_tree == by_tree:
            others = self._others
        elif self._plan_of_scratch().bodies:
            others = self._written
        else:
            others = self._flags
        for n in others:
            value = getattr(model, n)
            if value.tobytes() != self._others[n]:
                out[n] = value.copy()
        for s in _STATS:
            out[f"stat.{s}"] = np.array(getattr(model.stat, s), dtype=np.float64)
        if model.nkey:
            for n in _KEYS:
                out[n] = getattr(model, n).copy()
        mujoco = self.cache._mujoco
        parked = np.isin(self._root_of_geom, parked_roots)
        out["parked_geoms"] = parked
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
            raise _error(
                f"variant {index}: parked geom '{model.geom(a).name or a}' (object "
                f"'{model.body(int(self._root_of_geom[a])).name}') touches geom "
                f"'{model.geom(b).name or b}': its parking cell is within reach"
            )
        return out

    def _plan_of_scratch(self) -> Any:
        return self.cache._plans[id(self._scratch)]

    def _derive(self, model: Any, data: Any, layout: list) -> bool:
        """What mj_setConst derives, tree by tree where the patch's layout allows
        (:class:`TreeDerivation`, the same bits), else mj_setConst; whether ``data`` was
        left at qpos0's kinematics (see :meth:`TreeDerivation.__call__`)."""
        entry = self._derivations.get(id(layout))
        if entry is None or entry[0] is not layout:
            if len(self._derivations) >= 64:
                self._derivations.clear()
            built = TreeDerivation.build(self.cache._mujoco, model, layout) if self._by_tree else None
            entry = (layout, built)
            self._derivations[id(layout)] = entry
        derivation = entry[1]
        if derivation is None:
            self.cache._mujoco.mj_setConst(model, data)
            return False
        self.derived_by_tree += 1
        return derivation(model, data, self._parked_ids)

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
                raise _error(f"world {w} is not in the batch (0 to {self.nworld - 1})")
        rows = [self._rows(world) for world in self._worlds(indices)]
        for i, r in zip(indices, rows):
            for n in r:
                if n not in self.arrays and n != "parked_geoms" and n not in self.keys:
                    raise _error(
                        f"variant {i}: field {n} differs from the batch's, where all worlds "
                        "share one value (build a new WorldBatch)"
                    )
        for w, i, r in zip(worlds, indices, rows):
            for n in self.per_world:
                self.arrays[n][w] = r[n] if n in r else getattr(self.model, n)
            for n in self.keys:
                self.keys[n][w] = r[n]
            self.parked_geoms[w] = r["parked_geoms"]
            self.world_variant[w] = i
        mask = np.zeros(self.nworld, dtype=bool)
        mask[worlds] = True
        if self._warp is not None:
            import mujoco_warp as mjw
            import warp as wp

            m, d, specs = self._warp
            for name, rows_ in self._warp_rows(specs).items():
                getattr(m, name).assign(wp.array(rows_, dtype=specs[name].dtype))
            self.reset_mjwarp(mask)
        return mask

    def reset_mjwarp(self, worlds: Any = None) -> None:
        """The MuJoCo Warp data of :meth:`to_mjwarp` back at the initial state of the
        worlds given (a mask or indices; None: every world): ``reset_data``, then with
        ``key`` each world's own rows of the keyframe (MuJoCo Warp's
        ``reset_data_keyframe`` would give every world world 0's rows: its ``key_qpos``
        is one for all worlds, and a key's rows for an object are its pose in that
        world, placed or parked)."""
        import mujoco_warp as mjw
        import warp as wp

        if self._warp is None:
            raise ValueError("reset_mjwarp() needs to_mjwarp() first")
        mask = np.zeros(self.nworld, dtype=bool)
        if worlds is None:
            mask[:] = True
        else:
            worlds = np.asarray(worlds)
            mask[worlds if worlds.dtype != bool else np.flatnonzero(worlds)] = True
        m, d, _specs = self._warp
        mjw.reset_data(m, d, reset=wp.array(mask, dtype=bool))
        self._warp_start(d, mask)

    # ---------------------------------------------------------------- MuJoCo Warp
    def _warp_specs(self) -> dict[str, Any]:
        """Per-world fields MuJoCo Warp reads, by name, with their array specs; an error
        naming a per-world field Warp has but cannot vary per world. Fields Warp does not
        have (``dof_M0``, the statistics: Warp scales its solver by each world's mass
        matrix instead) are left out."""
        import mujoco_warp as mjw

        types = {f.name: f.type for f in dataclasses.fields(mjw.Model)}
        specs = {}
        for name in self.per_world + ["geom_dataid"]:
            spec = types.get(name)
            if spec is None:
                continue
            shape = getattr(spec, "shape", ())
            batched = bool(shape) and shape[0] == "*"
            if not batched:
                sleep = self.model.opt.enableflags & self.cache._mujoco.mjtEnableBit.mjENBL_SLEEP
                if name in _WARP_SLEEP_ONLY and not sleep:
                    continue
                rows = self.arrays.get(name)
                if rows is not None and not (rows == rows[0]).all():
                    raise _error(
                        f"MuJoCo Warp cannot vary {name} per world (its Model field is shared "
                        "by all worlds), and the batch's worlds differ in it"
                    )
                continue
            specs[name] = spec
        return specs

    def _warp_rows(self, specs: dict[str, Any]) -> dict[str, np.ndarray]:
        out = {}
        for name, spec in specs.items():
            if name == "geom_dataid":
                # A parked mesh geom is absent from its world (mjlab's switch for padded
                # slots): no collision work for it, whatever its pose.
                rows = np.tile(self.model.geom_dataid, (self.nworld, 1))
                mesh = self.model.geom_type == self.cache._mujoco.mjtGeom.mjGEOM_MESH
                rows[self.parked_geoms & mesh[None, :]] = -1
            else:
                rows = self.arrays[name]
            dtype_shape = getattr(spec.dtype, "_shape_", ())
            rows = rows.reshape((self.nworld,) + rows.shape[1:-1] + (-1,)) if dtype_shape else rows
            out[name] = rows
        return out

    def warp_sizes(self) -> dict[str, int]:
        """``nconmax`` and ``njmax`` for :meth:`to_mjwarp` when not given, from the model.

        MuJoCo Warp's own defaults count none of the superset's objects (48 contacts and
        64 constraint rows for a model without height fields, whatever it holds): lift5's
        worlds need up to 24 contacts and 140 rows (measured, scripts/sim_gap.py). Here:
        Warp's default contacts plus ``_CONTACTS_PER_OBJECT`` for each free body a world
        places (its largest count over the worlds); rows: that many contacts times the
        rows a contact of the model's largest ``condim`` takes (``2 (condim - 1)``
        pyramidal, ``condim`` elliptic), plus a row for every equality's
        (6: a weld), limited joint or tendon and dof or tendon with friction loss. An
        estimate, not a bound: a world past it sets its bit of Warp's ``d.overflow``
        (contacts beyond are dropped); give ``nconmax``/``njmax`` then."""
        mujoco = self.cache._mujoco
        m = self.model
        free = m.jnt_bodyid[m.jnt_type == mujoco.mjtJoint.mjJNT_FREE]
        placed = 0
        for w in range(self.nworld):
            parked_roots = set(m.body_rootid[m.geom_bodyid[self.parked_geoms[w]]].tolist())
            placed = max(placed, sum(int(m.body_rootid[b]) not in parked_roots for b in free))
        colliding = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
        condim = int(max(m.geom_condim[colliding].max(initial=1), m.pair_dim.max(initial=1)))
        elliptic = m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
        rows = condim if elliptic or condim == 1 else 2 * (condim - 1)
        fixed = (
            6 * m.neq
            + int(m.jnt_limited.sum())
            + int(m.tendon_limited.sum())
            + int((m.dof_frictionloss > 0).sum())
            + int((m.tendon_frictionloss > 0).sum())
        )
        from mujoco_warp._src.io import _default_nconmax

        nconmax = _default_nconmax(m) + _CONTACTS_PER_OBJECT * placed
        return {"nconmax": int(nconmax), "njmax": int(nconmax * rows + fixed)}

    def to_mjwarp(self, **make_data: Any) -> tuple[Any, Any]:
        """A ``mujoco_warp`` ``Model`` with every per-world field one row per world (its
        dtypes: float32 vectors and quaternions, int32 ids) and a ``Data`` of ``nworld``
        worlds at their initial pose (``reset_data``: each world's ``qpos0``).
        ``make_data`` goes to ``mujoco_warp.make_data``; ``nconmax`` and ``njmax`` default
        to :meth:`warp_sizes` (Warp's own fit one robot alone)."""
        import mujoco_warp as mjw
        import warp as wp

        if "naconmax" not in make_data:
            for key, value in self.warp_sizes().items():
                make_data.setdefault(key, value)
        specs = self._warp_specs()
        rows = self._warp_rows(specs)
        m = mjw.put_model(self.model)
        for name, r in rows.items():
            # Warp converts MuJoCo's float64 and int32 rows to the field's own dtype.
            arr = wp.array(r, dtype=specs[name].dtype)
            arr._is_batched = True
            setattr(m, name, arr)
        d = mjw.make_data(self.model, nworld=self.nworld, **make_data)
        self._warp = (m, d, specs)
        self.reset_mjwarp()
        return m, d

    def _warp_start(self, d: Any, mask: np.ndarray) -> None:
        """With ``key``: the worlds of ``mask`` at their own rows of the keyframe (after
        ``reset_data``, which sets ``qpos0``). MuJoCo Warp's ``reset_data_keyframe``
        would not do: its ``key_qpos`` is one for all worlds (world 0's, whose object
        poses are other worlds' parked or placed ones)."""
        if self.key is None:
            return
        import warp as wp

        for name, rows in self.initial().items():
            arr = getattr(d, name, None)
            if arr is None or rows.size == 0:
                continue
            value = arr.numpy()
            value[mask] = rows[mask].reshape(value[mask].shape)
            arr.assign(wp.array(value, dtype=arr.dtype))

    # ---------------------------------------------------------------- MJX
    def to_mjx(self, impl: str | None = None) -> tuple[Any, Any]:
        """An MJX model whose per-world leaves have a leading world axis (MJX's dtypes:
        float32 unless JAX runs in x64) and the matching ``in_axes`` (0 for those leaves,
        None elsewhere): ``jax.vmap(mjx.step, in_axes=(in_axes, 0))(model, data)``. The
        first call runs ``mjx.put_model``; later ones (after :meth:`assign`) only replace
        the per-world leaves. Fields MJX does not have are left out; one it holds as a
        static (NumPy) array cannot vary per world: an error names it. ``impl`` goes to
        ``mjx.put_model`` ("jax", "warp"...)."""
        import jax
        import jax.numpy as jnp
        from mujoco import mjx

        if self._mjx is not None and not self._mjx_flags_hold():
            self._mjx = None  # a reassigned world needs the general path somewhere new
        if self._mjx is None:
            shared = copy.copy(self.model)
            for name in _BOUNDS:
                if name in self.arrays:
                    getattr(shared, name)[...] = self.arrays[name].max(axis=0)
            for name in _FLAGS:
                if name in self.arrays:
                    rows = self.arrays[name]
                    getattr(shared, name)[...] = np.where((rows == rows[0]).all(axis=0), rows[0], 0)
            self._mjx = mjx.put_model(shared, impl=impl)
            self._mjx_shared = shared
            self._mjx_impl = impl
        base = self._mjx
        replace: dict[str, Any] = {}
        for name in self.per_world:
            path = name if not name.startswith("stat.") else name
            leaf = _mjx_leaf(base, path)
            if leaf is None:
                continue
            rows = self.arrays[name]
            if not isinstance(leaf, jax.Array):
                if (rows == rows[0]).all() or name in _BOUNDS or name in _FLAGS:
                    continue
                raise _error(
                    f"MJX cannot vary {name} per world (put_model keeps it as a static NumPy "
                    "array), and the batch's worlds differ in it"
                )
            replace[_mjx_path(base, path)] = jnp.asarray(rows.reshape((self.nworld,) + leaf.shape), dtype=leaf.dtype)
        model = base.tree_replace(replace)
        in_axes = jax.tree_util.tree_map(lambda _: None, base)
        in_axes = in_axes.tree_replace({k: 0 for k in replace})
        return model, in_axes

    def _mjx_flags_hold(self) -> bool:
        """Whether the same-frame flags MJX was put with hold in every world: each one
        either every world's or 0 (the general computation)."""
        for name in _FLAGS:
            if name in self.arrays:
                put = getattr(self._mjx_shared, name)
                if not ((put == 0) | (self.arrays[name] == put).all(axis=0)).all():
                    return False
        return True

    def mjx_data(self, **make_data: Any) -> Any:
        """An MJX ``Data`` of ``nworld`` worlds (leading axis) at their initial pose, of the
        model's ``impl``; ``make_data`` goes to ``mjx.make_data`` (``nconmax``...)."""
        import jax
        import jax.numpy as jnp
        from mujoco import mjx

        if self._mjx is None:
            self.to_mjx()
        one = mjx.make_data(self.model, impl=self._mjx_impl, **make_data)
        data = jax.tree_util.tree_map(lambda x: jnp.broadcast_to(x, (self.nworld,) + x.shape), one)
        start = self.initial()
        if self.key is None:
            start = {"qpos": start["qpos"]}
        return data.replace(
            **{
                name: jnp.asarray(rows.reshape((self.nworld,) + getattr(one, name).shape), dtype=getattr(one, name).dtype)
                for name, rows in start.items()
                if hasattr(one, name)
            }
        )

    def mjx_reset(self, data: Any, mask: np.ndarray) -> Any:
        """``data`` with the worlds of ``mask`` back at their initial pose (after
        :meth:`assign`); the others as they were."""
        import jax
        import jax.numpy as jnp

        fresh = self.mjx_data()
        keep = jnp.asarray(mask)

        def pick(new, old):
            m = keep.reshape((-1,) + (1,) * (old.ndim - 1))
            return jnp.where(m, new, old)

        return jax.tree_util.tree_map(pick, fresh, data)

    # ---------------------------------------------------------------- MuJoCo (CPU)
    def mujoco_models(self) -> list[Any]:
        """One ``MjModel`` per world: the superset patched for the world's variant (what
        ``ModelCache(scene, superset=True).model`` gives), for
        ``mujoco.batch.Batch.set_models`` or a loop of ``mj_step``."""
        out = []
        for i in self.world_variant:
            out.append(copy.copy(self.cache.apply(_Index(int(i)), self._scratch)))
        return out

    def _forget(self) -> None:
        """The scratch model was patched another way: every tree is derived again."""
        for _layout, derivation in self._derivations.values():
            if derivation is not None:
                derivation.forget()


def _mjx_path(model: Any, name: str) -> str:
    if name.startswith("stat."):
        return name
    if name in {f.name for f in dataclasses.fields(model)}:
        return name
    return f"_impl.{name}"


def _mjx_leaf(model: Any, name: str) -> Any:
    obj = model
    for part in _mjx_path(model, name).split("."):
        fields = {f.name for f in dataclasses.fields(obj)} if dataclasses.is_dataclass(obj) else set()
        if part not in fields:
            return None
        obj = object.__getattribute__(obj, part)
    return obj
