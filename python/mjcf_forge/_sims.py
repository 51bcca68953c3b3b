"""robosuite's simulations kept across hard resets, for :mod:`mjcf_forge.robosuite`.

A robosuite hard reset frees its ``MjSim`` (``MjSim.free``: the render context and its
OpenGL context, the data, the model, then ``gc.collect()``), builds its task again and
makes a new ``MjSim`` from the task's XML (``MjSim.from_xml_string``), and later a new
render context, which uploads every texture, mesh, height field and skin again. With the
switch, ``MjSim.free`` keeps the freed simulation instead (the last
:data:`KEPT_PER_THREAD` per thread, the oldest released as stock releases it; robosuite
1.5, unless its renderer is ``"mujoco"``, does not free it but lets go of it as
``_initialize_sim`` makes the next: offered the same way), and ``MjSim.from_xml_string``
makes the next simulation out of one of them when it can (two, because robosuite's
clients make two structures take turns: a task and the XML that
``DataCollectionWrapper`` or ``CameraMover`` reload from its ``get_xml()``):

- the model cache patches the kept simulation's own model in place, when the new XML has
  its structure (``DocumentCache.model(xml, into=...)``): the model MuJoCo compiles from
  the XML, every array and size, in the model the simulation already holds;
- its data is reset in place (``mj_resetData``: what a new ``MjData`` holds);
- its render context stays, with everything it has uploaded, when the patched model
  gives what a new context would take from it (:func:`_render_inputs`: the visual
  options, the extent, the texture, material, plane, mesh, height-field and skin values
  that ``mjr_makeContext`` reads; the bulk data, never written by a patch, is the data
  the context uploaded); its scene, camera, options and perturbation are made new, as a
  new context makes them. Otherwise the context is freed and robosuite makes a new one.

Then ``MujocoEnv._reset_internal`` runs the ``sim.forward()`` a new render context would
run, and ``MujocoEnv.reset`` leaves robosuite's observables their sensors
(:func:`keep_environment`). Anything else (another structure, no model cache, a
simulation class robosuite did not make this way) does what stock does. A process forked
while a simulation is kept (LIBERO's ``SubprocVectorEnv`` forks its workers) starts with
none: the child holds the inherited one untouched, since its OpenGL context is the
parent's. What a kept simulation saves is the compile, the ``gc.collect()``, the render
context and the observables' checks (a render per camera): docs/compiled.md says why
each kept thing gives stock's result.
"""

from __future__ import annotations

import os
import threading
from typing import Any, Callable

import numpy as np

from . import _settings
from ._mujoco import VISUAL
from ._last_xml import owe
from ._mjcf_forge import Document

_KEPT = threading.local()
# Simulations a forked child inherited kept: never used (their OpenGL contexts belong to
# the parent) and never freed (freeing would call into those contexts), only held.
_INHERITED: list = []


#: Simulations kept per thread, one per structure at most: a hard reset's task and the
#: XML robosuite's clients reload between episodes (DataCollectionWrapper's
#: reset_from_xml_string of get_xml(), CameraMover's scene with its mocap body) take turns.
KEPT_PER_THREAD = 2


def _kept() -> list:
    """This thread's kept simulations, most recent first, as ``(sim, freed)``."""
    kept = getattr(_KEPT, "sims", None)
    if kept is None:
        kept = _KEPT.sims = []
    return kept


def _forget_after_fork() -> None:
    _INHERITED.extend(getattr(_KEPT, "sims", None) or [])
    _KEPT.sims = []
    _KEPT.renewed = None


os.register_at_fork(after_in_child=_forget_after_fork)

# Arrays ``mjr_makeContext`` reads outside the bulk data (which a patch never writes):
# materials with textures, textures, meshes, height fields and skins.
_RENDER_ARRAYS = (
    "mat_texid", "mat_texuniform", "mat_texrepeat",
    "tex_type", "tex_width", "tex_height", "tex_nchannel", "tex_colorspace", "tex_adr",
    "mesh_vertadr", "mesh_vertnum", "mesh_normaladr", "mesh_texcoordadr", "mesh_faceadr",
    "mesh_facenum", "mesh_graphadr",
    "hfield_size", "hfield_nrow", "hfield_ncol", "hfield_adr",
    "skin_texcoordadr", "skin_vertnum", "skin_faceadr", "skin_facenum",
)


