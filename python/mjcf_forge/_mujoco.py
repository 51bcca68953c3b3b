"""What differs between the versions of the user's ``mujoco`` the caches run on (3.3 to
4.0), in one place: the rest of the package asks here instead of testing for fields.

- the joint-space inertia: ``mj_makeM`` where MuJoCo has it, else ``mj_crb`` (3.3),
  which fills ``qM`` the same way;
- its diagonal: the last entry of each row of ``data.M`` (sparse rows: ``M_rowadr``,
  ``M_rownnz``, from 3.9 or so), else ``data.qM`` at ``dof_Madr`` (3.3: the same numbers);
- fields some versions do not have (``dof_length``, ``body_simple``, ``M_rownnz``):
  :func:`field` gives ``None`` for them.
"""

from __future__ import annotations

from typing import Any

import numpy as np


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
