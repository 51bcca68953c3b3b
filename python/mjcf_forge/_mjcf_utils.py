"""robosuite's ``mjcf_utils`` helpers that :mod:`mjcf_forge.base` uses, with MuJoCo's
rules where robosuite's differ, and the element helpers its merges need.

``base`` re-exports the public ones (``array_to_string``, ``string_to_array``,
``sort_elements``) and robosuite's private ``_element_filter``. The rule of
:func:`element_filter` is written once, in Rust (``mjcf_forge::sort``, the one
``mjcf_forge.Model``'s lists run too): :func:`sort_elements` with the default filter over
our elements runs it natively (``Element._sort_elements``), as ``base`` does
(``Document._sort_elements``); the Python functions stay, robosuite's replaceable API,
for a filter of the user's, for ``xml.etree`` elements, and as what a replaced
``group`` or ``tree_parent`` changes.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Optional

import numpy as np


def array_to_string(array: Any) -> str:
    """``[0, 1, 2]`` as ``"0 1 2"`` (robosuite's ``array_to_string``).

    >>> array_to_string([0, 1.5, 2])
    '0 1.5 2'
    """
    return " ".join(["{}".format(x) for x in array])


def string_to_array(string: str) -> np.ndarray:
    """``"0 1 2"`` as ``array([0., 1., 2.])`` (any white space between numbers).

    >>> string_to_array(" 0  1\\t2").tolist()
    [0.0, 1.0, 2.0]
    """
    return np.array([float(x) for x in string.split()])


# Where MuJoCo takes a <body>, <geom>, <site> or <joint> as part of the kinematic tree.
TREE = {"worldbody", "body", "frame", "replicate"}


def group(element: Any) -> Optional[int]:
    """A geom's group as MuJoCo reads it (0 when absent), or None if it is no integer."""
    value = element.get("group")
    if value is None:
        return 0
    try:
        return int(value.strip())
    except ValueError:
        return None


def tree_parent(element: Any, parent: Any) -> bool:
    """Whether ``parent`` holds ``element`` in the kinematic tree."""
    return parent is not None and parent.tag in TREE


def element_filter(element: Any, parent: Any) -> Optional[str]:
    """robosuite's ``_element_filter`` with MuJoCo's scopes: the key ``element`` is sorted
    under (``"root_body"``, ``"bodies"``, ``"joints"``, ``"actuators"``, ``"sites"``,
    ``"sensors"``, ``"contact_geoms"``, ``"visual_geoms"``), or None.

    Bodies, joints, sites and geoms count only in the kinematic tree (not a tendon's
    ``<site>``/``<geom>`` wrap references, an equality's ``<joint>``, or ``<default>``);
    a body is the root body when no body encloses it (frames do not count); every child
    of ``<sensor>`` is a sensor. As robosuite: ``<freejoint>`` is not listed, geoms of
    groups other than 0 and 1 are not.
    """
    tag = element.tag
    if parent is not None and parent.tag == "actuator":
        return "actuators"
    if parent is not None and parent.tag == "sensor":
        return "sensors"
    if not tree_parent(element, parent):
        return None
    if tag == "joint":
        return "joints"
    if tag == "body":
        above = parent
        while above is not None and above.tag in ("frame", "replicate"):
            above = above.parent
        return "bodies" if above is not None and above.tag == "body" else "root_body"
    if tag == "site":
        return "sites"
    if tag == "geom":
        kind = group(element)
        if kind == 0:
            return "contact_geoms"
        if kind == 1:
            return "visual_geoms"
    return None


def sort_elements(
    root: Any,
    parent: Any = None,
    element_filter: Optional[Callable[[Any, Any], Optional[str]]] = None,
    _elements_dict: Optional[dict] = None,
) -> dict:
    """robosuite's ``sort_elements``: every element under ``root`` (itself included, in
    document order) grouped in lists under the key ``element_filter(element, parent)``
    returns (None: left out). The default filter is :func:`element_filter`."""
    if element_filter is None and _elements_dict is None and _native_default(root, parent):
        elements, _names = root._sort_elements()
        return elements
    if _elements_dict is None:
        _elements_dict = {}
    if element_filter is None:
        element_filter = globals()["element_filter"]
    # Depth first in document order, without recursion (models nest deep).
    stack = [(root, parent)]
    while stack:
        element, above = stack.pop()
        key = element_filter(element, above)
        if key is not None:
            _elements_dict.setdefault(key, []).append(element)
        children = list(element)
        stack.extend((child, element) for child in reversed(children))
    return _elements_dict


# The rule's functions as written here: while they are the ones in use, the native sort
# (mjcf_forge::sort) is theirs.
_RULE = {"element_filter": element_filter, "group": group, "tree_parent": tree_parent}


def _native_default(root: Any, parent: Any) -> bool:
    """Whether ``sort_elements(root, parent)`` with the default filter may run natively:
    ``root`` is one of our elements, ``parent`` its own parent (the filter reads both),
    and the rule's functions are not replaced on this module."""
    from ._mjcf_forge import Element

    g = globals()
    return (
        isinstance(root, Element)
        and parent is root.parent
        and all(g[name] is fn for name, fn in _RULE.items())
    )


def without_materials(xml: str) -> str:
    """``xml`` without its materials and textures, and without every reference to a
    material: what no mass or inertia depends on. A part may refer to materials that the
    model it goes into gets only later (robosuite's TwoArmPegInHole puts a peg with its
    material into each robot and merges the material into the task afterwards), so the
    part alone is compiled without them (and without decoding textures).

    >>> without_materials('<mujoco><geom material="m"/></mujoco>')
    '<mujoco><geom /></mujoco>'
    """
    import xml.etree.ElementTree as XET

    root = XET.fromstring(xml)
    for asset in root.iter("asset"):
        for child in [c for c in asset if c.tag in ("material", "texture")]:
            asset.remove(child)
    for element in root.iter():
        element.attrib.pop("material", None)
    return XET.tostring(root, encoding="unicode")


def named(names: list) -> list:
    """The names of a raw list (robosuite's ``_joints`` and friends) without the ``None``
    of unnamed elements, which no name can refer to."""
    return [n for n in names if n is not None]


def same_subtree(a: Any, b: Any) -> bool:
    """Same tag, attributes (any order), text and children, recursively."""
    if a.tag != b.tag or dict(a.items()) != dict(b.items()):
        return False
    if (a.text or "").strip() != (b.text or "").strip():
        return False
    kids_a, kids_b = list(a), list(b)
    return len(kids_a) == len(kids_b) and all(same_subtree(x, y) for x, y in zip(kids_a, kids_b))


# Assets MuJoCo names after their file when they have no name of their own.
NAMED_AFTER_FILE = {"mesh", "texture", "hfield", "skin"}


def asset_name(asset: Any) -> Optional[str]:
    """The name MuJoCo gives ``asset``: its own, or, for a file-backed one without, its
    file's stem."""
    name = asset.get("name")
    if name:
        return name
    if asset.tag in NAMED_AFTER_FILE and asset.get("file"):
        stem = os.path.splitext(os.path.basename(asset.get("file").replace("\\", "/")))[0]
        return stem or None
    return None
