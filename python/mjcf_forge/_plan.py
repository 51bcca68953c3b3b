"""How one compiled model is patched in place: :class:`Plan`, made once per model (the
model caches, ``_cache.py`` and ``_doc_cache.py``, hold one per model they patch).

A plan resolves where each entry of a patch lands (once per layout: the extension's
``PatchLanding``, ``mjcf_forge::split::land``, the rule the C face follows too), writes a
patch's numbers and material ids through it, and the options and body models itself, then what follows from the values: ``mj_setConst`` (or a
caller's derivation that writes the same, see ``_trees.py``), the model statistics the
compiler derives at ``qpos0`` (which ``mj_setConst`` of 3.17 and 4.0 leaves: this module
runs the kinematics, the extension's ``Statistics`` computes them in place, the one
implementation both faces use, ``mjcf_forge::split::statistics``), and the statistics the
document fixes.
"""

from __future__ import annotations

import itertools
from typing import Any, Callable

import numpy as np

from ._errors import error
from ._last_xml import compile_xml
from . import _mujoco
from ._mjcf_forge import BODY_MODELS_KEPT, MODEL_FIELDS, PATCH_OBJECTS, ModelArrays, PatchLanding, Statistics

# The split tier's tables (``mjcf_forge::split::targets``, through the extension): each
# patched object's array prefix, mjtObj name and count; the joints' dof and qpos fields.
OBJ = {obj: kind for obj, (_prefix, kind, _count) in PATCH_OBJECTS.items()}


