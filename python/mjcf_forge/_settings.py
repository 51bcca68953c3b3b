"""The process-wide settings of :mod:`mjcf_forge.base` (which re-exports them): the
rules :class:`~mjcf_forge.base.MujocoXML` reads and merges by, and the process's model
cache, through which ``get_model`` and the robosuite switch compile."""

from __future__ import annotations

import os
from typing import Any, Optional

# The rules MujocoXML reads and merges by (see set_rules).
RULES = ("mujoco", "robosuite")
_rules = "mujoco"


def rules() -> str:
    """The rules :class:`~mjcf_forge.base.MujocoXML` reads default classes and merges
    models by: ``"mujoco"`` (the default) or ``"robosuite"`` (see :func:`set_rules`)."""
    return _rules


def set_rules(rules: str) -> str:
    """Sets the rules :class:`~mjcf_forge.base.MujocoXML` reads and merges by, for the
    models made from then on, and returns the rules it replaces.

    - ``"mujoco"``: MuJoCo's. Default classes inlined exactly; a merge converts a part's
      compiler settings (angles, Euler sequences, mass settings with the installed
      ``mujoco``) so that every part compiles to what it compiles to alone, shares
      identical assets and refuses a name clash, and carries every section. A merged
      model can differ from stock robosuite's: the table's mass, joint ranges of parts
      written in degrees, a clashing asset refused (docs/model-hierarchy.md).
    - ``"robosuite"``: stock robosuite's (1.4.0 and 1.5.2 alike), so that a model compiles
      to the one stock robosuite builds: only the top-level default classes inlined, a
      part's ``<compiler>`` dropped (its values read under the base's), the base's asset
      kept where a part repeats a name, seven sections carried (module
      ``mjcf_forge._stock``). What :func:`mjcf_forge.robosuite.use` sets by default.

    >>> from mjcf_forge import base
    >>> previous = base.set_rules("robosuite")
    >>> base.rules()
    'robosuite'
    >>> _ = base.set_rules(previous)

    Raises:
        ValueError: rules other than ``"mujoco"`` and ``"robosuite"``
    """
    global _rules
    if rules not in RULES:
        raise ValueError(f"rules are 'mujoco' or 'robosuite', not {rules!r}")
    previous, _rules = _rules, rules
    return previous


#: The environment variable that turns the process's model cache off before it is made:
#: ``MJCF_FORGE_MODEL_CACHE=0`` (or ``off``, ``false``, ``no``).
MODEL_CACHE_ENV = "MJCF_FORGE_MODEL_CACHE"

_UNSET: Any = object()
_model_cache: Any = _UNSET


def model_cache() -> Optional[Any]:
    """The process's :class:`~mjcf_forge.DocumentCache`, through which
    :meth:`~mjcf_forge.base.MujocoXML.get_model` (and, with
    :func:`mjcf_forge.robosuite.use`, robosuite's simulations) compiles, or ``None`` when
    it is off.

    On by default: made on first use (at most 8 structures, least recently used out), unless
    the environment variable ``MJCF_FORGE_MODEL_CACHE`` is ``0``, ``off``, ``false`` or
    ``no``; it keeps its structures in the environment's model store
    (``MJCF_FORGE_STORE``, else the user cache folder), so a structure any process compiled
    is a load and a patch. :func:`set_model_cache` replaces it or turns it off.
    """
    global _model_cache
    if _model_cache is _UNSET:
        if os.environ.get(MODEL_CACHE_ENV, "").strip().lower() in ("0", "off", "false", "no"):
            _model_cache = None
        elif not caches_run_on_this_mujoco():
            _model_cache = None
        else:
            from ._doc_cache import DocumentCache

            # With the environment's model store (MJCF_FORGE_STORE, else the user
            # cache folder): a structure compiled by any process is a load and a patch.
            _model_cache = DocumentCache(max_models=8)
    return _model_cache


#: The oldest MuJoCo the caches (model cache, patches, kept simulations) run on.
OLDEST_CACHED_MUJOCO = (3, 3)


def caches_run_on_this_mujoco() -> bool:
    """Whether the installed ``mujoco`` is one the caches run on (3.3 and newer). On an
    older one (robosuite 1.4.0 accepts MuJoCo 2.3; libero-infinity pins it), the
    process's model cache is off and every model compiles as stock compiles it, which is
    said once, as a warning; everything else of the package runs as on any MuJoCo."""
    from ._mujoco import version_tuple
    from ._upcalls import mujoco_version

    version = mujoco_version()
    parts = version_tuple(version)
    if parts is None or parts >= OLDEST_CACHED_MUJOCO:
        return True
    import warnings

    warnings.warn(
        f"mjcf_forge: the model cache needs MuJoCo {'.'.join(map(str, OLDEST_CACHED_MUJOCO))} "
        f"or newer, and this is {version}: models compile as stock compiles them "
        "(mujoco.MjModel.from_xml_string), at stock's cost",
        RuntimeWarning,
        stacklevel=3,
    )
    return False


def set_model_cache(cache: Any) -> Optional[Any]:
    """Sets the process's model cache (see :func:`model_cache`) and returns the one it
    replaces (``None`` if it was off), so a caller can put it back.

    Args:
        cache: a :class:`~mjcf_forge.DocumentCache` (yours, with your bounds), ``True`` (a
            new default one), or ``None`` / ``False`` (off: every ``get_model`` compiles)

    >>> from mjcf_forge import base
    >>> previous = base.set_model_cache(None)      # off: MuJoCo compiles every model
    >>> base.model_cache() is None
    True
    >>> _ = base.set_model_cache(previous)         # as it was
    """
    global _model_cache
    from ._doc_cache import DocumentCache

    if cache is True:
        cache = DocumentCache(max_models=8)
    elif cache is False:
        cache = None
    elif cache is not None and not isinstance(cache, DocumentCache):
        raise TypeError(f"set_model_cache takes a DocumentCache, True, False or None, not {type(cache).__name__}")
    previous = model_cache()
    _model_cache = cache
    return previous