def _render_inputs(mujoco: Any, model: Any) -> bytes:
    """What a new render context takes from ``model`` besides the bulk data, as bytes:
    equal bytes, equal context."""
    parts = [np.float64(model.stat.extent).tobytes()]
    for group in VISUAL:
        obj = getattr(model.vis, group, None)
        for name in sorted(dir(obj)):
            if not name.startswith("_"):
                value = getattr(obj, name)
                if isinstance(value, (int, float, np.ndarray)):
                    parts.append(np.asarray(value).tobytes())
    for name in _RENDER_ARRAYS:
        value = getattr(model, name, None)
        if value is not None:
            parts.append(value.tobytes())
    # Planes: their grid is built from their size and their material's repeat.
    planes = model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE
    parts += [model.geom_size[planes].tobytes(), model.geom_matid[planes].tobytes()]
    return b"".join(parts)


def keep_render_inputs(context_class: Any) -> None:
    """Makes robosuite's render context remember what it was made from, each time its
    MuJoCo context is made (at creation and when robosuite enlarges its buffers)."""
    make = context_class.__dict__["_set_mujoco_context_and_buffers"]

    def _set_mujoco_context_and_buffers(self: Any) -> None:
        make(self)
        if _settings.model_cache() is None:
            return  # no simulation is kept: nothing will compare them
        import mujoco

        self._mjcf_forge_inputs = _render_inputs(mujoco, self.model._model)

    _set_mujoco_context_and_buffers.__doc__ = make.__doc__
    context_class._set_mujoco_context_and_buffers = _set_mujoco_context_and_buffers


def offer(sim: Any, freed: bool) -> None:
    """Keeps ``sim`` (freed by robosuite, or let go of) for this thread's next
    ``MjSim.from_xml_string``, which first releases, as stock releases them, the oldest
    beyond :data:`KEPT_PER_THREAD` (there, where stock frees its simulation: before the
    next is made, so that freeing a render context never unbinds the OpenGL context of a
    simulation made after it)."""
    kept = _kept()
    for i, (other, was_freed) in enumerate(kept):
        if other is sim:
            del kept[i]
            freed = freed or was_freed
            break
    kept.insert(0, (sim, freed))


def _trim(release: Callable[[Any, bool], None]) -> list:
    kept = _kept()
    while len(kept) > KEPT_PER_THREAD:
        release(*kept.pop())
    return kept


def keep_simulations(sim_class: Any) -> None:
    """``MjSim.free`` and ``MjSim.from_xml_string`` as the module says."""
    compile_sim = sim_class.__dict__["from_xml_string"].__func__
    free_sim: Callable[[Any], None] = sim_class.__dict__["free"]

    def release(sim: Any, freed: bool) -> None:
        """What stock does with a simulation not made again: frees the one robosuite
        freed, drops the one it let go of. Its render context is made current first:
        MuJoCo's ``mjr_freeContext`` deletes its textures and buffers by id in whatever
        OpenGL context is current, and ids repeat across contexts (stock frees the one
        context it has, current; a kept one may not be)."""
        _make_current(sim)
        if freed:
            free_sim(sim)

    def free(self: Any) -> None:
        if _settings.model_cache() is None:
            return free_sim(self)
        offer(self, True)

    def from_xml_string(cls: Any, xml: str) -> Any:
        cache = _settings.model_cache()
        kept = _trim(release)
        if cache is None:
            while kept:
                release(*kept.pop())
            return compile_sim(cls, xml)
        candidates = [sim for sim, _ in kept if type(sim) is cls]
        doc = Document.from_string(xml)
        if not candidates:
            model = cache.model(doc)
            # Stock loaded ``xml`` here: MuJoCo's last loaded XML model is owed it.
            owe(xml, served=model, files=doc.files("mesh"))
            return cls(model)
        model = cache.model(doc, into=[sim.model._model for sim in candidates])
        owe(xml, served=model, files=doc.files("mesh"))
        for i, (sim, _) in enumerate(kept):
            if sim.model._model is model:
                del kept[i]
                _renew(sim)
                _KEPT.renewed = sim
                return sim
        return cls(model)

    free.__doc__ = free_sim.__doc__
    from_xml_string.__doc__ = compile_sim.__doc__
    from_xml_string.__wrapped__ = compile_sim  # type: ignore[attr-defined]
    sim_class.free = free
    sim_class.from_xml_string = classmethod(from_xml_string)


