"""What ``mj_setConst`` derives for a superset world, tree by tree.

A world of a superset (:class:`mjcf_forge.batch.WorldBatch`) is the superset model with
one variant's patch written in, then ``mj_setConst``. Most of that call's time goes to
the inverse inertias of every body and joint (``body_invweight0``, ``dof_invweight0``),
one solve with the whole model's mass matrix per body, so it grows with every candidate
the superset holds, placed or parked. Yet each of those values depends on its own
kinematic tree only (the mass matrix is block diagonal by tree), and a world changes only
the trees its patch writes into: its placed candidates (parked ones are the same in every
world: as authored, in their cell).

:class:`TreeDerivation` does the same computation per tree: each tree the patch writes
into is compiled once alone as a skeleton (its bodies, inertials and joints, no geoms),
and per world the tree's values are copied into its skeleton, MuJoCo's own
``mj_setConst`` runs there and the derived values are copied back; parked trees take the
values of their first computation. What spans trees is computed on the superset itself:
``body_subtreemass`` (the same sums in the same order) and the cameras' and lights'
reference frames (MuJoCo's kinematics at ``qpos0``, then the same differences). The
result is bit for bit what ``mj_setConst`` gives (``python/tests/test_world_batch.py`` compares
every per-world array of both ways); a patch that writes anything else ``mj_setConst``
reads (a robot's armature, an actuated tree, a tendon) gets ``None`` from
:meth:`TreeDerivation.build`, and the caller keeps ``mj_setConst``.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from ._mjcf_forge import GEOM_FACTORS, JOINT_TYPES, MODEL_FIELDS, PATCH_OBJECTS, ModelArrays, joint_widths, target_array
from . import _mujoco
from ._last_xml import compile_xml

# Each patched object's mjtObj name (the split tier's PATCH_OBJECTS, through the extension).
OBJ = {obj: kind for obj, (_prefix, kind, _count) in PATCH_OBJECTS.items()}

# Patch targets (MjModel arrays) that mj_setConst reads: a tree written into through
# them is derived again per world.
_INPUTS = frozenset({
    "body_pos", "body_quat", "body_ipos", "body_iquat", "body_mass", "body_inertia",
    "jnt_pos", "jnt_axis", "qpos0", "dof_armature",
})
# Patch targets mj_setConst does not read (its kinematics at qpos0 reads geom and site
# frames, but nothing it keeps depends on them), nor the statistics that follow it
# through a path not taken here (geom sizes go through "geoms" entries).
_UNREAD_PREFIXES = ("geom_", "mat_", "site_rgba", "key_")
_UNREAD = frozenset({
    "light_diffuse", "light_specular", "light_ambient", "light_attenuation", "cam_fovy",
    "dof_damping", "dof_frictionloss", "jnt_stiffness", "qpos_spring", "body_gravcomp",
})
# Per-tree values copied into a skeleton (bodies, joints, dofs) and the flags that steer
# MuJoCo's computation (copied too: the skeleton's placeholder inertials set their own).
_BODY_IN = ("body_pos", "body_quat", "body_ipos", "body_iquat", "body_mass", "body_inertia",
            "body_sameframe", "body_simple")
_JOINT_IN = ("jnt_pos", "jnt_axis")
_DOF_IN = ("dof_armature", "dof_simplenum")


def _num(values: Any) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


class _Tree:
    """One kinematic tree of the superset compiled alone as a skeleton, and where its
    bodies, joints, dofs and coordinates sit in the superset (contiguous ranges).

    MuJoCo's dot products over all dofs (``mju_dot``, as in ``body_invweight0``'s
    ``J M^-1 J'``) add in four interleaved partial sums, then the last ``nv % 4`` terms
    one by one: which sum a term joins depends on its dof's index. So the skeleton puts
    its tree's dofs at the superset's indices modulo 4 (slide joints of a padding body
    before them) and on the same side of that tail (padding after them): the same terms,
    in the same sums, the same bits."""

    def __init__(self, mujoco: Any, model: Any, root: int) -> None:
        self.mujoco = mujoco
        bodies = np.flatnonzero(model.body_rootid == root)
        joints = np.flatnonzero(np.isin(model.jnt_bodyid, bodies))
        dofs = np.flatnonzero(np.isin(model.dof_bodyid, bodies))
        if len(bodies) != bodies[-1] - bodies[0] + 1 or len(joints) == 0:
            raise ValueError("not a contiguous moving tree")
        if len(dofs) != dofs[-1] - dofs[0] + 1 or len(joints) != joints[-1] - joints[0] + 1:
            raise ValueError("not a contiguous moving tree")
        first = int(model.jnt_qposadr[joints[0]])
        last = int(model.jnt_qposadr[joints[-1]])
        width = joint_widths(int(model.jnt_type[joints[-1]]))[1]
        self.bodies = slice(int(bodies[0]), int(bodies[-1]) + 1)
        self.joints = slice(int(joints[0]), int(joints[-1]) + 1)
        self.dofs = slice(int(dofs[0]), int(dofs[-1]) + 1)
        self.qpos = slice(first, last + width)
        start, count, nv = int(dofs[0]), len(dofs), int(model.nv)
        before = start % 4
        if start + count <= nv - nv % 4:
            after = -(before + count) % 4
        else:
            after = nv - start - count
        sk = self.skeleton = compile_xml(mujoco, self._xml(model, bodies, before, after))
        b0 = 1 + (before > 0)
        if (
            sk.nbody != len(bodies) + b0 + (after > 0)
            or sk.nv != before + count + after
            or int(sk.jnt_dofadr[(before > 0) * before]) != before
        ):
            raise ValueError("the skeleton does not have the tree's layout")
        self.data = mujoco.MjData(sk)
        mb = slice(b0, b0 + len(bodies))
        mj = slice(before, before + len(joints))
        md = slice(before, before + count)
        # The mass matrix's sparsity, as the superset's (the dofs' own rows).
        rows = slice(start, start + count)
        if _mujoco.field(sk, "M_rownnz") is None:
            # MuJoCo 3.3 has no M_rownnz to compare (mj_setConst on the whole model then).
            raise ValueError("this MuJoCo has no M_rownnz")
        if not (
            np.array_equal(sk.M_rownnz[md], model.M_rownnz[rows])
            and all(
                np.array_equal(
                    sk.M_colind[sk.M_rowadr[before + k] : sk.M_rowadr[before + k] + sk.M_rownnz[before + k]] - before,
                    model.M_colind[model.M_rowadr[start + k] : model.M_rowadr[start + k] + model.M_rownnz[start + k]] - start,
                )
                for k in range(count)
            )
            and all(
                np.array_equal(getattr(sk, n)[mb], getattr(model, n)[self.bodies])
                for n in ("body_simple",) if _mujoco.field(sk, n) is not None
            )
        ):
            raise ValueError("the skeleton's mass matrix is not laid out as the tree's")
        mq = slice(before, before + last + width - first)
        # Views: (superset array, its rows, skeleton rows) to copy in; and back.
        self.inputs = [(n, self.bodies, getattr(sk, n)[mb]) for n in _BODY_IN if hasattr(sk, n)]
        self.inputs += [(n, self.joints, getattr(sk, n)[mj]) for n in _JOINT_IN]
        self.inputs += [(n, self.dofs, getattr(sk, n)[md]) for n in _DOF_IN if hasattr(sk, n)]
        self.inputs += [("qpos0", self.qpos, sk.qpos0[mq])]
        self.outputs = [
            ("body_invweight0", self.bodies, sk.body_invweight0[mb]),
            ("dof_invweight0", self.dofs, sk.dof_invweight0[md]),
            ("dof_M0", self.dofs, sk.dof_M0[md]),
        ]

    @staticmethod
    def _xml(model: Any, bodies: np.ndarray, before: int, after: int) -> str:
        """The tree's bodies and joints with placeholder inertials (every value that
        matters is copied in before each use), between padding bodies of ``before`` and
        ``after`` slide joints."""
        parts: dict[int, list[str]] = {int(b): [] for b in bodies}
        for j in np.flatnonzero(np.isin(model.jnt_bodyid, bodies)):
            kind = JOINT_TYPES[int(model.jnt_type[j])]
            parts[int(model.jnt_bodyid[j])].append(
                f'<joint type="{kind}" pos="{_num(model.jnt_pos[j])}" axis="{_num(model.jnt_axis[j])}"/>'
            )
        inertial = '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
        # The compiler makes a body whose inertial frame is its own "simple" (a sparser
        # mass matrix): the skeleton's bodies are simple exactly where the superset's are.
        offset = '<inertial pos=".01 .02 .03" quat=".9 .1 .2 .3" mass="1" diaginertia="1 1 1"/>'
        simple = _mujoco.field(model, "body_simple")

        def body(b: int) -> str:
            children = [int(c) for c in bodies if model.body_parentid[c] == b and c != b]
            return (
                f'<body pos="{_num(model.body_pos[b])}" quat="{_num(model.body_quat[b])}">'
                + (offset if simple is not None and simple[b] == 0 else inertial)
                + "".join(parts[b])
                + "".join(body(c) for c in children)
                + "</body>"
            )

        def padding(n: int) -> str:
            slides = '<joint type="slide" axis="1 0 0"/>' * n
            return f"<body>{inertial}{slides}</body>" if n else ""

        return (
            '<mujoco><compiler angle="radian"/><worldbody>'
            + padding(before)
            + body(int(bodies[0]))
            + padding(after)
            + "</worldbody></mujoco>"
        )

    def derive(self, model: Any) -> list[np.ndarray]:
        """The tree's derived values for the superset's current values."""
        for name, rows, mine in self.inputs:
            mine[...] = getattr(model, name)[rows]
        self.mujoco.mj_setConst(self.skeleton, self.data)
        return [mine.copy() for _, _, mine in self.outputs]

    def write(self, model: Any, values: list[np.ndarray]) -> None:
        for (name, rows, _), value in zip(self.outputs, values):
            getattr(model, name)[rows] = value


class TreeDerivation:
    """``mj_setConst`` for a superset world, per tree (see the module). Build it with
    :meth:`build`, then call it after each patch instead of ``mj_setConst``."""

    def __init__(
        self, mujoco: Any, model: Any, roots: list[int], moving: set[int], framed: tuple
    ) -> None:
        self.mujoco = mujoco
        # Per tree the patch writes into: its skeleton (None for a tree welded to the
        # world: nothing to derive but its flags), and its bodies, geoms and sites whose
        # same-frame flags its patch may change (``framed``: those of the whole model).
        self.trees = {root: _Tree(mujoco, model, root) if root in moving else None for root in roots}
        # Set again in every world that changes a tree (one pass: cheaper than picking the
        # changed trees' elements), by the rule both faces share
        # (mjcf_forge::split::write_frame_flags, through the extension's ModelArrays).
        self.framed = tuple(sorted(int(i) for i in f) for f in framed)
        self.arrays = ModelArrays(model)
        # Each tree's values as last written ("parked" or "placed"), and the derived
        # values of parked trees (the same in every world).
        self.state: dict[int, str] = {}
        self.parked: dict[int, list[np.ndarray]] = {}
        self.parent = [int(p) for p in model.body_parentid]
        self.cam_body = model.cam_bodyid.copy()
        self.cam_target = np.where(model.cam_targetbodyid >= 0, model.cam_targetbodyid, model.cam_bodyid)
        self.light_body = model.light_bodyid.copy()
        self.light_target = np.where(
            model.light_targetbodyid >= 0, model.light_targetbodyid, model.light_bodyid
        )
        self.sameframe = _recomputes_sameframe(mujoco)

    def forget(self) -> None:
        """The model was patched some other way since the last call: every tree is
        derived again at the next."""
        self.state.clear()

    @classmethod
    def build(cls, mujoco: Any, model: Any, layout: list) -> "TreeDerivation | None":
        """The derivation for ``model`` (a superset) and patches of ``layout`` (their
        ``(object, name, field)`` triples), or None when such a patch writes what it does
        not follow (``mj_setConst`` then)."""
        if model.nflex:
            return None
        roots: set[int] = set()
        # Bodies whose inertial frame, geoms and sites whose frame a patch writes (their
        # same-frame flags follow: a geom's and a site's also follow their body's).
        framed_bodies: set[int] = set()
        framed: set[tuple[str, int]] = set()
        for obj, name, field in layout:
            if obj == "option":
                continue
            target = target_array(obj, field)
            if field in MODEL_FIELDS or field == GEOM_FACTORS:
                target = "body_mass"
            if target in ("geom_pos", "geom_quat", "site_pos", "site_quat"):
                i = _id_of(mujoco, model, obj, name)
                if i is None:
                    return None
                framed.add((obj, i))
            if target is None or target.startswith(_UNREAD_PREFIXES) or target in _UNREAD:
                continue
            if target not in _INPUTS:
                return None
            body = _body_of(mujoco, model, obj, name)
            if body is None:
                return None
            roots.add(int(model.body_rootid[body]))
            if field == "geoms":  # a body model writes the geoms' frames too
                framed_bodies.add(body)
                framed.update(("geom", int(g)) for g in np.flatnonzero(model.geom_bodyid == body))
            elif target in ("body_ipos", "body_iquat") or field == GEOM_FACTORS:
                framed_bodies.add(body)
        roots.discard(0)
        # A geom or site whose own frame no patch writes and whose orientation is its
        # body's keeps its flag (BODY or BODYROT) whatever the body's inertial frame.
        turned_geoms = ~_same_quat(model.geom_quat, _UNIT)
        turned_sites = ~_same_quat(model.site_quat, _UNIT)
        in_bodies = list(framed_bodies)
        geoms = {i for o, i in framed if o == "geom"}
        geoms |= set(np.flatnonzero(np.isin(model.geom_bodyid, in_bodies) & turned_geoms).tolist())
        sites = {i for o, i in framed if o == "site"}
        sites |= set(np.flatnonzero(np.isin(model.site_bodyid, in_bodies) & turned_sites).tolist())
        # A frame written outside the trees followed here: its flags would go stale.
        for b in [*framed_bodies, *model.geom_bodyid[list(geoms)], *model.site_bodyid[list(sites)]]:
            if int(model.body_rootid[b]) not in roots:
                return None
        tied = _tied_bodies(mujoco, model)
        moving = set()
        for root in roots:
            tree = model.body_rootid == root
            if tied[tree].any():
                return None
            if (model.body_weldid[tree] != 0).any():
                moving.add(root)
        try:
            return cls(mujoco, model, sorted(roots), moving, (framed_bodies, geoms, sites))
        except ValueError:
            return None

    def __call__(self, model: Any, data: Any, parked: set[int]) -> bool:
        """Writes into ``model`` what ``mj_setConst`` derives from its values (``parked``:
        the root bodies of the candidates this world parks), in its order: same-frame
        flags, then the trees, subtree masses, cameras and lights. Returns whether
        ``data`` (scratch) was left with MuJoCo's kinematics and centres of mass at
        ``qpos0`` (as the statistics need them)."""
        changed = []
        for root in self.trees:
            now = "parked" if root in parked else "placed"
            # A tree parked in the last world too holds its values already.
            if now != "parked" or self.state.get(root) != "parked":
                changed.append((root, now))
        if self.sameframe and changed:
            self.arrays.write_frame_flags(*self.framed)
        for root, now in changed:
            tree = self.trees[root]
            if tree is not None:
                values = self.parked.get(root) if now == "parked" else None
                if values is None:
                    values = tree.derive(model)
                    if now == "parked":
                        self.parked[root] = values
                tree.write(model, values)
            self.state[root] = now
        # Subtree masses: the same sums in the same order as MuJoCo's.
        mass = model.body_mass.tolist()
        for i in range(len(mass) - 1, 0, -1):
            mass[self.parent[i]] += mass[i]
        model.body_subtreemass[:] = mass
        self._frames(model, data)
        return True

    def _frames(self, model: Any, data: Any) -> None:
        """MuJoCo's kinematics and centres of mass at qpos0, and from them the cameras'
        and lights' offsets from their bodies and subtree centres, as mj_setConst takes
        them (every camera and light held fixed)."""
        mujoco = self.mujoco
        if not (model.ncam or model.nlight):
            data.qpos[:] = model.qpos0
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
            return
        cam_mode, light_mode = model.cam_mode.copy(), model.light_mode.copy()
        model.cam_mode[:] = 0
        model.light_mode[:] = 0
        try:
            data.qpos[:] = model.qpos0
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
            mujoco.mj_camlight(model, data)
        finally:
            model.cam_mode[:] = cam_mode
            model.light_mode[:] = light_mode
        if model.ncam:
            model.cam_pos0[:] = data.cam_xpos - data.xpos[self.cam_body]
            model.cam_poscom0[:] = data.cam_xpos - data.subtree_com[self.cam_target]
            model.cam_mat0[:] = data.cam_xmat
        if model.nlight:
            model.light_pos0[:] = data.light_xpos - data.xpos[self.light_body]
            model.light_poscom0[:] = data.light_xpos - data.subtree_com[self.light_target]
            model.light_dir0[:] = data.light_xdir


def _id_of(mujoco: Any, model: Any, obj: str, name: Any) -> int | None:
    kind = OBJ.get(obj)
    if kind is None:
        return None
    i = name if isinstance(name, int) else mujoco.mj_name2id(model, getattr(mujoco.mjtObj, kind), name)
    return None if i < 0 else int(i)


def _body_of(mujoco: Any, model: Any, obj: str, name: Any) -> int | None:
    i = _id_of(mujoco, model, obj, name)
    if i is None or obj == "site":
        return None
    if obj == "joint":
        return int(model.jnt_bodyid[i])
    if obj == "geom":
        return int(model.geom_bodyid[i])
    return int(i)


def _tied_bodies(mujoco: Any, model: Any) -> np.ndarray:
    """Bodies an actuator, equality or tendon reaches (their trees' derived values are not
    the tree's own: actuator_acc0, eq_data, tendon_invweight0)."""
    tied = np.zeros(model.nbody, dtype=bool)
    wrap = mujoco.mjtWrap
    tendon_bodies: list[list[int]] = []
    for t in range(model.ntendon):
        bodies = []
        for w in range(int(model.tendon_adr[t]), int(model.tendon_adr[t] + model.tendon_num[t])):
            kind, obj = int(model.wrap_type[w]), int(model.wrap_objid[w])
            if kind == wrap.mjWRAP_JOINT:
                bodies.append(int(model.jnt_bodyid[obj]))
            elif kind == wrap.mjWRAP_SITE:
                bodies.append(int(model.site_bodyid[obj]))
            elif kind in (wrap.mjWRAP_SPHERE, wrap.mjWRAP_CYLINDER):
                bodies.append(int(model.geom_bodyid[obj]))
        tendon_bodies.append(bodies)
        tied[bodies] = True
    trn = mujoco.mjtTrn
    for i in range(model.nu):
        kind, obj = int(model.actuator_trntype[i]), int(model.actuator_trnid[i, 0])
        if kind in (trn.mjTRN_JOINT, trn.mjTRN_JOINTINPARENT):
            tied[model.jnt_bodyid[obj]] = True
        elif kind in (trn.mjTRN_SITE, trn.mjTRN_SLIDERCRANK):
            tied[model.site_bodyid[obj]] = True
        elif kind == trn.mjTRN_BODY:
            tied[obj] = True
        elif kind == trn.mjTRN_TENDON:
            tied[tendon_bodies[obj]] = True
        else:
            tied[:] = True
    objs, eq = mujoco.mjtObj, mujoco.mjtEq
    for i in range(model.neq):
        kind, objtype = int(model.eq_type[i]), int(model.eq_objtype[i])
        for j in (int(model.eq_obj1id[i]), int(model.eq_obj2id[i])):
            if j < 0:
                continue
            if kind == eq.mjEQ_JOINT:
                tied[model.jnt_bodyid[j]] = True
            elif kind == eq.mjEQ_TENDON:
                tied[tendon_bodies[j]] = True
            elif objtype == objs.mjOBJ_BODY:
                tied[j] = True
            elif objtype == objs.mjOBJ_SITE:
                tied[model.site_bodyid[j]] = True
            else:
                tied[:] = True
    return tied


# MuJoCo's tolerance for "the same frame" (kSameFrameEps, as the compiler's kFrameEps).
_FRAME_EPS = 1e-6
_UNIT = np.array([1.0, 0.0, 0.0, 0.0])


@functools.lru_cache(maxsize=None)
def _recomputes_sameframe(mujoco: Any) -> bool:
    """Whether this MuJoCo's mj_setConst sets the bodies', geoms' and sites' same-frame
    flags again from their frames (4.0 does; 3.17 keeps the compiler's)."""
    model = compile_xml(
        mujoco,
        '<mujoco><worldbody><body><freejoint/><geom size=".1" pos=".1 0 0"/></body>'
        "</worldbody></mujoco>"
    )
    model.body_sameframe[1] = mujoco.mjtSameFrame.mjSAMEFRAME_NONE
    mujoco.mj_setConst(model, mujoco.MjData(model))
    return int(model.body_sameframe[1]) != int(mujoco.mjtSameFrame.mjSAMEFRAME_NONE)


def _same(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return (np.abs(a - b) < _FRAME_EPS).all(axis=-1)


def _same_quat(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return _same(a, b) | (np.abs(a + b) < _FRAME_EPS).all(axis=-1)
