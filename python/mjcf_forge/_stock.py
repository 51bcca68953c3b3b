"""robosuite's own rules for reading and merging models (``rules="robosuite"``), over our
documents: what :class:`mjcf_forge.base.MujocoXML` does when
:func:`mjcf_forge.base.set_rules` (or :func:`mjcf_forge.robosuite.use`) asks for the models
stock robosuite builds, bit for bit, rather than the ones MuJoCo's rules give.

robosuite 1.4.0 and 1.5.2 (``robosuite.models.base``) do the same here:

- **default classes**: the classes directly under the file's first ``<default>`` are
  inlined, each with the attributes it sets itself (not those it would inherit); an
  element's ``class`` is dropped; the ``<default>`` goes, and with it the main class's
  defaults and what ``childclass`` would have applied;
- **merge**: the part's ``<worldbody>`` children, assets, actuators, sensors, tendons,
  equalities and contacts are appended; its ``<compiler>`` (angle units, Euler sequences,
  inertia settings...), keyframes, custom data, plugins and every other section are
  dropped, so the part's values are read under the base's compiler;
- **assets**: a part's asset is left out when the base has one of the same tag and
  ``name`` attribute, whatever its content (the part's geoms then take the base's); two
  unnamed assets of one tag count as the same name.

Everything else (includes, file paths, prefixes, the name lists) is as with MuJoCo's
rules. docs/model-hierarchy.md lists where robosuite's rules give another model than
MuJoCo's, and where robosuite fails and these rules do better.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as _XET
from collections import OrderedDict
from typing import Any, Callable

from ._mjcf_forge import Document

# Documents read by robosuite's rules, by path: (the file's bytes, the document). A file
# with the same bytes is a copy of the document; a file with <include> is read anew.
_LOADS: "OrderedDict[str, tuple[bytes, Any]]" = OrderedDict()
_LOADS_MAX = 256


def load(fname: str, load_exact: Callable[[str], Any], error: Callable[[str], Exception]) -> Any:
    """The document of ``fname`` with its default classes inlined as robosuite inlines
    them. A file without ``<default`` is read by ``load_exact`` (the same: there is nothing
    to inline, and robosuite drops nothing)."""
    try:
        with open(fname, "rb") as f:
            data = f.read()
    except OSError:
        return load_exact(fname)  # which says what is wrong, as for any file
    if b"<default" not in data:
        return load_exact(fname)
    key = os.path.abspath(fname)
    kept = _LOADS.get(key)
    if kept is not None and kept[0] == data:
        _LOADS.move_to_end(key)
        return kept[1].copy()
    try:
        root = _XET.fromstring(data)
    except _XET.ParseError:
        # The exact reader says where and what, as for any unreadable file.
        return load_exact(fname)
    if root.tag == "robot":
        # URDF: no default classes of robosuite's to inline (the reader converts it).
        return load_exact(fname)
    _inline_defaults(root, fname, error)
    doc = Document.from_string(_XET.tostring(root, encoding="unicode"), os.path.dirname(os.path.abspath(fname)))
    if b"<include" not in data:
        _LOADS[key] = (data, doc.copy())
        if len(_LOADS) > _LOADS_MAX:
            _LOADS.popitem(last=False)
    return doc


def _inline_defaults(root: Any, fname: str, error: Callable[[str], Exception]) -> None:
    """robosuite's ``_get_default_classes`` and ``_replace_defaults_inline`` on an
    ``xml.etree`` tree, then the ``<default>`` removed. A class robosuite would not find
    (a nested one, or one of another ``<default>``: robosuite raises ``KeyError``) is an
    error naming the file, the element and the class."""
    default = root.find("default")
    if default is None:
        return
    classes = {cls.get("class"): {child.tag: child for child in cls} for cls in default}
    missing = []
    stack = [root]
    while stack:
        element = stack.pop()
        name = element.attrib.pop("class", None)
        if name is not None:
            if name not in classes:
                what = element.get("name")
                missing.append(
                    "{}: <{}{}> has class {!r}, which is not a class directly under the first "
                    "<default>: robosuite's rules cannot inline it (robosuite raises KeyError); "
                    "MuJoCo's rules can (mjcf_forge.base.set_rules('mujoco'))".format(
                        fname, element.tag, " name={!r}".format(what) if what else "", name
                    )
                )
            else:
                values = classes[name].get(element.tag)
                if values is not None:
                    for k, v in values.items():
                        if element.get(k) is None:
                            element.set(k, v)
        stack.extend(reversed(list(element)))
    if missing:
        raise error("\n".join(missing))
    root.remove(default)


# The sections robosuite's merge carries besides the worldbody and the assets, in its order.
_CARRIED = ("actuator", "sensor", "tendon", "equality", "contact")


def merge(base: Any, other: Any, into: Any) -> None:
    """robosuite's ``MujocoXML.merge`` of one part: ``into`` (an element of ``base``, or
    None for no worldbody children) gets the part's worldbody children, ``base`` the part's
    assets (by ``base.merge_assets``, which a subclass may override) and sections."""
    if into is not None:
        for body in list(other.worldbody):
            into.append(body)
    base.merge_assets(other)
    for section in _CARRIED:
        mine = getattr(base, section)
        for element in list(getattr(other, section)):
            mine.append(element)


def merge_assets(base: Any, other: Any) -> None:
    """robosuite's ``merge_assets``: each of the part's assets unless ``base`` has one of
    the same tag and ``name`` attribute (compared as text; two unnamed ones match)."""
    have = {(asset.tag, asset.get("name")) for asset in base.asset.iter() if asset is not base.asset}
    for asset in list(other.asset):
        key = (asset.tag, asset.get("name"))
        if key not in have:
            base.asset.append(asset)
            have.add(key)
