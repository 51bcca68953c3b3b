"""``xml.etree.ElementTree``'s functions over mjcf-forge elements.

The names robosuite's model code uses from ``xml.etree.ElementTree`` (``Element``,
``SubElement``, ``tostring``, ``fromstring``, ``parse``, ``ElementTree``, ``iselement``),
working with :class:`mjcf_forge.Element` and with ``xml.etree``'s own elements alike, so
that this module can stand in for ``ET`` in such code::

    from mjcf_forge import etree as ET

    body = ET.Element("body", name="cube")
    ET.SubElement(body, "geom", type="box", size="0.1 0.1 0.1")
    ET.tostring(body, encoding="unicode")
    # '<body name="cube"><geom type="box" size="0.1 0.1 0.1" /></body>'

``Element``, ``fromstring`` and ``parse`` make mjcf-forge elements: a new element lives in a
small document of its own until it is appended to a model's, where it is copied in and the
handle follows the copy. The text is read as XML, not as an MJCF model (no includes
expanded, no defaults inlined: use :meth:`mjcf_forge.Document.load` for that), and text
that is only white space (an indented file's layout) is dropped, as the model reader does.
``ET.SubElement`` itself cannot take our elements (it is C code that checks the parent's
type); this one takes both.
"""

from __future__ import annotations

import xml.etree.ElementTree as _ET
from typing import Any, Optional

from ._mjcf_forge import Element

__all__ = [
    "Element",
    "ElementTree",
    "ParseError",
    "SubElement",
    "XML",
    "dump",
    "fromstring",
    "indent",
    "iselement",
    "parse",
    "tostring",
    "tostringlist",
]

ParseError = _ET.ParseError
# Serializing is duck-typed in xml.etree (tag, items(), text, tail, len, iteration), so its
# own functions write our elements as they write theirs; tostring writes ours natively
# (the same text) where it can.
tostringlist = _ET.tostringlist
dump = _ET.dump
indent = _ET.indent


def _native_agrees() -> bool:
    """Whether the native writer gives this Python's xml.etree text, on a probe holding
    every character the two escape (they changed across Python versions)."""
    probe = Element("a", {"b": "&<>\"\r\n\t'x", "c": ""})
    child = probe.append("d", {})
    child.text = "&<>\"'"
    probe.append("e", {"f": "1"}).append("g", {})
    child.tail = "t&<>"
    return probe._etree_xml() == _ET.tostring(probe, encoding="unicode")


_NATIVE = _native_agrees()


def tostring(
    element: Any,
    encoding: Optional[str] = None,
    method: Optional[str] = None,
    *,
    xml_declaration: Optional[bool] = None,
    default_namespace: Optional[str] = None,
    short_empty_elements: bool = True,
) -> Any:
    """``ET.tostring``: the same text (or bytes, as ``encoding`` says), written natively
    for our elements with the defaults (xml.etree's own writer otherwise)."""
    text = None
    if (
        _NATIVE
        and isinstance(element, Element)
        and method in (None, "xml")
        and default_namespace is None
        and short_empty_elements
        and not (xml_declaration and (encoding or "").lower() == "unicode")
    ):
        text = element._etree_xml()
    if text is None:
        return _ET.tostring(
            element, encoding, method, xml_declaration=xml_declaration,
            default_namespace=default_namespace, short_empty_elements=short_empty_elements,
        )
    if encoding is None:
        encoding = "us-ascii"
    if encoding.lower() == "unicode":
        return text
    if xml_declaration or (
        xml_declaration is None and encoding.lower() not in ("utf-8", "us-ascii")
    ):
        text = f"<?xml version='1.0' encoding='{encoding}'?>\n" + text
    return text.encode(encoding, "xmlcharrefreplace")


def iselement(element: Any) -> bool:
    """Whether ``element`` looks like an element (has a ``tag``), as ``ET.iselement``."""
    return hasattr(element, "tag")


def SubElement(parent: Any, tag: str, attrib: Optional[dict] = None, **extra: Any) -> Any:
    """A new child ``tag`` of ``parent`` (ours or xml.etree's) with the given attributes."""
    attrib = {**(attrib or {}), **extra}
    if isinstance(parent, Element):
        return parent.append(tag, attrib)
    return _ET.SubElement(parent, tag, attrib)


def _adopt(foreign: Any) -> Element:
    """An xml.etree tree as a new mjcf-forge element (copied)."""
    element = Element(foreign.tag, foreign.attrib)
    if foreign.text is not None and foreign.text.strip():
        element.text = foreign.text
    element.extend(list(foreign))
    return element


def fromstring(text: Any, parser: Any = None) -> Element:
    """The XML ``text`` (``str`` or ``bytes``) as a new element."""
    return _adopt(_ET.fromstring(text, parser))


XML = fromstring


class ElementTree(_ET.ElementTree):
    """``ET.ElementTree`` whose :meth:`parse` makes mjcf-forge elements; it wraps any element
    (``ElementTree(el).write(...)`` writes ours as xml.etree writes its own)."""

    def parse(self, source: Any, parser: Any = None) -> Element:
        """Reads ``source`` (a file name or file object) as the tree's root."""
        root = super().parse(source, parser)
        self._root = _adopt(root)
        return self._root


def parse(source: Any, parser: Any = None) -> ElementTree:
    """An :class:`ElementTree` read from ``source`` (a file name or file object)."""
    tree = ElementTree()
    tree.parse(source, parser)
    return tree
