"""Which values of an XML text MuJoCo's writer takes from the model, and whether two texts
differ only there (the rule by which :mod:`._last_xml` writes an owed text through the
load the slot holds).

``mujoco.mj_saveLastXML`` writes the parsed model of the last load with the given model's
values copied back into it (``mj_copyBack``). Where an owed text differs from the held one
only in values that ``mj_copyBack`` overwrites and the writer writes from there alone, the
held load writes what a load of the owed text would (given the held compile's statistics):
:func:`rewrites_as` says whether that is so.

It answers per pair of texts, and a recording loop asks it once per episode about a text of
about 100 kB, so the held text is read once into a :class:`_Skeleton` (every attribute
value, its element and tag, the text between values), and each owed text is only split at
its values and compared with it, piece by piece. Texts the split cannot read as tags and
attributes alone (comments, CDATA, text content) are compared as parsed by xml.etree.

>>> from mjcf_forge import _copied_back
>>> a = '<mujoco><worldbody><body pos="0 0 1"><geom size="1"/></body></worldbody></mujoco>'
>>> _copied_back.rewrites_as(a, a.replace('pos="0 0 1"', 'pos="0 0 2"'), _copied_back.COPIED_BACK)
True
>>> _copied_back.rewrites_as(a, a.replace('size="1"', 'size="2"'), _copied_back.COPIED_BACK)
False
"""

from __future__ import annotations

import functools
import re
import xml.etree.ElementTree as _XET

from ._mujoco import version_tuple

__all__ = ["COPIED_BACK", "copied_back", "rewrites_as"]

# What mj_copyBack overwrites from the model at every write, and the writer writes only
# from what it overwrote (user_model.cc's CopyBack, xml_native_writer.cc): (element,
# attribute). test_last_xml.py writes each both ways under every MuJoCo of the suite, and
# test_robosuite_clients.py Lift's episodes (its cube's size is drawn per reset).
COPIED_BACK = frozenset({
    ("body", "pos"), ("body", "quat"), ("geom", "rgba"), ("geom", "friction"),
    ("site", "pos"), ("site", "quat"), ("site", "rgba"),
})
# A geom's size and frame also feed its body's inertia, where the body has no
# <inertial>. Up to MuJoCo 3.15 the writer writes an inertial only for one given as such;
# from 3.16 on it also writes one where the copied-back inertia differs from the held
# compile's, so there these values are loaded (found by writing test_last_xml.py's scene
# both ways under each of 3.9.0 to 3.16.0). Sizes only for primitives without `fromto`
# (a fromto is written as given).
_FEEDS_INERTIA = frozenset({("geom", "size"), ("geom", "pos"), ("geom", "quat")})
_INERTIA_WRITTEN_AS_GIVEN_BEFORE = (3, 16)
_PRIMITIVES = frozenset({"sphere", "capsule", "ellipsoid", "cylinder", "box"})


@functools.lru_cache(maxsize=None)
def copied_back(version: str) -> frozenset:
    """The (element, attribute) pairs whose values a write through the held load takes
    from the model under MuJoCo ``version`` (see :func:`rewrites_as`).

    >>> ("geom", "size") in copied_back("3.9.0"), ("geom", "size") in copied_back("3.17.0")
    (True, False)
    """
    parts = version_tuple(version)
    if parts is not None and parts < _INERTIA_WRITTEN_AS_GIVEN_BEFORE:
        return COPIED_BACK | _FEEDS_INERTIA
    return COPIED_BACK


def rewrites_as(held: str, owed: str, copied: frozenset) -> bool:
    """Whether the two texts have the same elements and attributes and differ only in
    values of ``copied`` (a geom's only where it is a primitive without ``fromto``)."""
    if held == owed:
        return True
    skeleton = _skeleton(held)
    if skeleton.tags is None or "<!" in owed:
        return _parsed_differ_only_in(held, owed, copied)
    parts = _ATTRIBUTE.split(owed)
    if len(parts) != len(skeleton.parts) or parts[0::3] != skeleton.between or parts[1::3] != skeleton.names:
        return False
    for i, (was, now) in enumerate(zip(skeleton.values, parts[2::3])):
        if was == now:
            continue
        tag = skeleton.tags[i]
        if (tag, skeleton.names[i]) not in copied or "<" in now:
            return False
        if tag == "geom":
            attributes = skeleton.elements[skeleton.element_of[i]]
            if not _a_primitive_as_sized(_quoted(attributes.get("type"), "sphere"), attributes):
                return False
    return True


# An attribute and its quoted value; re.split keeps both groups, so a text splits into
# [between, name, "value", between, name, "value", ..., between].
_ATTRIBUTE = re.compile(r"""([^\s=<>/"']+)[ \t\r\n]*=[ \t\r\n]*("[^"]*"|'[^']*')""")
_OPENING = re.compile(r"<([^\s/>!][^\s/>]*)")


class _Skeleton:
    """A held text split at its attribute values: the values, their names, the text
    between them, and each value's element (its index and tag); ``tags`` is None where
    some text between values is not inside a tag (comments, CDATA, text content)."""

    def __init__(self, text: str) -> None:
        self.parts = _ATTRIBUTE.split(text)
        self.between = self.parts[0::3]
        self.names = self.parts[1::3]
        self.values = self.parts[2::3]
        self.tags: list | None = []
        self.element_of: list = []
        self.elements: list = []  # each element's attributes, name -> quoted value
        if "<!" in text:
            self.tags = None
            return
        tag = None
        for i, name in enumerate(self.names):
            text_before = self.between[i]
            opened = _OPENING.findall(text_before)
            if opened:
                # The last tag opened here holds the attribute, and nothing closes it
                # between its name and this attribute.
                if text_before.rfind(">") > text_before.rfind("<"):
                    self.tags = None
                    return
                tag = opened[-1]
                self.elements.append({})
            elif tag is None or text_before.strip():
                self.tags = None  # an attribute-like run outside a tag
                return
            self.tags.append(tag)
            self.element_of.append(len(self.elements) - 1)
            self.elements[-1][name] = self.values[i]


@functools.lru_cache(maxsize=4)
def _skeleton(text: str) -> _Skeleton:
    return _Skeleton(text)


def _a_primitive_as_sized(geom_type: str, attributes) -> bool:
    """Whether a geom's differing values may be written from the model: a primitive sized
    by its `size` (a `fromto` is written as given)."""
    return geom_type in _PRIMITIVES and "fromto" not in attributes


def _quoted(value: str | None, default: str) -> str:
    return default if value is None else value[1:-1]


def _parsed_differ_only_in(held: str, owed: str, copied: frozenset) -> bool:
    """:func:`rewrites_as` by xml.etree, for texts the split does not read."""
    try:
        a, b = _XET.fromstring(held), _XET.fromstring(owed)
    except _XET.ParseError:
        return False
    ea, eb = list(a.iter()), list(b.iter())
    if len(ea) != len(eb):
        return False
    for x, y in zip(ea, eb):
        if x.tag != y.tag or x.attrib.keys() != y.attrib.keys():
            return False
        if x.attrib == y.attrib:
            continue
        for name, value in x.attrib.items():
            if y.attrib[name] == value:
                continue
            if (x.tag, name) not in copied:
                return False
            if x.tag == "geom" and not _a_primitive_as_sized(x.get("type", "sphere"), x.attrib):
                return False
    return True
