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

import collections
import math
import weakref
from typing import Any

import numpy as np

from ._mjcf_forge import MjcfError

# The compiled model's statistics, as <statistic> names them.
_STATISTICS = ("meaninertia", "meanmass", "meansize", "extent", "center")

# Integer arrays that, with the sizes and the names, tell one structure from another.
_SIGNATURE_ARRAYS = (
    "body_parentid",
    "jnt_type",
    "geom_type",
    "geom_bodyid",
    "geom_dataid",
    "mesh_vertnum",
    "tex_width",
)


def _error(message: str) -> MjcfError:
    err = MjcfError(message)
    err.errors = [message]
    return err


def _signature(model: Any) -> tuple:
    """Sizes, names and the integer arrays that decide a model's structure."""
    sizes = tuple(
        getattr(model, a)
        for a in sorted(dir(model))
        if a.startswith("n") and isinstance(getattr(model, a, None), int)
    )
    arrays = tuple(
        getattr(model, a).tobytes() for a in _SIGNATURE_ARRAYS if hasattr(model, a)
    )
    return sizes, bytes(model.names), arrays


class _Plan:
    """How to patch one model object: its structure key and where each entry of the last
    patch lands (array name and rows). It holds no array view and no ``MjData``: both keep
    their model alive, and plans are kept per model weakly."""

    __slots__ = ("key", "fields", "targets")

    def __init__(self, key: str) -> None:
        self.key = key
        self.fields: list[tuple[str, str, str]] | None = None
        self.targets: list[tuple[str, Any]] = []


# The array prefix of each accessor's fields in MjModel.
_PREFIX = {
    "body": "body_",
    "joint": "jnt_",
    "geom": "geom_",
    "site": "site_",
    "camera": "cam_",
    "light": "light_",
    "material": "mat_",
}
_OBJ = {
    "body": "mjOBJ_BODY",
    "joint": "mjOBJ_JOINT",
    "geom": "mjOBJ_GEOM",
    "site": "mjOBJ_SITE",
    "camera": "mjOBJ_CAMERA",
    "light": "mjOBJ_LIGHT",
    "material": "mjOBJ_MATERIAL",
}
_COUNT = {
    "body": "nbody",
    "joint": "njnt",
    "geom": "ngeom",
    "site": "nsite",
    "camera": "ncam",
    "light": "nlight",
    "material": "nmat",
}
# Joint fields that are per degree of freedom or per qpos coordinate.
_DOF_FIELDS = ("damping", "armature", "frictionloss")
_QPOS_FIELDS = ("qpos0", "qpos_spring")
_JOINT_QPOS = {0: 7, 1: 4, 2: 1, 3: 1}  # free, ball, slide, hinge


def _targets(mujoco: Any, model: Any, patch: list) -> list[tuple[str, Any]]:
    """Where every entry of ``patch`` lands in ``model``: (array name, rows)."""
    targets = []
    for obj, name, field, _ in patch:
        if isinstance(name, int):
            i = name if name < getattr(model, _COUNT[obj]) else -1
        else:
            i = mujoco.mj_name2id(model, getattr(mujoco.mjtObj, _OBJ[obj]), name)
        if i < 0:
            raise _error(
                f"the patch names {obj} '{name}', which the compiled model does not have"
            )
        if obj == "joint" and field in _DOF_FIELDS:
            adr = int(model.jnt_dofadr[i])
            n = _JOINT_QPOS[int(model.jnt_type[i])]
            n = {7: 6, 4: 3}.get(n, n)
            targets.append((f"dof_{field}", slice(adr, adr + n)))
        elif obj == "joint" and field in _QPOS_FIELDS:
            adr = int(model.jnt_qposadr[i])
            n = _JOINT_QPOS[int(model.jnt_type[i])]
            targets.append((field, slice(adr, adr + n)))
        else:
            array = _PREFIX[obj] + field
            # A one-component field of a one-dimensional array: its row as a slice.
            rows = i if getattr(model, array).ndim > 1 else slice(i, i + 1)
            targets.append((array, rows))
    return targets