def keep_environment(env_class: Any) -> None:
    """``MujocoEnv._initialize_sim``: the simulation it lets go of is offered (see the
    module); ``MujocoEnv.reset``: when the hard reset kept the simulation, robosuite's
    observables keep their sensors (see :func:`_kept_observables`); and
    ``MujocoEnv._reset_internal``: where stock makes the render context again, which
    runs ``sim.forward()`` first, a kept context has the simulation run it too: without
    that forward, LIBERO's libero_object 0 steps to other object poses in the last bits
    (a forward's results seed the next step's)."""
    reset = env_class.__dict__["reset"]
    reset_internal = env_class.__dict__["_reset_internal"]
    initialize_sim = env_class.__dict__["_initialize_sim"]

    def _initialize_sim(self: Any, xml_string: Any = None) -> Any:
        # A hard reset that does not free the simulation (robosuite 1.5's, unless its
        # renderer is "mujoco") lets go of it as the new one is made: offered too.
        sim = getattr(self, "sim", None)
        if sim is not None and _settings.model_cache() is not None and all(s is not sim for s, _ in _kept()):
            offer(sim, False)
        return initialize_sim(self, xml_string)

    _initialize_sim.__doc__ = initialize_sim.__doc__
    env_class._initialize_sim = _initialize_sim

    def _reset_internal(self: Any) -> Any:
        sim = getattr(_KEPT, "renewed", None)
        if sim is self.sim and sim._render_context_offscreen is not None:
            sim.forward()
        return reset_internal(self)

    _reset_internal.__doc__ = reset_internal.__doc__
    env_class._reset_internal = _reset_internal

    def reset_env(self: Any) -> Any:
        _KEPT.renewed = None
        self._setup_observables = lambda: _kept_observables(self)
        try:
            return reset(self)
        finally:
            del self._setup_observables
            _KEPT.renewed = None

    reset_env.__doc__ = reset.__doc__
    env_class.reset = reset_env


def _kept_observables(env: Any) -> Any:
    """What ``reset`` gets from ``env._setup_observables()``: the observables made again
    (stock: each sensor called once to check it, a render per camera, then once more when
    ``reset`` installs it in the observable of its name), or, when this reset kept the
    simulation, none, so that each observable keeps its sensor: a sensor reads the
    environment's simulation and references as they are when it runs, and this reset
    kept the simulation object and its names and ids (same structure)."""
    if getattr(_KEPT, "renewed", None) is env.sim:
        return {}
    return type(env)._setup_observables(env)


def _make_current(sim: Any) -> None:
    """Makes ``sim``'s render context's OpenGL context current, if it has one."""
    context = getattr(sim, "_render_context_offscreen", None)
    gl = getattr(context, "gl_ctx", None)
    if gl is not None:
        gl.make_current()


def _renew(sim: Any) -> None:
    """A kept simulation whose model was patched: as robosuite makes a new one."""
    import mujoco

    model = sim.model._model
    # The data reset in place (what a new MjData holds: MuJoCo makes one by resetting
    # it), not made again: robosuite's sensors keep views of its arrays
    # (ToolHang's ``pos_lookup = self.sim.data.body_xpos``).
    mujoco.mj_resetData(model, sim.data._data)
    context = sim._render_context_offscreen
    if context is None:
        return
    if getattr(context, "_mjcf_forge_inputs", None) != _render_inputs(mujoco, model):
        # Another context than this model makes: robosuite makes a new one (this one
        # freed with its own OpenGL context current: see release in keep_simulations).
        _make_current(sim)
        sim._render_context_offscreen = None
        del context
        return
    context.gl_ctx.make_current()
    context.scn = mujoco.MjvScene(model, maxgeom=context.scn.maxgeom)
    context.cam = mujoco.MjvCamera()
    context.cam.fixedcamid = 0
    context.cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
    context.vopt = mujoco.MjvOption()
    context.pert = mujoco.MjvPerturb()
    context.pert.active = 0
    context.pert.select = 0
    context.pert.skinselect = -1
