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
  appends them.

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


class _Loader(importlib.abc.Loader):
    """A robosuite module's own loader, then :func:`_adapt`."""

    def __init__(self, loader: Any):
        self._loader = loader

    def create_module(self, spec: Any) -> Any:
        return self._loader.create_module(spec)

    def exec_module(self, module: Any) -> None:
        self._loader.exec_module(module)
        _adapt(module)

    def __getattr__(self, name: str) -> Any:
        # get_source, get_resource_reader, is_package...: the module's own loader's.
        return getattr(self._loader, name)


class _Finder(importlib.abc.MetaPathFinder):
    """Finds robosuite's modules as the other finders do, with :class:`_Loader`."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> Optional[Any]:
        if fullname.partition(".")[0] != _PACKAGE:
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
            spec.loader = _Loader(spec.loader)
        return spec


_FINDER = _Finder()


def in_use() -> bool:
    """Whether :func:`use` has been called in this process."""
    return _FINDER in sys.meta_path


def use() -> None:
    """Makes robosuite's model classes build on :mod:`mjcf_forge.base` and its ``ET`` be
    :mod:`mjcf_forge.etree` (see the module's documentation). Call it once, before
    robosuite is imported; calling it again does nothing.

    Raises:
        RuntimeError: robosuite's models are already imported (their classes already
            derive from robosuite's own ``MujocoXML``)
    """
    if in_use():
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
    sys.meta_path.insert(0, _FINDER)
