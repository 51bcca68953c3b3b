"""What differs between the versions of the user's ``mujoco`` the caches run on (3.3 to
4.0), in one place: the rest of the package asks here instead of testing for fields.

- the joint-space inertia: ``mj_makeM`` where MuJoCo has it, else ``mj_crb`` (3.3),
  which fills ``qM`` the same way;
- its diagonal: the last entry of each row of ``data.M`` (sparse rows: ``M_rowadr``,
  ``M_rownnz``, from 3.9 or so), else ``data.qM`` at ``dof_Madr`` (3.3: the same numbers);
- fields some versions do not have (``dof_length``, ``body_simple``, ``M_rownnz``):
  :func:`field` gives ``None`` for them;
- which of a model's arrays are bulk data (:func:`restored_arrays`: the rest), the
  number fields of its structs (:func:`struct_fields`) and the parts of ``mjVisual``.
"""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ._mjcf_forge import BULK_PREFIXES, BULK_SIZES


def make_inertia(mujoco: Any, model: Any, data: Any) -> None:
    """Fills ``data``'s joint-space inertia (``qM``, and ``M`` where MuJoCo has it) from
    its kinematics."""
    (getattr(mujoco, "mj_makeM", None) or mujoco.mj_crb)(model, data)


def inertia_diagonal(model: Any, data: Any) -> tuple[np.ndarray, np.ndarray]:
    """The array that holds ``data``'s joint-space inertia and the indices of its
    diagonal in it (one per degree of freedom), live: read after :func:`make_inertia`."""
    if hasattr(data, "M"):
        return data.M, model.M_rowadr + model.M_rownnz - 1
    return data.qM, model.dof_Madr.copy()


def field(obj: Any, name: str) -> Any:
    """``obj.name`` (a model's or data's field), or ``None`` where this MuJoCo has none."""
    return getattr(obj, name, None)


# The sizes that count rows of mesh, texture, height field, skin and bounding-volume data
# (BULK_SIZES), and the same arrays by name for a mujoco without introspection
# (BULK_PREFIXES): the split tier's tables (mjcf_forge::split, through the extension). No
# patch writes them and they are most of a model's bytes (70 MB of lift5's 70.5), so they
# are not restored before a patch (see DocumentCache).
_BULK_SIZES = frozenset(BULK_SIZES)
# The parts of mjVisual, each a struct of numbers.
VISUAL = ("global_", "quality", "headlight", "map", "scale", "rgba")


def restored_arrays(mujoco: Any, model: Any) -> list[str]:
    """The arrays of ``model`` but the bulk data (mesh, texture, height-field, skin and
    bounding-volume data): what a patch may write and ``mj_copyBack`` reads, but height
    fields' data."""
    try:
        from mujoco.introspect import structs

        fields = structs.STRUCTS["mjModel"].fields
        names = [
            f.name
            for f in fields
            if getattr(f, "array_extent", None) and str(f.array_extent[0]) not in _BULK_SIZES
        ]
    except (ImportError, KeyError, AttributeError):
        names = [n for n in dir(model) if not n.startswith(("_",) + BULK_PREFIXES)]
    return [n for n in names if isinstance(getattr(model, n, None), np.ndarray)]


def snapshot_fields(mujoco: Any, model: Any) -> list[tuple[tuple[str, ...], str]]:
    """What ``DocumentCache`` writes back into a model before each patch, as
    ``(path, name)`` pairs (``model.<path...>.<name>``): every array but the bulk data
    (:func:`restored_arrays`), and the numbers of ``model.opt`` and ``model.vis``.

    >>> import mujoco
    >>> model = mujoco.MjModel.from_xml_string("<mujoco/>")
    >>> fields = snapshot_fields(mujoco, model)
    >>> ((), "body_mass") in fields, (("opt",), "timestep") in fields
    (True, True)
    """
    fields: list[tuple[tuple[str, ...], str]] = [((), n) for n in restored_arrays(mujoco, model)]
    for path in [("opt",)] + [("vis", v) for v in VISUAL]:
        obj = model
        for part in path:
            obj = getattr(obj, part, None)
        if obj is not None:
            fields.extend((path, n) for n in struct_fields(obj))
    return fields


def struct_fields(obj: Any) -> list[str]:
    """The number fields of a struct of the bindings (``model.opt``, ``model.vis.map``)."""
    return [
        n
        for n in dir(obj)
        if not n.startswith("_")
        and isinstance(getattr(obj, n, None), (int, float, np.ndarray))
        and not callable(getattr(obj, n))
    ]


def version_tuple(version: Any) -> Optional[tuple]:
    """A MuJoCo version's (major, minor), or ``None`` where it is not one
    (``"3.16.0"`` -> ``(3, 16)``)."""
    try:
        parts = tuple(int(p) for p in str(version or "").split(".")[:2])
    except ValueError:
        return None
    return parts if len(parts) == 2 else None