def _statistics(mujoco: Any, model: Any, data: Any) -> None:
    """The model statistics and dof lengths the compiler derives from the model at qpos0
    (``mj_setConst`` of MuJoCo 3.17 and 4.0 leaves them), computed as the compiler does:
    the same operations in the same order, so the same bits."""
    data.qpos[:] = model.qpos0
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    mujoco.mj_makeM(model, data)
    stat = model.stat
    # Bounding box of bodies, inertial frames, joint anchors, sites and geoms.
    lo = [1e10, 1e10, 1e10]
    hi = [-1e10, -1e10, -1e10]
    size = model.geom_size
    rbound = model.geom_rbound.copy()
    for g in np.flatnonzero(rbound <= 0):
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE:
            if size[g, 0] or size[g, 1]:
                rbound[g] = max(size[g, 0], size[g, 1]) * 0.1
            else:
                rbound[g] = 0.01
        elif model.geom_type[g] == mujoco.mjtGeom.mjGEOM_HFIELD:
            h = model.hfield_size[model.geom_dataid[g]]
            rbound[g] = max(h[0], max(h[1], max(h[2], h[3]))) * 0.1
        else:
            rbound[g] = 0.0
    r = rbound[:, None]
    for points in (
        data.xpos[1:],
        data.xipos[1:],
        data.xanchor,
        data.site_xpos,
        data.geom_xpos - r,
        data.geom_xpos + r,
    ):
        if len(points):
            lo = np.minimum(lo, points.min(axis=0))
            hi = np.maximum(hi, points.max(axis=0))
    stat.center[:] = (lo + hi) * 0.5
    extent = stat.extent
    if hi[0] > lo[0]:
        d = hi - lo
        extent = max(1e-5, max(d[0], max(d[1], d[2])))
    # Body sizes: the largest com-joint distance, then geom bounds around the com.
    nbody = model.nbody
    body = [0.0] * nbody
    xipos, xanchor, gxpos = data.xipos, data.xanchor, data.geom_xpos
    parent = model.body_parentid
    for j, b in enumerate(model.jnt_bodyid):
        for i in (int(b), int(parent[b])):
            a, c = xipos[i], xanchor[j]
            dist = math.sqrt(
                (a[0] - c[0]) * (a[0] - c[0])
                + (a[1] - c[1]) * (a[1] - c[1])
                + (a[2] - c[2]) * (a[2] - c[2])
            )
            body[i] = max(body[i], dist)
    body[0] = 0.0
    adr, num, grb = model.body_geomadr, model.body_geomnum, model.geom_rbound
    for i in range(1, nbody):
        a = xipos[i]
        for g in range(adr[i], adr[i] + num[i]):
            if grb[g] > 0:
                c = gxpos[g]
                dist = math.sqrt(
                    (a[0] - c[0]) * (a[0] - c[0])
                    + (a[1] - c[1]) * (a[1] - c[1])
                    + (a[2] - c[2]) * (a[2] - c[2])
                )
                body[i] = max(body[i], float(grb[g]) + dist)
    if nbody > 1:
        meansize = 0.0
        for i in range(1, nbody):
            body[i] = max(body[i], 1e-5)
            meansize += body[i] / (nbody - 1)
        stat.meansize = meansize
    # Rotational dofs take their body's size.
    length = model.dof_length
    for i in range(model.nv):
        jnt = model.dof_jntid[i]
        kind = model.jnt_type[jnt]
        rotational = kind in (1, 3) or (kind == 0 and i - model.jnt_dofadr[jnt] >= 3)
        length[i] = body[model.dof_bodyid[i]] if rotational else 1.0
    stat.extent = max(extent, 2 * stat.meansize)
    if nbody > 1:
        mass = 0.0
        for m in model.body_mass[1:]:
            mass += m
        stat.meanmass = mass / (nbody - 1)
    if model.nv:
        inertia = 0.0
        diagonal = model.M_rowadr + model.M_rownnz - 1
        for k in diagonal:
            inertia += data.M[k]
        stat.meaninertia = inertia / model.nv


