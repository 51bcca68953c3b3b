"""MJX for a :class:`mjcf_forge.batch.WorldBatch`: an MJX model whose per-world leaves
have a leading world axis, the ``in_axes`` to ``jax.vmap`` it, and batched ``Data``.
``jax`` and ``mujoco.mjx`` are imported only here, by the methods that need them."""

from __future__ import annotations

import copy
import dataclasses
from typing import Any

import numpy as np

from ._errors import error

# Bounds a simulator reads only to cull collision candidates (the narrow phase reads the
# geoms' own margins): where a simulator holds one for all worlds, the largest of the
# worlds' values is exact.
_BOUNDS = ("body_margin",)
# Shortcuts MJX takes per body, geom or site where its frame is its body's or inertial
# frame (kept as static arrays by put_model): where the worlds differ, the general
# computation (0, mjSAMEFRAME_NONE) serves every world (the same numbers where a frame
# is exactly its body's; MuJoCo's flags allow 1e-6 of difference for a shortcut).
_FLAGS = ("body_sameframe", "geom_sameframe", "site_sameframe")


class MjxWorlds:
    """The MJX side of :class:`mjcf_forge.batch.WorldBatch` (a mixin: it reads the batch's
    ``model``, ``arrays``, ``per_world``, ``key`` and ``initial()``)."""

    _mjx: Any
    _mjx_shared: Any
    _mjx_impl: str | None
    model: Any
    arrays: dict[str, np.ndarray]
    per_world: list[str]
    key: int | None

    def to_mjx(self, impl: str | None = None) -> tuple[Any, Any]:
        """An MJX model whose per-world leaves have a leading world axis (MJX's dtypes:
        float32 unless JAX runs in x64) and the matching ``in_axes`` (0 for those leaves,
        None elsewhere): ``jax.vmap(mjx.step, in_axes=(in_axes, 0))(model, data)``. The
        first call runs ``mjx.put_model``; later ones (after :meth:`assign`) only replace
        the per-world leaves. Fields MJX does not have are left out; one it holds as a
        static (NumPy) array cannot vary per world: an error names it. ``impl`` goes to
        ``mjx.put_model``: "jax" (MJX's own, the default on CPU) or "warp" (MuJoCo Warp's
        kernels under MJX, on CPU too: its collisions include the cylinder and mesh pairs
        MJX's JAX collision lacks); with "warp" the per-world leaves are those MuJoCo Warp
        reads per world (:meth:`to_mjwarp`'s), ``geom_dataid`` aside (MJX holds one for
        all worlds). Without ``impl``, the one of the model put before, if any."""
        import jax
        import jax.numpy as jnp
        from mujoco import mjx

        if impl is None and self._mjx is not None:
            impl = self._mjx_impl  # after assign(): the implementation put before
        if self._mjx is not None and (impl != self._mjx_impl or not self._mjx_flags_hold()):
            # Another implementation, or a reassigned world needs the general path
            # somewhere new.
            self._mjx = None
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
        for name in self._mjx_per_world():
            leaf = _mjx_leaf(base, name)
            if leaf is None:
                continue
            rows = self.arrays[name]
            if not isinstance(leaf, jax.Array):
                if (rows == rows[0]).all() or name in _BOUNDS or name in _FLAGS:
                    continue
                raise error(
                    f"MJX cannot vary {name} per world (put_model keeps it as a static NumPy "
                    "array), and the batch's worlds differ in it"
                )
            replace[_mjx_path(base, name)] = jnp.asarray(rows.reshape((self.nworld,) + leaf.shape), dtype=leaf.dtype)
        model = base.tree_replace(replace)
        in_axes = jax.tree_util.tree_map(lambda _: None, base)
        in_axes = in_axes.tree_replace({k: 0 for k in replace})
        return model, in_axes

    def _mjx_warp(self) -> bool:
        """Whether the MJX model runs MuJoCo Warp's kernels (``impl="warp"``)."""
        return str(getattr(self._mjx_impl, "value", self._mjx_impl)) == "warp"

    def _mjx_per_world(self) -> list[str]:
        """The per-world fields the MJX model's implementation reads per world."""
        if not self._mjx_warp():
            return self.per_world
        from mujoco.mjx.third_party import mujoco_warp

        # MJX's put_model keeps one geom_dataid for all worlds: parked objects stand in
        # their own cells out of reach, so their mesh geoms find no partner anyway.
        return [n for n in self._warp_specs(mujoco_warp) if n != "geom_dataid"]

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
        model's ``impl``; ``make_data`` goes to ``mjx.make_data``. With ``impl="warp"``,
        ``naconmax`` (contacts of all worlds together) and ``njmax`` (rows per world)
        default to :meth:`warp_sizes`'s."""
        import jax
        import jax.numpy as jnp
        from mujoco import mjx

        if self._mjx is None:
            self.to_mjx()
        if self._mjx_warp():
            sizes = self.warp_sizes()
            make_data.setdefault("naconmax", sizes["nconmax"] * self.nworld)
            make_data.setdefault("njmax", sizes["njmax"])
        one = mjx.make_data(self.model, impl=self._mjx_impl, **make_data)
        start = self.initial()
        if self.key is None:
            start = {"qpos": start["qpos"]}
        rows = {
            name: jnp.asarray(r.reshape((self.nworld,) + getattr(one, name).shape), dtype=getattr(one, name).dtype)
            for name, r in start.items()
            if hasattr(one, name)
        }
        # vmap, not a broadcast of every leaf: MJX keeps some leaves (empty buffers) as
        # static shapes, which must stay as make_data gave them.
        return jax.vmap(lambda world: one.replace(**world))(rows)

    def mjx_reset(self, data: Any, mask: np.ndarray) -> Any:
        """``data`` with the worlds of ``mask`` back at their initial pose (after
        :meth:`assign`); the others as they were."""
        import jax
        import jax.numpy as jnp

        fresh = self.mjx_data()
        # MJX's Data.where, world by world: with impl="warp" the worlds' joint contact and
        # constraint buffers stay as they are.
        return jax.vmap(lambda reset, new, old: old.where(reset, new))(jnp.asarray(mask), fresh, data)


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