class Plan:
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
        # Superset: the tree-by-tree derivations of mj_setConst (TreeDerivation, by patch
        # layout), and the cache's patch count after the last one (another count: the
        # model was patched another way since; ModelCache._tree_derive).
        self.derivations: dict[int, tuple[list, Any]] = {}
        self.derived_at = -1
        # The patch the layout was last resolved from (ModelCache._apply_world), and which
        # of its string values are a body model (the others: material names).
        self.source: Any = None
        self.string_geoms: list[bool] = []
        # Where the patch's numbers and material ids land (the extension's PatchLanding),
        # and (field of model.opt, first of its numbers, how many) per option entry.
        self.landing: Any = None
        self.options: list[tuple[str, int, int]] = []
        # The bodies of the patch's body-model and unit-model entries (MODEL_FIELDS), in
        # order, with their fields, and the models of their geoms compiled so far (MJCF
        # text -> model), the newest last; the unit model of each body with one.
        self.bodies: list[tuple[int, str]] = []
        self.body_models: dict[str, tuple[Any, Any]] = {}
        self.units: dict[int, Any] = {}
        # Per such entry: its model as the structure compiled it (what the snapshot's
        # arrays hold), and the one last written into this model (None: not known; the
        # bounding volumes are not restored before a patch).
        self.body_xml0: list[str] = []
        self.body_written: list[Any] = []
        # The <statistic> values the scene sets: MuJoCo keeps them over what it computes.
        self.fixed = fixed
        # Views (fetching one from the bindings costs microseconds) and constants.
        self.stat = model.stat
        self.qpos0, self.qpos = model.qpos0, data.qpos
        # The arrays a body model is copied into (the copy: the extension's
        # ModelArrays.copy_body_model, mjcf_forge::split::copy_body_model), with the
        # inertial frames of the bodies the structure compiled without mass.
        self.arrays = ModelArrays(model)
        # The mass matrix's diagonal, where this MuJoCo keeps it (_mujoco.py), and the
        # arrays the statistics read, found once.
        inertia, diagonal = _mujoco.inertia_diagonal(model, data)
        self.statistics_arrays = Statistics(model, data, inertia, diagonal)

    def resolve(self, patch: list) -> None:
        """Where every entry of ``patch`` lands: the extension's ``PatchLanding``
        (``mjcf_forge::split::land``, the rule both faces share) over this model, given
        each entry's element id as this MuJoCo finds it; the options and body models
        apart."""
        mujoco, model = self.mujoco, self.model
        ids: list[int | None] = []
        bodies: list[tuple[int, str]] = []
        body_xml: list[str] = []
        for obj, name, field, value in patch:
            if obj == "option":
                if isinstance(value, str) or not hasattr(model.opt, field):
                    raise error(f"this MuJoCo's mjOption has no field {field}")
                ids.append(None)
                continue
            if isinstance(name, int):
                i = name if name < getattr(model, PATCH_OBJECTS[obj][2]) else -1
            else:
                i = mujoco.mj_name2id(model, getattr(mujoco.mjtObj, OBJ[obj]), name)
            if i < 0:
                raise error(
                    f"the patch names {obj} '{name}', which the compiled model does not have"
                )
            ids.append(int(i))
            if field in MODEL_FIELDS:
                bodies.append((int(i), field))
                body_xml.append(value)
        try:
            self.landing = PatchLanding(model, patch, ids)
        except ValueError as e:
            raise error(str(e)) from None
        self.options = self.landing.options
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
        materials = [e[3] for e in patch if isinstance(e[3], str) and e[2] not in MODEL_FIELDS]
        self.write(values, materials, [e[3] for e in patch if e[2] in MODEL_FIELDS])
        self.finish(derive)

    def write(self, values: np.ndarray, materials: list, bodies: list = ()) -> None:
        """Writes a patch of the resolved layout: its numbers end to end (``values``), the
        names of its materials in order, and the body models of its bodies' geoms."""
        ids = []
        for name in materials:
            i = self.mujoco.mj_name2id(self.model, self.mujoco.mjtObj.mjOBJ_MATERIAL, name)
            if i < 0:
                raise error(f"no material named '{name}'")
            ids.append(int(i))
        try:
            self.landing.write(values, ids)
        except ValueError as e:
            raise error(str(e)) from None
        opt = self.model.opt
        for field, first, n in self.options:
            if n == 1:
                setattr(opt, field, float(values[first]))
            else:
                getattr(opt, field)[:] = values[first : first + n]
        if self.bodies:
            for k, ((body, field), xml) in enumerate(zip(self.bodies, bodies)):
                if field != "geoms":
                    # A unit model: its geom factors' entry follows.
                    self.units[body] = self.compiled(body, xml)
                    continue
                # As compiled and as last written: the arrays already hold it.
                if xml == self.body_xml0[k] and self.body_written[k] == xml:
                    continue
                self.body_written[k] = None
                self.body_model(body, xml)
                self.body_written[k] = xml
        for body, first, n in self.landing.geom_factors:
            try:
                self.arrays.write_geom_masses(
                    body, self.model.body(body).name, self.units[body], values[first : first + n].tolist()
                )
            except ValueError as e:
                raise error(str(e)) from None

    def compiled(self, body: int, xml: str) -> Any:
        """The arrays of ``xml``, a model of ``body``'s geoms, compiled by this MuJoCo once
        (the last ``BODY_MODELS_KEPT`` kept)."""
        entry = self.body_models.get(xml)
        if entry is None:
            try:
                mini = compile_xml(self.mujoco, xml)
            except ValueError as e:
                raise error(f"body '{self.model.body(body).name}': its geoms alone: {e}") from None
            if len(self.body_models) >= BODY_MODELS_KEPT:
                del self.body_models[next(iter(self.body_models))]
            entry = self.body_models[xml] = (mini, ModelArrays(mini))
        return entry[1]

    def body_model(self, body: int, xml: str) -> None:
        """Writes what MuJoCo derives from ``body``'s geoms, read off its compile of their
        body model ``xml`` (the same computation on the same numbers: each geom's size,
        bounding radius and box, the body's mass, inertia and inertial frame, its bounding
        volumes). Raises when the body model's layout is not the body's (the document is
        then compiled)."""
        try:
            self.arrays.copy_body_model(body, self.model.body(body).name, self.compiled(body, xml))
        except ValueError as e:
            raise error(str(e)) from None

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
        compiler computes them (``mjcf_forge::split::statistics``: the same operations in
        the same order, so the same bits). ``fresh``: the scratch data holds the kinematics
        and centres of mass at qpos0."""
        if not fresh:
            self.qpos[:] = self.qpos0
            self.mujoco.mj_kinematics(self.model, self.data)
            self.mujoco.mj_comPos(self.model, self.data)
        # The joint-space inertia (_mujoco.py: mj_makeM or, in 3.3, mj_crb).
        _mujoco.make_inertia(self.mujoco, self.model, self.data)
        self.statistics_arrays.compute()

    def mean_inertia(self, dofs: np.ndarray) -> float:
        """The mean of the joint-space inertia's diagonal over ``dofs`` (in order, not
        empty), from the scratch data as :meth:`finish` left it: a superset world's
        ``stat.meaninertia``, the dofs of what its variant places."""
        return self.statistics_arrays.mean_inertia(dofs.tolist())