class ModelCache:
    """Compiled models of a :class:`Scene`'s variants, one per structure, patched per
    variant; bounded in count (``max_models``) and bytes (``max_bytes``: the models, their
    scratch data included), least recently used first out.

    ``cache.model(variant)`` gives a model equal to what MuJoCo compiles from
    ``variant.xml``: the cached model of the variant's structure, patched in place, or on
    a miss the variant compiled (and kept). The model belongs to the cache: the next call
    for the same structure patches it again (``copy.copy`` it to keep one).
    ``cache.apply(variant, model)`` patches a model of your own in place (an environment's
    ``reset``: no allocation, no copy); it must have the variant's structure, else an
    :class:`MjcfError` says so.

    >>> import mjcf_forge
    >>> scene = mjcf_forge.Scene.demo()
    >>> cache = mjcf_forge.ModelCache(scene, max_models=4)
    >>> model = cache.model(scene.variant(0))
    >>> model.nbody > 1
    True
    """

    def __init__(self, scene: Any, max_models: int = 8, max_bytes: int | None = None) -> None:
        import mujoco

        if max_models < 1:
            raise ValueError("max_models must be at least 1")
        self._mujoco = mujoco
        self._scene = scene
        self._fixed = list(scene.fixed_statistics)
        self._max_models = max_models
        self._max_bytes = max_bytes
        # Cached models by structure key, least recently used first.
        self._entries: collections.OrderedDict[str, Any] = collections.OrderedDict()
        # Every model patched or handed out: how to patch it (weakly: a user's model may go).
        self._plans: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
        # Signatures of structures seen, kept after their models are evicted.
        self._signatures: dict[str, tuple] = {}
        # Per structure, the scratch MjData mj_setConst is given (it overwrites its qpos):
        # any data of the structure's sizes serves every model of the structure.
        self._scratch: collections.OrderedDict[str, Any] = collections.OrderedDict()
        # Per structure, the <statistic> values the scene fixes (MuJoCo keeps them).
        self._fixed_values: dict[str, list] = {}
        #: Models compiled (misses) and patches applied so far.
        self.compiles = 0
        self.patches = 0

    def __len__(self) -> int:
        return len(self._entries)

    @property
    def nbytes(self) -> int:
        """Bytes held: every cached model and every scratch ``MjData``."""
        return sum(m.nbuffer for m in self._entries.values()) + sum(
            d.nbuffer + d.narena for d in self._scratch.values()
        )

    def _compile(self, variant: Any) -> Any:
        model = self._mujoco.MjModel.from_xml_string(variant.xml)
        self.compiles += 1
        key = variant.structure_key
        self._signatures[key] = _signature(model)
        self._fixed_values[key] = [(s, _copy(getattr(model.stat, s))) for s in self._fixed]
        self._plans[model] = _Plan(key)
        self._entries[key] = model
        self._entries.move_to_end(key)
        while len(self._entries) > 1 and (
            len(self._entries) > self._max_models
            or (self._max_bytes is not None and self.nbytes > self._max_bytes)
        ):
            gone, _ = self._entries.popitem(last=False)
            self._scratch.pop(gone, None)
        return model

    def _patch(self, model: Any, plan: _Plan, variant: Any) -> None:
        mujoco = self._mujoco
        patch = variant.patch
        fields = [(o, n, f) for o, n, f, _ in patch]
        if plan.fields != fields:
            plan.targets = _targets(mujoco, model, patch)
            plan.fields = fields
        for (array, rows), (_, _, field, value) in zip(plan.targets, patch):
            if field == "matid":
                value = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_MATERIAL, value)
            getattr(model, array)[rows] = value
        scratch = self._scratch.get(plan.key)
        if scratch is None:
            scratch = mujoco.MjData(model)
            self._scratch[plan.key] = scratch
            while len(self._scratch) > self._max_models:
                self._scratch.popitem(last=False)
        mujoco.mj_setConst(model, scratch)
        _statistics(mujoco, model, scratch)
        for stat, value in self._fixed_values.get(plan.key, ()):
            if hasattr(value, "copy"):
                getattr(model.stat, stat)[...] = value
            else:
                setattr(model.stat, stat, value)
        self.patches += 1

    def model(self, variant: Any) -> Any:
        """A compiled model equal to MuJoCo's compile of ``variant.xml`` (see the class)."""
        key = variant.structure_key
        model = self._entries.get(key)
        if model is None:
            return self._compile(variant)
        self._entries.move_to_end(key)
        self._patch(model, self._plans[model], variant)
        return model

    def apply(self, variant: Any, model: Any) -> Any:
        """Patches ``model`` (of ``variant``'s structure) in place into ``variant``'s
        compiled model; returns it. Raises :class:`MjcfError` when its structure differs."""
        key = variant.structure_key
        plan = self._plans.get(model)
        if plan is None:
            if key not in self._signatures:
                # The structure's first sight: its compile (kept) says what it is.
                self._compile(variant)
            if _signature(model) != self._signatures[key]:
                raise _error(
                    f"the model does not have the structure of variant {variant.index} "
                    f"(key {key}): its sizes, names or element types differ"
                )
            plan = _Plan(key)
            self._plans[model] = plan
        elif plan.key != key:
            raise _error(
                f"the model has structure {plan.key}, variant {variant.index} has {key}: "
                "a patch cannot change a structure (cache.model(variant) compiles it)"
            )
        self._patch(model, plan, variant)
        return model
