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
import copy
import itertools
import os
from typing import Any, Callable

import numpy as np

from ._mjcf_forge import MjcfError, Scene
from ._progress import progress_of

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


# Sizes mj_setConst recomputes from patched values (bodies with gravity compensation).
_SET_BY_PATCHING = frozenset({"ngravcomp"})


def _error(message: str) -> MjcfError:
    err = MjcfError(message)
    err.errors = [message]
    return err


def _signature(model: Any) -> tuple:
    """Sizes, names and the integer arrays that decide a model's structure."""
    sizes = tuple(
        getattr(model, a)
        for a in sorted(dir(model))
        if a.startswith("n")
        and a not in _SET_BY_PATCHING
        and isinstance(getattr(model, a, None), int)
    )
    arrays = tuple(
        getattr(model, a).tobytes() for a in _SIGNATURE_ARRAYS if hasattr(model, a)
    )
    return sizes, bytes(model.names), arrays


# Model arrays no patch changes (meshes, textures, height fields, skins, flexes, bounding
# volumes, names): left out of batch().
_STATIC_PREFIXES = (
    "mesh_", "tex_", "hfield_", "skin_", "flex", "bvh_", "oct_", "name", "text_", "paths",
    "tuple_", "numeric_", "plugin", "sensor_", "key_",
)


def _evict(
    entries: "collections.OrderedDict[str, Any]",
    max_models: int,
    max_bytes: int | None,
    nbytes: Callable[[], int],
    dropped: Callable[[str, Any], None],
) -> None:
    """The bound both caches keep: the least recently used entries out (``dropped`` is
    told of each) while there are more than ``max_models`` or ``nbytes()`` is above
    ``max_bytes``; the most recent one always stays."""
    while len(entries) > 1 and (
        len(entries) > max_models or (max_bytes is not None and nbytes() > max_bytes)
    ):
        key, gone = entries.popitem(last=False)
        dropped(key, gone)


def _copy(value: Any) -> Any:
    return value.copy() if hasattr(value, "copy") else value


# The array prefix of each accessor's fields in MjModel, its object type and its count.
_PREFIX = {
    "body": "body_",
    "joint": "jnt_",
    "geom": "geom_",
    "site": "site_",
    "camera": "cam_",
    "light": "light_",
    "material": "mat_",
    "actuator": "actuator_",
}
_OBJ = {
    "body": "mjOBJ_BODY",
    "joint": "mjOBJ_JOINT",
    "geom": "mjOBJ_GEOM",
    "site": "mjOBJ_SITE",
    "camera": "mjOBJ_CAMERA",
    "light": "mjOBJ_LIGHT",
    "material": "mjOBJ_MATERIAL",
    "actuator": "mjOBJ_ACTUATOR",
}
_COUNT = {
    "body": "nbody",
    "joint": "njnt",
    "geom": "ngeom",
    "site": "nsite",
    "camera": "ncam",
    "light": "nlight",
    "material": "nmat",
    "actuator": "nu",
}
# Joint fields that are per degree of freedom or per qpos coordinate.
_DOF_FIELDS = ("damping", "armature", "frictionloss")
_QPOS_FIELDS = ("qpos0", "qpos_spring")
_JOINT_QPOS = {0: 7, 1: 4, 2: 1, 3: 1}  # free, ball, slide, hinge
_JOINT_DOFS = {0: 6, 1: 3, 2: 1, 3: 1}


class _Groups:
    """Rows grouped by an index (``np.maximum.at`` without its slow per-row loop)."""

    def __init__(self, index: np.ndarray) -> None:
        self.order = np.argsort(index, kind="stable")
        ordered = index[self.order]
        self.starts = np.flatnonzero(np.r_[True, ordered[1:] != ordered[:-1]]) if len(index) else index
        self.targets = ordered[self.starts] if len(index) else index

    def maximum(self, out: np.ndarray, values: np.ndarray) -> None:
        """``out[i] = max(out[i], values of rows indexed i)`` (a maximum: any order)."""
        if len(self.order):
            best = np.maximum.reduceat(values[self.order], self.starts)
            out[self.targets] = np.maximum(out[self.targets], best)


class _Variant:
    """What a superset ModelCache reads of a variant: its index."""

    def __init__(self, index: int) -> None:
        self.index = index


