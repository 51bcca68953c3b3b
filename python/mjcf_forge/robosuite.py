"""robosuite's own model classes, built on :mod:`mjcf_forge.base`.

One call, before robosuite is imported::

    import mjcf_forge.robosuite
    mjcf_forge.robosuite.use()

    import robosuite                 # its robots, grippers, mounts, objects, arenas and
    env = robosuite.make("Lift", robots="Panda")   # tasks now read and merge with ours

:func:`use` installs an import hook for the ``robosuite`` package. After each of its
modules has run:

- ``robosuite.models.base``'s ``MujocoXML``, ``MujocoModel`` and ``MujocoXMLModel`` are
  :mod:`mjcf_forge.base`'s, so every robosuite class derived from them (``RobotModel``,
  ``GripperModel``, ``MountModel``, ``Arena``, ``MujocoXMLObject``, ``Task``, ...) builds
  on ours, unchanged: its files read as MuJoCo reads them, its merges by MuJoCo's rules,
  its prefixes exact (``mjcf_forge.base`` lists where that differs from robosuite);
- every module-level name bound to ``xml.etree.ElementTree`` (robosuite's ``ET``) is
  :mod:`mjcf_forge.etree`, so the elements robosuite makes (``new_element``,
  ``ET.Element``, ``ET.fromstring``) are ours and go into our documents as robosuite
  appends them;
- ``robosuite.utils.binding_utils.MjSim.from_xml_string`` (what an environment's hard
  reset compiles its task with) gets its model from the process's model cache
  (:func:`mjcf_forge.base.model_cache`, on by default): a reset compiles only a structure
  the cache has not seen, and otherwise patches that structure's model, a model no
  earlier simulation still holds, with every array written back as compiled first (so
  ``DomainRandomizationWrapper``'s changes do not outlive the reset);
- ``MjSim.free`` keeps the simulation a hard reset frees (the last two per thread), and a
  later ``from_xml_string`` of its thread makes it the new one when the XML has its
  structure:
  its own model patched in place, its data reset, its render context kept with what it
  uploaded (when the patched model gives a new context the same inputs), and
  ``MujocoEnv.reset`` then leaves robosuite's observables their sensors instead of
  making them again (:mod:`mjcf_forge._sims`; docs/compiled.md says why each kept
  thing gives stock's result);
- MuJoCo's last loaded XML model, which robosuite's ``MjModel.get_xml()`` writes
  (``mujoco.mj_saveLastXML``: what ``DataCollectionWrapper``, robomimic and MimicGen
  save with every demonstration), is stock's: each load the cache serves is owed to it,
  and given to it when it is read (:mod:`mjcf_forge._last_xml`);
- ``RobotModel.mujoco_model``, the robot compiled alone at every load
  (``set_mujoco_model()``), which robosuite never reads, is compiled on first read, from
  the robot as it was when ``set_mujoco_model()`` was called.

robosuite's own code keeps running as written, its ``mjcf_utils`` included: objects that
robosuite builds element by element (``MujocoGeneratedObject``, ``MujocoXMLObject``'s
subtree) are prefixed by robosuite's ``add_prefix``, as before. ``except XMLError`` with
robosuite's class catches ours (:class:`mjcf_forge.base.XMLError`).

The hook rebinds names after a module has run, so what a module does with ``ET`` while it
is imported is xml.etree's (robosuite does nothing with it then).
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import sys
import xml.etree.ElementTree as _XET
from typing import Any, Optional

from . import base as _base
from . import _last_xml
from . import _sims
from . import etree as _etree

__all__ = ["use", "in_use"]

_PACKAGE = "robosuite"


def _adapt(module: Any) -> None:
    """What :func:`use` changes in a robosuite module that has just run."""
    for name, value in list(vars(module).items()):
        if value is _XET:
            setattr(module, name, _etree)
    if module.__name__ == "robosuite.models.base":
        module.MujocoXML = _base.MujocoXML
        module.MujocoModel = _base.MujocoModel
        module.MujocoXMLModel = _base.MujocoXMLModel
    elif module.__name__ == "robosuite.utils.binding_utils":
        _sims.keep_simulations(module.MjSim)
        _sims.keep_render_inputs(module.MjRenderContext)
    elif module.__name__ == "robosuite.environments.base":
        _sims.keep_environment(module.MujocoEnv)
    elif module.__name__ == "robosuite.models.robots.robot_model":
        _lazy_robot_model(module.RobotModel)


class _Pending:
    """A robot's model not compiled yet: the robot's document as it was when
    ``set_mujoco_model()`` was called (a copy: the robot is merged into its task later)."""

    __slots__ = ("document",)

    def __init__(self, document: Any) -> None:
        self.document = document


class _LazyModel:
    """``RobotModel.mujoco_model``: what ``set_mujoco_model()`` was given, or the robot
    compiled on first read (through :meth:`mjcf_forge.base.MujocoXML.get_model`'s cache)."""

    def __get__(self, robot: Any, owner: Any = None) -> Any:
        if robot is None:
            return self
        value = robot.__dict__.get("_mjcf_forge_model")
        if isinstance(value, _Pending):
            cache = _base.model_cache()
            if cache is not None:
                value = cache.model(value.document)
            else:
                import mujoco

                value = _last_xml.compile_xml(mujoco, value.document.to_xml())
            robot.__dict__["_mjcf_forge_model"] = value
        return value

    def __set__(self, robot: Any, value: Any) -> None:
        robot.__dict__["_mjcf_forge_model"] = value


def _lazy_robot_model(robot_class: Any) -> None:
    robot_class.mujoco_model = _LazyModel()

    def set_mujoco_model(self: Any, mujoco_model: Any = None) -> None:
        if mujoco_model is not None:
            self.mujoco_model = mujoco_model
        else:
            pending = _Pending(self.document.copy())
            self.mujoco_model = pending
            # Stock compiles the robot here with mujoco.MjModel.from_xml_string: MuJoCo's
            # last loaded XML model is owed it (written only if read before the next load).
            _last_xml.owe(pending.document.to_xml, files=pending.document.files("mesh"))

    set_mujoco_model.__doc__ = (
        "Sets ``mujoco_model``: the model given, or else this robot compiled alone, "
        "on first read (mjcf_forge.robosuite)."
    )
    robot_class.set_mujoco_model = set_mujoco_model


def _adapt_mujoco(module: Any) -> None:
    """What :func:`use` changes in ``mujoco`` once it has run: its loaders and
    ``mj_saveLastXML`` wrapped (:mod:`mjcf_forge._last_xml`), so that what MuJoCo's last
    loaded XML model holds is known from the first load on."""
    _last_xml.install(module)


class _Loader(importlib.abc.Loader):
    """A module's own loader, then ``adapt`` (:func:`_adapt` for robosuite's)."""

    def __init__(self, loader: Any, adapt: Any):
        self._loader = loader
        self._adapt = adapt

    def create_module(self, spec: Any) -> Any:
        return self._loader.create_module(spec)

    def exec_module(self, module: Any) -> None:
        self._loader.exec_module(module)
        self._adapt(module)

    def __getattr__(self, name: str) -> Any:
        # get_source, get_resource_reader, is_package...: the module's own loader's.
        return getattr(self._loader, name)


class _Finder(importlib.abc.MetaPathFinder):
    """Finds robosuite's modules and ``mujoco`` as the other finders do, with
    :class:`_Loader`."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> Optional[Any]:
        if fullname == "mujoco":
            adapt = _adapt_mujoco
        elif fullname.partition(".")[0] == _PACKAGE:
            adapt = _adapt
        else:
            return None
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec(fullname, path, target)
            if spec is not None:
                break
        else:
            return None
        if spec.loader is not None and hasattr(spec.loader, "exec_module"):
            spec.loader = _Loader(spec.loader, adapt)
        return spec


_FINDER = _Finder()


def in_use() -> bool:
    """Whether :func:`use` has been called in this process."""
    return _FINDER in sys.meta_path


def use(rules: str = "robosuite") -> None:
    """Makes robosuite's model classes build on :mod:`mjcf_forge.base` and its ``ET`` be
    :mod:`mjcf_forge.etree` (see the module's documentation). Call it once, before
    robosuite is imported; calling it again changes only the rules.

    Args:
        rules: ``"robosuite"`` (the default): every model compiles to the one stock
            robosuite builds, bit for bit, its merge rules included (a part's
            ``<compiler>`` dropped, the base's asset kept where a part repeats its name).
            ``"mujoco"``: MuJoCo's rules, where each merged part compiles to what it
            compiles to alone (another model than stock's where robosuite's rules differ:
            the table's mass, the joint ranges of parts written in degrees). Sets
            :func:`mjcf_forge.base.set_rules`.

    Raises:
        RuntimeError: robosuite's models are already imported (their classes already
            derive from robosuite's own ``MujocoXML``)
        ValueError: other rules
    """
    if in_use():
        _base.set_rules(rules)
        return
    loaded = sorted(
        name
        for name in sys.modules
        if name == "robosuite.models" or name.startswith(("robosuite.models.", "robosuite.utils.mjcf_utils"))
    )
    if loaded:
        raise RuntimeError(
            "mjcf_forge.robosuite.use() must come before robosuite is imported: "
            f"{loaded[0]} is already imported"
        )
    _base.set_rules(rules)
    sys.meta_path.insert(0, _FINDER)
    if "mujoco" in sys.modules:
        _adapt_mujoco(sys.modules["mujoco"])
