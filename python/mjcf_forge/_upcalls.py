"""Everything the compiled module calls in Python, in one place: ``python/src/upcalls.rs``
looks each up here by name, and nowhere else.

- :func:`compile_inertia`: the installed ``mujoco`` compiling a part alone
  (``Document.merge(compile_inertia=...)``, a scene group's ``write_inertials``);
- ``preview``: a contact sheet drawn with the installed ``mujoco`` (``Scene.preview``);
- ``progress_of``: a progress reporter (``Scene.variants(progress=...)``);
- ``fromstring``: an element rebuilt from its XML (pickling an ``Element``);
- ``MjcfFileNotFoundError``: the error raised when every problem is a missing file;
- :func:`mujoco_version`: the installed ``mujoco``'s version, whose URDF importer a URDF
  is read as (``Document.load``, ``Document.from_urdf``);
- ``compile_xml``, ``inertia_diagonal``, ``make_inertia``: a ``PatchPlan`` compiling its
  body models with the user's ``mujoco`` (leaving MuJoCo's last loaded XML model alone)
  and finding the joint-space inertia as that version keeps it (``_mujoco.py``).
"""

from __future__ import annotations

import functools
import sys
from typing import Any, Optional

from ._errors import MjcfFileNotFoundError
from ._last_xml import compile_xml
from ._mjcf_utils import without_materials
from ._mujoco import (
    inertia_diagonal,
    make_inertia,
    model_bytes,
    model_from_bytes,
    signature_offset,
    snapshot_fields,
)
from ._preview import preview
from ._progress import progress_of
from ._settings import model_cache
from .etree import fromstring

__all__ = [
    "MjcfFileNotFoundError",
    "compile_inertia",
    "compile_xml",
    "fromstring",
    "inertia_diagonal",
    "make_inertia",
    "model_bytes",
    "model_from_bytes",
    "signature_offset",
    "mujoco_version",
    "preview",
    "progress_of",
    "snapshot_fields",
]


def compile_inertia(xml: str, model_dir: Any) -> tuple:
    """The bodies' names, masses and inertias as the installed ``mujoco`` compiles ``xml``
    alone: what a merge writes out when a part's compiler mass settings differ from the
    base's (``Document.merge(compile_inertia=...)``). Through the process's model cache
    when it is on: robosuite merges the same arena at every hard reset."""
    import mujoco

    xml = without_materials(xml)
    cache = model_cache()
    model = cache.model(xml) if cache is not None else compile_xml(mujoco, xml)
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, i) or "" for i in range(model.nbody)]
    return (
        names,
        model.body_mass.ravel().tolist(),
        model.body_ipos.ravel().tolist(),
        model.body_iquat.ravel().tolist(),
        model.body_inertia.ravel().tolist(),
    )


@functools.lru_cache(maxsize=None)
def mujoco_version() -> Optional[str]:
    """The installed ``mujoco``'s version, or ``None`` when none is installed: the URDF
    importer a load follows (``Document.load`` of a URDF file, ``Document.from_urdf``
    without ``importer=``, a scene's URDF models). Read from the package's metadata, so
    that asking never imports ``mujoco`` (which must come after ``MUJOCO_GL`` is set, for
    ``Scene.preview``); an imported ``mujoco`` answers for itself."""
    module = sys.modules.get("mujoco")
    version = getattr(module, "__version__", None) if module is not None else None
    if isinstance(version, str):
        return version
    try:
        from importlib import metadata

        return metadata.version("mujoco")
    except Exception:  # noqa: BLE001 - not installed
        return None