def _dist(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise distances, each computed as mju_dist3 computes it (same operations, same
    order, so the same bits)."""
    d = a - b
    return np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])


def _in_order_sum(values: np.ndarray) -> float:
    """A left-to-right sum, as a C loop adds (``np.add.accumulate`` is sequential; ``sum``
    is pairwise and may differ in the last bits)."""
    return float(np.add.accumulate(values)[-1]) if len(values) else 0.0


class _Plan:
    """Everything patching one model object takes, made once per model: its structure key,
    a scratch ``MjData`` (``mj_setConst`` overwrites the qpos of the data it is given), the
    array views of the last patch's entries, and the views and constants of the statistics
    the compiler derives (``mj_setConst`` of 3.17 and 4.0 leaves them)."""

    def __init__(self, mujoco: Any, model: Any, key: str, fixed: list, superset: bool) -> None:
        self.mujoco = mujoco
        self.superset = superset
        self.model = model
        self.key = key
        self.data = data = mujoco.MjData(model)
        self.nbytes = model.nbuffer + data.nbuffer + data.narena
        self.fields: list[tuple[Any, Any, str]] | None = None
        # The patch the layout was last resolved from (ModelCache._apply_world), and which
        # of its string values are a body's little model (the others: material names).
        self.source: Any = None
        self.string_geoms: list[bool] = []
        self.groups: list[tuple[Any, np.ndarray, np.ndarray]] = []
        # (flat array, index, which material name of the patch) per matid entry.
        self.matids: list[tuple[Any, int, int]] = []
        # (field of model.opt, first of its numbers, how many) per option entry.
        self.options: list[tuple[str, int, int]] = []
        # The bodies of the patch's "geoms" entries, in order, and the little models of
        # their geoms compiled so far (MJCF text -> model), the newest last.
        self.bodies: list[int] = []
        self.body_models: dict[str, Any] = {}
        # Per "geoms" entry: its little model as the structure compiled it (what the
        # snapshot's arrays hold), and the one last written into this model (None: not
        # known; the bounding volumes are not restored before a patch).
        self.body_xml0: list[str] = []
        self.body_written: list[Any] = []
        # The <statistic> values the scene sets: MuJoCo keeps them over what it computes.
        self.fixed = fixed
        # Views (fetching one from the bindings costs microseconds) and constants.
        self.stat = model.stat
        self.qpos0, self.qpos = model.qpos0, data.qpos
        self.points = (data.xpos[1:], data.xipos[1:], data.xanchor, data.site_xpos)
        self.geom_xpos, self.xipos, self.xanchor = data.geom_xpos, data.xipos, data.xanchor
        self.body_mass, self.M = model.body_mass[1:], data.M
        self.M_diagonal = model.M_rowadr + model.M_rownnz - 1
        self.nbody, self.nv = model.nbody, model.nv
        self.dof_length = model.dof_length
        # Geom radii for the bounding box: a plane or height field (rbound 0) counts a
        # tenth of its largest size. Sizes are patched only through "geoms" entries, which
        # update these (compiled_body()).
        size, kind = model.geom_size, model.geom_type
        rbound = model.geom_rbound.copy()
        plane = (rbound <= 0) & (kind == mujoco.mjtGeom.mjGEOM_PLANE)
        finite = (size[:, 0] != 0) | (size[:, 1] != 0)
        rbound[plane & finite] = np.maximum(size[:, 0], size[:, 1])[plane & finite] * 0.1
        rbound[plane & ~finite] = 0.01
        for g in np.flatnonzero((rbound <= 0) & (kind == mujoco.mjtGeom.mjGEOM_HFIELD)):
            h = model.hfield_size[model.geom_dataid[g]]
            rbound[g] = max(h[0], max(h[1], max(h[2], h[3]))) * 0.1
        rbound[rbound < 0] = 0.0
        self.box_radius = rbound[:, None]
        self.box_radius0 = self.box_radius.copy()
        self.joint_body = model.jnt_bodyid.copy()
        self.joint_parent = model.body_parentid[self.joint_body]
        self.by_joint_body = _Groups(self.joint_body)
        self.by_joint_parent = _Groups(self.joint_parent)
        geoms = np.flatnonzero((model.geom_rbound > 0) & (model.geom_bodyid > 0))
        self.sized_geoms = geoms
        self.sized_geom_body = model.geom_bodyid[geoms]
        self.by_geom_body = _Groups(self.sized_geom_body)
        self.sized_geom_rbound = model.geom_rbound[geoms].copy()
        self.sized_geom_rbound0 = self.sized_geom_rbound.copy()
        jnt = model.dof_jntid
        jtype = model.jnt_type[jnt]
        offset = np.arange(model.nv) - model.jnt_dofadr[jnt]
        self.rotational = (jtype == 1) | (jtype == 3) | ((jtype == 0) & (offset >= 3))
        self.dof_body = model.dof_bodyid.copy()

    def resolve(self, patch: list) -> None:
        """Where every entry of ``patch`` lands: per target array, the flat indices its
        numbers go to and where they come from in the patch's numbers laid end to end
        (a one-number entry fills all its rows, as a joint's damping fills each of its
        dofs); material names apart."""
        mujoco, model = self.mujoco, self.model
        groups: dict[str, tuple[Any, list[int], list[int]]] = {}
        matids: list[tuple[Any, int, int]] = []
        options: list[tuple[str, int, int]] = []
        bodies: list[int] = []
        body_xml: list[str] = []
        numbers = 0
        for obj, name, field, value in patch:
            if obj == "option":
                if isinstance(value, str) or not hasattr(model.opt, field):
                    raise _error(f"this MuJoCo's mjOption has no field {field}")
                options.append((field, numbers, len(value)))
                numbers += len(value)
                continue
            if isinstance(name, int):
                i = name if name < getattr(model, _COUNT[obj]) else -1
            else:
                i = mujoco.mj_name2id(model, getattr(mujoco.mjtObj, _OBJ[obj]), name)
            if i < 0:
                raise _error(
                    f"the patch names {obj} '{name}', which the compiled model does not have"
                )
            if field == "geoms":
                bodies.append(int(i))
                body_xml.append(value)
                continue
            if obj == "joint" and field in _DOF_FIELDS:
                array = f"dof_{field}"
                first = int(model.jnt_dofadr[i])
                rows = range(first, first + _JOINT_DOFS[int(model.jnt_type[i])])
            elif obj == "joint" and field in _QPOS_FIELDS:
                array = field
                first = int(model.jnt_qposadr[i])
                rows = range(first, first + _JOINT_QPOS[int(model.jnt_type[i])])
            elif obj == "joint" and field == "key_qpos":
                # The joint's rows of every keyframe (one row of nq per key).
                array = field
                first = int(model.jnt_qposadr[i])
                width = _JOINT_QPOS[int(model.jnt_type[i])]
                _, targets, sources = groups.setdefault(array, (model.key_qpos.reshape(-1), [], []))
                for k in range(model.nkey):
                    targets.extend(range(k * model.nq + first, k * model.nq + first + width))
                    sources.extend(range(numbers, numbers + len(value)))
                numbers += len(value)
                continue
            else:
                array = _PREFIX[obj] + field
                width = 1 if isinstance(value, str) else len(value)
                rows = range(i * width, (i + 1) * width)
            whole = getattr(model, array)
            flat = whole.reshape(-1)
            if not np.shares_memory(flat, whole):
                raise _error(f"mjModel.{array} is not one contiguous array here")
            if isinstance(value, str):
                matids.append((flat, rows[0], len(matids)))
                continue
            _, targets, sources = groups.setdefault(array, (flat, [], []))
            targets.extend(rows)
            sources.extend(
                [numbers] * len(rows) if len(value) == 1 else range(numbers, numbers + len(value))
            )
            numbers += len(value)
        self.groups = [(flat, np.array(t), np.array(s)) for flat, t, s in groups.values()]
        self.matids = matids
        self.options = options
        self.bodies = bodies
        self.body_xml0 = body_xml
        self.body_written = [None] * len(bodies)
        self.fields = [tuple(e[:3]) for e in patch]
        self.source = None

    def apply(self, patch: list, derive: Callable[[Any, Any, list], None] | None = None) -> None:
        """Writes ``patch`` and what follows from it (:meth:`finish`; ``derive(model,
        data, layout)`` instead of ``mj_setConst`` when given, ``layout`` the patch's
        ``(object, name, field)`` triples, one list object per layout resolved)."""
        # A structure key covers its patch's layout, so a variant's targets are resolved
        # once per structure; a superset patch's layout follows which objects are placed.
        if (
            self.fields is None
            or len(self.fields) != len(patch)
            or (self.superset and any(f != e[:3] for f, e in zip(self.fields, patch)))
        ):
            self.resolve(patch)
        values = np.fromiter(
            itertools.chain.from_iterable(e[3] for e in patch if not isinstance(e[3], str)),
            dtype=np.float64,
        )
        materials = [e[3] for e in patch if isinstance(e[3], str) and e[2] != "geoms"]
        self.write(values, materials, [e[3] for e in patch if e[2] == "geoms"])
        self.finish(derive)

    def write(self, values: np.ndarray, materials: list, bodies: list = ()) -> None:
        """Writes a patch of the resolved layout: its numbers end to end (``values``), the
        names of its materials in order, and the little models of its bodies' geoms."""
        for flat, targets, sources in self.groups:
            # A float32 array takes the numbers rounded as MuJoCo rounds them (they are).
            flat[targets] = values[sources]
        for flat, index, k in self.matids:
            i = self.mujoco.mj_name2id(self.model, self.mujoco.mjtObj.mjOBJ_MATERIAL, materials[k])
            if i < 0:
                raise _error(f"no material named '{materials[k]}'")
            flat[index] = i
        opt = self.model.opt
        for field, first, n in self.options:
            if n == 1:
                setattr(opt, field, float(values[first]))
            else:
                getattr(opt, field)[:] = values[first : first + n]
        if self.bodies:
            # The statistics' radii as compiled, then each body's as written below.
            self.box_radius[:] = self.box_radius0
            self.sized_geom_rbound[:] = self.sized_geom_rbound0
            for k, (body, xml) in enumerate(zip(self.bodies, bodies)):
                # As compiled and as last written: the arrays already hold it.
                if xml == self.body_xml0[k] and self.body_written[k] == xml:
                    continue
                self.body_written[k] = None
                self.compiled_body(body, xml)
                self.body_written[k] = xml

    def compiled_body(self, body: int, xml: str) -> None:
        """Writes what MuJoCo derives from ``body``'s geoms, read off its compile of their
        little model ``xml`` (the same computation on the same numbers: each geom's size,
        bounding radius and box, the body's mass, inertia and inertial frame, its bounding
        volumes). Raises when the little model's layout is not the body's (the document is
        then compiled)."""
        mini = self.body_models.get(xml)
        if mini is None:
            mini = self.mujoco.MjModel.from_xml_string(xml)
            if len(self.body_models) >= 64:
                del self.body_models[next(iter(self.body_models))]
            self.body_models[xml] = mini
        model = self.model
        first, n = int(model.body_geomadr[body]), int(model.body_geomnum[body])
        mfirst = int(mini.body_geomadr[1]) if mini.nbody == 2 else -1
        bvh, nbvh = int(model.body_bvhadr[body]), int(model.body_bvhnum[body])
        mbvh = int(mini.body_bvhadr[1]) if mini.nbody == 2 else -1
        if (
            mini.nbody != 2
            or int(mini.body_geomnum[1]) != n
            or int(mini.body_sameframe[1]) != int(model.body_sameframe[body])
            or int(mini.body_bvhnum[1]) != nbvh
            or not np.array_equal(mini.geom_type[mfirst : mfirst + n], model.geom_type[first : first + n])
            or not np.array_equal(mini.geom_sameframe[mfirst : mfirst + n], model.geom_sameframe[first : first + n])
            or not np.array_equal(mini.bvh_child[mbvh : mbvh + nbvh], model.bvh_child[bvh : bvh + nbvh])
            or not np.array_equal(mini.bvh_depth[mbvh : mbvh + nbvh], model.bvh_depth[bvh : bvh + nbvh])
            or not np.array_equal(mini.bvh_nodeid[mbvh : mbvh + nbvh] + (first - mfirst) * (mini.bvh_nodeid[mbvh : mbvh + nbvh] >= 0), model.bvh_nodeid[bvh : bvh + nbvh])
        ):
            raise _error(
                f"body '{model.body(body).name}': its geoms compile to another layout than "
                "this structure's (sizes, frames or densities that move or turn its inertial "
                "frame off its own, or another bounding-volume tree): not a patch of it"
            )
        geoms, mgeoms = slice(first, first + n), slice(mfirst, mfirst + n)
        for field in ("geom_size", "geom_rbound", "geom_aabb", "geom_pos", "geom_quat"):
            getattr(model, field)[geoms] = getattr(mini, field)[mgeoms]
        for field in ("body_mass", "body_inertia", "body_ipos", "body_iquat"):
            getattr(model, field)[body] = getattr(mini, field)[1]
        model.bvh_aabb[bvh : bvh + nbvh] = mini.bvh_aabb[mbvh : mbvh + nbvh]
        # The bounding radii the statistics take (primitives: rbound > 0).
        rbound = mini.geom_rbound[mgeoms]
        self.box_radius[geoms, 0] = rbound
        at = np.searchsorted(self.sized_geoms, np.arange(first, first + n))
        hit = (at < len(self.sized_geoms)) & (self.sized_geoms[np.minimum(at, len(self.sized_geoms) - 1)] == np.arange(first, first + n))
        self.sized_geom_rbound[at[hit]] = rbound[hit]

    def finish(self, derive: Callable[[Any, Any, list], None] | None = None) -> None:
        """What follows the values: ``mj_setConst`` (or ``derive(model, data, layout)``,
        which writes the same), the compiler's statistics, and the statistics the document
        fixes."""
        fresh = False
        if derive is None:
            self.mujoco.mj_setConst(self.model, self.data)
        else:
            fresh = bool(derive(self.model, self.data, self.fields))
        self.statistics(fresh)
        for stat, value in self.fixed:
            if hasattr(value, "copy"):
                getattr(self.stat, stat)[...] = value
            else:
                setattr(self.stat, stat, value)

    def statistics(self, fresh: bool = False) -> None:
        """The model statistics and dof lengths, computed from the model at qpos0 as the
        compiler computes them: the same operations, sums in the same order, so the same
        bits (minima and maxima do not depend on order, so those run vectorized).
        ``fresh``: the scratch data holds the kinematics and centres of mass at qpos0."""
        mujoco, model, data, stat = self.mujoco, self.model, self.data, self.stat
        if not fresh:
            self.qpos[:] = self.qpos0
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
        mujoco.mj_makeM(model, data)
        lo = np.full(3, 1e10)
        hi = np.full(3, -1e10)
        points = np.concatenate(
            self.points + (self.geom_xpos - self.box_radius, self.geom_xpos + self.box_radius)
        )
        if len(points):
            lo = np.minimum(lo, points.min(axis=0))
            hi = np.maximum(hi, points.max(axis=0))
        stat.center[:] = (lo + hi) * 0.5
        extent = stat.extent
        if hi[0] > lo[0]:
            d = hi - lo
            extent = max(1e-5, max(d[0], max(d[1], d[2])))
        # Body sizes: the largest com-joint distance (the joint's body and its parent),
        # then geom bounds around the com.
        body = np.zeros(self.nbody)
        if len(self.joint_body):
            xipos, xanchor = self.xipos, self.xanchor
            self.by_joint_body.maximum(body, _dist(xipos[self.joint_body], xanchor))
            self.by_joint_parent.maximum(body, _dist(xipos[self.joint_parent], xanchor))
        body[0] = 0.0
        if len(self.sized_geoms):
            gb = self.sized_geom_body
            far = self.sized_geom_rbound + _dist(self.xipos[gb], self.geom_xpos[self.sized_geoms])
            self.by_geom_body.maximum(body, far)
        if self.nbody > 1:
            body[1:] = np.maximum(body[1:], 1e-5)
            stat.meansize = _in_order_sum(body[1:] / (self.nbody - 1))
            stat.meanmass = _in_order_sum(self.body_mass) / (self.nbody - 1)
        # Rotational dofs take their body's size.
        if self.nv:
            self.dof_length[:] = np.where(self.rotational, body[self.dof_body], 1.0)
            stat.meaninertia = _in_order_sum(self.M[self.M_diagonal]) / self.nv
        stat.extent = max(extent, 2 * stat.meansize)


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
        self._fixed = list(scene.fixed_statistics)
        self._max_models = max_models
        self._max_bytes = max_bytes
        #: The scene's :class:`Superset` when every variant is a patch of it, else None.
        self.superset = scene.superset() if superset else None
        # Superset: the dofs of each candidate's subtree, by its root's name (one
        # structure: the same in every model of it).
        self._subtree_dofs: dict[str, np.ndarray] = {}
        # Cached models by structure key, least recently used first.
        self._entries: collections.OrderedDict[str, Any] = collections.OrderedDict()
        # How to patch each model seen (cached ones and the caller's), by id; holding the
        # model keeps the id its own. Bounded: the least recently patched go first.
        self._plans: collections.OrderedDict[int, _Plan] = collections.OrderedDict()
        # Signatures of structures seen, kept after their models are evicted, and the
        # <statistic> values each fixes.
        self._signatures: dict[str, tuple] = {}
        self._fixed_values: dict[str, list] = {}
        #: Models compiled (misses) and patches applied so far.
        self.compiles = 0
        self.patches = 0

    def __len__(self) -> int:
        return len(self._entries)

    @property
    def nbytes(self) -> int:
        """Bytes held: every cached model, and every model's scratch ``MjData``."""
        return sum(p.nbytes for p in self._plans.values())

    def _plan(self, model: Any, key: str) -> _Plan:
        plan = _Plan(self._mujoco, model, key, self._fixed_values[key], self.superset is not None)
        self._plans[id(model)] = plan
        self._trim()
        return plan

    def _trim(self) -> None:
        cached = {id(m) for m in self._entries.values()}

        def dropped(_key: str, gone: Any) -> None:
            self._plans.pop(id(gone), None)
            cached.discard(id(gone))

        _evict(self._entries, self._max_models, self._max_bytes, lambda: self.nbytes, dropped)
        # Plans of the caller's models: as many as cached models are allowed.
        extra = [k for k in self._plans if k not in cached]
        for k in extra[: max(0, len(extra) - self._max_models)]:
            del self._plans[k]

    def _variant_inertia(self, model: Any, plan: "_Plan", variant: Any, parked: Any = None) -> None:
        """Superset: ``stat.meaninertia`` (which scales the constraint solver's tolerance)
        as the variant's own model has it: the mean of the mass matrix's diagonal over the
        dofs of what the variant places (in the superset's dof order, which is the
        variant's), parked objects left out (``parked``: their root bodies' names, when
        known)."""
        roots = self.superset.parked(variant.index) if parked is None else parked
        of = self._subtree_dofs
        for root in roots:
            if root not in of:
                inside = np.zeros(model.nbody, dtype=bool)
                inside[model.body(root).id] = True
                for b in range(1, model.nbody):  # parents come before their children
                    inside[b] |= inside[model.body_parentid[b]]
                of[root] = np.flatnonzero(inside[model.dof_bodyid])
        mask = np.ones(model.nv, dtype=bool)
        if roots:
            mask[np.concatenate([of[root] for root in roots])] = False
        keep = np.flatnonzero(mask)
        if len(keep):
            model.stat.meaninertia = _in_order_sum(plan.M[plan.M_diagonal[keep]]) / len(keep)

    def _key_and_patch(self, variant: Any) -> tuple[str, Any]:
        if self.superset is not None:
            return self.superset.structure_key, self.superset.patch(variant.index)
        return variant.structure_key, variant.patch

    def _compile(self, variant: Any) -> Any:
        """Compiles the variant's structure (the superset, or the variant itself) and keeps
        it; the model returned is already the variant's."""
        xml = self.superset.xml if self.superset is not None else variant.xml
        model = self._mujoco.MjModel.from_xml_string(xml)
        self.compiles += 1
        key = self.superset.structure_key if self.superset is not None else variant.structure_key
        self._signatures[key] = _signature(model)
        self._fixed_values[key] = [(s, _copy(getattr(model.stat, s))) for s in self._fixed]
        self._entries[key] = model
        self._entries.move_to_end(key)
        plan = self._plan(model, key)
        if self.superset is not None:
            # The superset as compiled parks every object: the variant's patch places its own.
            plan.apply(self.superset.patch(variant.index))
            self._variant_inertia(model, plan, variant)
            self.patches += 1
        return model

    def model(self, variant: Any) -> Any:
        """A compiled model equal to MuJoCo's compile of ``variant.xml`` (see the class);
        with ``superset=True``, the superset model patched for the variant."""
        key, patch = self._key_and_patch(variant)
        model = self._entries.get(key)
        if model is None:
            return self._compile(variant)
        self._entries.move_to_end(key)
        plan = self._plans.get(id(model)) or self._plan(model, key)
        try:
            plan.apply(patch)
        except MjcfError:
            if self.superset is not None:
                raise
            # A body's geoms that compile to another layout (sizes that turn its principal
            # axes): not a patch of this structure, so the variant is compiled (and kept).
            return self._compile(variant)
        if self.superset is not None:
            self._variant_inertia(model, plan, variant)
        self.patches += 1
        return model

    def apply(self, variant: Any, model: Any) -> Any:
        """Patches ``model`` (of ``variant``'s structure) in place into ``variant``'s
        compiled model; returns it. Raises :class:`MjcfError` when its structure differs."""
        return self._apply(variant, model)

    def _apply(self, variant: Any, model: Any, derive: Any = None, patch: Any = None) -> Any:
        """:meth:`apply`, with ``derive(model, data, layout)`` in place of ``mj_setConst``
        when given (it must write the same), and the variant's patch when already made."""
        key, made = self._key_and_patch(variant) if patch is None else (self.superset.structure_key, patch)
        patch = made
        plan = self._plans.get(id(model))
        if plan is None or plan.model is not model:
            if key not in self._signatures:
                # The structure's first sight: its compile (kept) says what it is.
                self._compile(variant)
            if _signature(model) != self._signatures[key]:
                raise _error(
                    f"the model does not have the structure of variant {variant.index} "
                    f"(key {key}): its sizes, names or element types differ"
                )
            plan = self._plan(model, key)
        elif plan.key != key:
            raise _error(
                f"the model has structure {plan.key}, variant {variant.index} has {key}: "
                "a patch cannot change a structure (cache.model(variant) compiles it)"
            )
        self._plans.move_to_end(id(model))
        plan.apply(patch, derive)
        if self.superset is not None:
            self._variant_inertia(model, plan, variant)
        self.patches += 1
        return model

    def _apply_world(self, model: Any, world: tuple, patch0: list, derive: Any = None) -> Any:
        """Superset: ``model`` patched for one world as :meth:`Superset.worlds` gives it
        (``world``: its index, numbers, strings and parked roots; ``patch0``: a patch of its
        layout, resolved once), ``derive`` as in :meth:`_apply`."""
        index, numbers, strings, parked = world
        key = self.superset.structure_key
        plan = self._plans.get(id(model))
        if plan is None or plan.model is not model:
            if key not in self._signatures:
                self._compile(_Variant(index))
            plan = self._plan(model, key)
        self._plans.move_to_end(id(model))
        if plan.source is not patch0:
            plan.resolve(patch0)
            plan.source = patch0
            plan.string_geoms = [e[2] == "geoms" for e in patch0 if isinstance(e[3], str)]
        values = np.frombuffer(numbers, dtype=np.float64)
        if strings:
            geoms = plan.string_geoms
            materials = [v for v, g in zip(strings, geoms) if not g]
            bodies = [v for v, g in zip(strings, geoms) if g]
        else:
            materials, bodies = [], []
        plan.write(values, materials, bodies)
        plan.finish(derive)
        self._variant_inertia(model, plan, None, parked)
        self.patches += 1
        return model

    def batch(self, variants: Any, progress: Any = None) -> dict[str, np.ndarray]:
        """Per-world arrays for batched simulation (``superset=True``): for every field of
        the superset model that differs between the given variants, one row per variant
        (``{"geom_rgba": (n, ngeom, 4), "qpos0": (n, nq), "stat.meaninertia": (n,), ...}``),
        each row what the patched superset model holds for that variant: the form MJX and
        MuJoCo Warp take for per-world model fields. Fields every variant shares are left
        out (they are the superset model's).

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
            and not n.startswith(_STATIC_PREFIXES)
        ]
        rows: dict[str, list[np.ndarray]] = {n: [] for n in names}
        stats = {f"stat.{s}": [] for s in ("meaninertia", "meanmass", "meansize", "extent", "center")}
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
        for n, r in list(rows.items()) + list(stats.items()):
            stacked = np.stack(r)
            if not (stacked == stacked[0]).all():
                out[n] = stacked
        return out
