"""MuJoCo Warp for a :class:`mjcf_forge.batch.WorldBatch`: its per-world fields as a
``mujoco_warp`` ``Model`` (fields whose spec starts with ``*`` get one row per world, read
at ``worldid % rows``) and ``Data``, its sizes, resets. ``mujoco_warp`` is imported only
here, by the methods that need it."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ._cache import mujoco_of
from ._errors import error

# Fields MuJoCo Warp holds for all worlds but reads only when sleeping is enabled (a
# rotational dof's length is its body's size, which for a massless root body depends on
# where the body stands: parked or placed).
_WARP_SLEEP_ONLY = ("dof_length",)
# Contacts a placed free object may have at once in MuJoCo Warp's default sizes (a box on
# a table: 4; lift5's worlds: at most 24 for 5 objects and the gripper, measured).
_CONTACTS_PER_OBJECT = 16


class WarpWorlds:
    """The MuJoCo Warp side of :class:`mjcf_forge.batch.WorldBatch` (a mixin: it reads
    the batch's ``model``, ``arrays``, ``per_world``, ``parked_geoms`` and ``initial()``)."""

    _warp: Any
    model: Any
    arrays: dict[str, np.ndarray]
    per_world: list[str]
    parked_geoms: np.ndarray
    cache: Any

    def _warp_reassigned(self, mask: np.ndarray) -> None:
        """The Warp model's per-world rows written again and the worlds of ``mask``
        reset, after :meth:`WorldBatch.assign`."""
        import warp as wp

        m, _d, specs = self._warp
        for name, rows in self._warp_rows(specs).items():
            getattr(m, name).assign(wp.array(rows, dtype=specs[name].dtype))
        self.reset_mjwarp(mask)

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

    def _warp_specs(self, mjw: Any = None) -> dict[str, Any]:
        """Per-world fields MuJoCo Warp reads, by name, with their array specs; an error
        naming a per-world field Warp has but cannot vary per world. Fields Warp does not
        have (``dof_M0``, the statistics: Warp scales its solver by each world's mass
        matrix instead) are left out. ``mjw``: the ``mujoco_warp`` module (MJX bundles
        its own)."""
        if mjw is None:
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
                sleep = self.model.opt.enableflags & mujoco_of(self.cache).mjtEnableBit.mjENBL_SLEEP
                if name in _WARP_SLEEP_ONLY and not sleep:
                    continue
                rows = self.arrays.get(name)
                if rows is not None and not (rows == rows[0]).all():
                    raise error(
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
                mesh = self.model.geom_type == mujoco_of(self.cache).mjtGeom.mjGEOM_MESH
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
        worlds need up to 24 contacts and 140 rows (measured, benches/compare/sim_gap.py). Here:
        Warp's default contacts plus ``_CONTACTS_PER_OBJECT`` for each free body a world
        places (its largest count over the worlds); rows: that many contacts times the
        rows a contact of the model's largest ``condim`` takes (``2 (condim - 1)``
        pyramidal, ``condim`` elliptic), plus a row for every equality's
        (6: a weld), limited joint or tendon and dof or tendon with friction loss. An
        estimate, not a bound: a world past it sets its bit of Warp's ``d.overflow``
        (contacts beyond are dropped); give ``nconmax``/``njmax`` then."""
        mujoco = mujoco_of(self.cache)
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
        try:
            from mujoco_warp._src.io import _default_nconmax
        except ImportError:  # MJX's own copy of MuJoCo Warp (to_mjx(impl="warp"))
            from mujoco.mjx.third_party.mujoco_warp._src.io import _default_nconmax
        fixed = (
            6 * m.neq
            + int(m.jnt_limited.sum())
            + int(m.tendon_limited.sum())
            + int((m.dof_frictionloss > 0).sum())
            + int((m.tendon_frictionloss > 0).sum())
        )
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
