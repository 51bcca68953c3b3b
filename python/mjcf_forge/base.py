"""robosuite's model hierarchy (``robosuite.models.base``, 1.5.2) over mjcf-forge documents.

``MujocoXML``, ``MujocoModel`` and ``MujocoXMLModel`` with robosuite's signatures,
attributes, defaults and hooks, so that code written for robosuite runs with the import line
changed::

    from mjcf_forge.base import MujocoXML, MujocoXMLModel

    world = MujocoXML("world.xml")
    world.merge(MujocoXML("arena.xml"))
    model = world.get_model(mode="mujoco")   # a mujoco.MjModel, from the installed mujoco

What is read and written is an mjcf-forge :class:`~mjcf_forge.Document`: the file as MuJoCo
reads it (includes expanded, default classes inlined exactly, file paths absolute), and its
elements (``root``, ``worldbody``, ``asset``, ``_elements``...) are live
:class:`~mjcf_forge.Element` s that behave as ``xml.etree.ElementTree`` elements. Names are
prefixed, and models merged, by the library's exact rules rather than robosuite's
approximations; docs/model-hierarchy.md lists every such difference with MuJoCo's rule.

Errors are :class:`XMLError`: an :class:`~mjcf_forge.MjcfError` (so a ``ValueError``), and,
once robosuite is imported, robosuite's own ``robosuite.utils.errors.XMLError`` too, so
``except`` clauses of code written for either catch it.

This module holds robosuite's classes; what they stand on lives in rooms of its own and
is re-exported here under robosuite's names: the error type (``_errors.py``), robosuite's
``mjcf_utils`` helpers (``_mjcf_utils.py``), the process's rules and model cache
(``_settings.py``), and the MuJoCo compile a merge calls back (``_upcalls.py``).
"""

from __future__ import annotations

import difflib
import os
import sys
import xml.dom.minidom
from typing import Any, Optional

from ._mjcf_forge import Document, LoadCache, MjcfError
from . import _last_xml
from . import _stock
from . import etree as ET
from ._errors import XMLError, reraised as _reraised, xml_error
from ._files import write_atomic
from ._mjcf_utils import (
    array_to_string,
    asset_name as _asset_name,
    element_filter as _element_filter,
    group as _group,
    named as _named,
    same_subtree as _same_subtree,
    sort_elements,
    string_to_array,
    tree_parent as _tree_parent,
)
from . import _settings
from ._settings import MODEL_CACHE_ENV, RULES, model_cache, rules, set_model_cache, set_rules
from ._upcalls import compile_inertia as _compile_inertia

__all__ = [
    "MujocoModel",
    "MujocoXML",
    "MujocoXMLModel",
    "FILE_CACHE",
    "MODEL_CACHE_ENV",
    "RULES",
    "USING_INSTANCE_RANDOMIZATION",
    "XMLError",
    "array_to_string",
    "model_cache",
    "rules",
    "set_model_cache",
    "set_rules",
    "sort_elements",
    "string_to_array",
    "xml_error",
]

#: robosuite's ``macros.USING_INSTANCE_RANDOMIZATION``: give every visual geom without a
#: material a default one, as robosuite does for its domain randomization. When
#: ``robosuite.macros`` is imported, its value is the one read.
USING_INSTANCE_RANDOMIZATION = False

#: Where :class:`MujocoXML` reads its files: a :class:`~mjcf_forge.LoadCache`, which serves
#: a file that has not changed since it was last read as a copy of that load (robosuite
#: reads the same robot, gripper, arena and object files at every environment reset).
#: ``None``: every file is read anew. Either way the document is the file as it is now.
FILE_CACHE: Optional[LoadCache] = LoadCache(256)


def _instance_randomization() -> bool:
    macros = sys.modules.get("robosuite.macros")
    if macros is not None and hasattr(macros, "USING_INSTANCE_RANDOMIZATION"):
        return bool(macros.USING_INSTANCE_RANDOMIZATION)
    return bool(USING_INSTANCE_RANDOMIZATION)


# The sorting functions robosuite's classes call, by their names here: while they are the
# ones in use (not replaced on this module), MujocoXMLModel sorts its elements natively
# (Document._sort_elements), with the same result; a replaced one is honoured through the
# Python path.
_SORTING = (
    ("sort_elements", sort_elements),
    ("_element_filter", _element_filter),
    ("_group", _group),
    ("_tree_parent", _tree_parent),
)


def _native_sorting() -> bool:
    g = globals()
    return all(g[name] is fn for name, fn in _SORTING)


def _load_exact(fname: str) -> Any:
    files = FILE_CACHE
    return Document.load(fname) if files is None else files.load(fname)


# The sections MujocoXML holds, in robosuite's order (created in that order when missing).
_SECTIONS = ["worldbody", "actuator", "sensor", "asset", "tendon", "equality", "contact"]


class MujocoXML(object):
    """A MuJoCo model read from an MJCF file, to merge other models into (robosuite's
    ``MujocoXML``).

    ``MujocoXML(fname)`` reads the file as MuJoCo does (:meth:`mjcf_forge.Document.load`:
    includes expanded, default classes inlined, asset paths absolute), through
    :data:`FILE_CACHE` (an unchanged file read before is a copy of that load). Attributes, as in
    robosuite: ``file``, ``folder``, ``tree`` (an ``ElementTree`` over ``root``),
    ``root`` (``<mujoco>``), and the sections ``worldbody``, ``actuator``, ``sensor``,
    ``asset``, ``tendon``, ``equality``, ``contact`` (created when missing). Ours besides:
    ``document``, the :class:`~mjcf_forge.Document` they all live in. Every element is a
    live :class:`~mjcf_forge.Element` (an ``xml.etree`` element in behaviour), and stays
    the same object across merges.

    Args:
        fname (str): path to the MJCF file.

    Raises:
        XMLError: the file cannot be read as an MJCF model (every problem, with positions).
    """

    def __init__(self, fname):
        self.file = fname
        self.folder = os.path.dirname(fname)
        try:
            if _settings.rules() == "robosuite":
                self.document = _stock.load(fname, _load_exact, xml_error)
            else:
                self.document = _load_exact(fname)
        except MjcfError as e:
            raise _reraised(e) from None
        self.root = self.document.root
        self.tree = ET.ElementTree(self.root)
        if type(self).create_default_element is MujocoXML.create_default_element:
            # The hook's own work, in one native call (the same elements, created in order).
            (self.worldbody, self.actuator, self.sensor, self.asset, self.tendon,
             self.equality, self.contact) = self.document._sections(_SECTIONS)
        else:
            self.worldbody = self.create_default_element("worldbody")
            self.actuator = self.create_default_element("actuator")
            self.sensor = self.create_default_element("sensor")
            self.asset = self.create_default_element("asset")
            self.tendon = self.create_default_element("tendon")
            self.equality = self.create_default_element("equality")
            self.contact = self.create_default_element("contact")
        # Default classes are already inlined (exactly) by Document.load, and file paths
        # made absolute, which is what the hook does: it is called only when a subclass
        # overrides it (and stays callable).
        if type(self).resolve_asset_dependency is not MujocoXML.resolve_asset_dependency:
            self.resolve_asset_dependency()

    def resolve_asset_dependency(self):
        """Makes every asset's ``file`` absolute (robosuite's hook; already so after
        loading, which resolved them as MuJoCo does, ``meshdir`` and includes included)."""
        for node in self.asset.findall("./*[@file]"):
            file = node.get("file")
            abs_path = os.path.abspath(self.folder)
            abs_path = os.path.join(abs_path, file)
            node.set("file", abs_path)

    def create_default_element(self, name):
        """The ``<name>`` child of ``root``, created (appended, empty) if there is none.

        Args:
            name (str): tag of the element

        Returns:
            Element: the element (live)
        """
        found = self.root.find(name)
        if found is not None:
            return found
        return self.root.append(name)

    def merge(self, others, merge_body="default"):
        """Merges ``others`` (a MujocoXML, or a list of them, merged in order) into this
        model, in place.

        The other's ``<worldbody>`` children go into this ``worldbody``
        (``merge_body="default"``), into the body named ``merge_body``, or nowhere
        (``None``); every other section is carried over by MuJoCo's rules: assets shared
        when identical, a name clash refused, compiler settings converted (mass settings
        with the installed ``mujoco``, which compiles the part alone so that its bodies
        keep their masses and inertias), keyframes remapped. Elements of the others that
        you hold follow their copies into this model. A refused merge changes nothing,
        here or in the others.

        Args:
            others (MujocoXML or list of MujocoXML): models to merge in
            merge_body (None or str): "default" (the world body), a body's name, or None

        Raises:
            XMLError: an other that is not a MujocoXML, a ``merge_body`` that is not a body
                of this model (with the closest names), or a merge MuJoCo's rules refuse
        """
        if type(others) is not list:
            others = [others]
        for other in others:
            if not isinstance(other, MujocoXML):
                raise xml_error("{} is not a MujocoXML instance.".format(type(other)))
        if not others:
            return
        worldbody = merge_body is not None
        body = None
        if merge_body is not None and merge_body != "default":
            body = merge_body
            # A body of that name found natively; the names listed only for the error.
            if not isinstance(body, str) or self.worldbody.find_named("body", body) is None:
                names = [b.get("name") for b in self.worldbody.iter("body") if b.get("name") is not None]
                close = difflib.get_close_matches(str(body), names, n=3)
                hint = " (did you mean {}?)".format(" or ".join(repr(c) for c in close)) if close else ""
                raise xml_error(
                    "merge_body {!r} is not a body of {}{}".format(body, self._label(), hint)
                )
        if _settings.rules() == "robosuite":
            into = None if body is None and not worldbody else (
                self.worldbody if body is None else self.worldbody.find_named("body", body))
            for other in others:
                _stock.merge(self, other, into)
            return
        try:
            self.document.merge(
                [other.document for other in others],
                body,
                worldbody=worldbody,
                compile_inertia=_compile_inertia,
            )
        except MjcfError as e:
            raise _reraised(e) from None

    def _label(self) -> str:
        return repr(self.root.get("model")) if self.root.get("model") else str(self.file)

    def get_model(self, mode="mujoco"):
        """The model compiled by the installed ``mujoco`` (a ``mujoco.MjModel``), equal to
        ``mujoco.MjModel.from_xml_string(self.get_xml())``.

        Through the process's model cache (:func:`model_cache`, on by default): a model
        whose structure the cache has seen is that structure's model with this one's values
        written in, at patch cost; a new structure compiles. The model is yours while you
        hold it: the cache patches only models no one else holds (see
        :class:`~mjcf_forge.DocumentCache`). ``set_model_cache(None)`` makes every call
        compile.

        Args:
            mode (str): "mujoco", the only mode

        Raises:
            ValueError: another mode (robosuite's message)
        """
        available_modes = ["mujoco"]
        if mode == "mujoco":
            cache = model_cache()
            if cache is not None:
                model = cache.model(self.document)
                # Stock loads the text here: MuJoCo's last loaded XML model is owed it.
                _last_xml.owe(self.document.copy().to_xml, served=model, files=self.document.files("mesh"))
                return model
            import mujoco

            return mujoco.MjModel.from_xml_string(self.document.to_xml())
        raise ValueError("Unkown model mode: {}. Available options are: {}".format(mode, ",".join(available_modes)))

    def get_xml(self):
        """The model as MJCF text (compact)."""
        return self.document.to_xml()

    def save_model(self, fname, pretty=False):
        """Writes the model to ``fname`` (compact, or indented with ``pretty``), atomically:
        through a temporary file in the same folder and a rename.

        Args:
            fname (str): output file
            pretty (bool): indent the output
        """
        text = self.document.to_xml(pretty=bool(pretty))
        write_atomic(fname, text.encode("utf-8"))

    def merge_assets(self, other):
        """Adds ``other``'s assets (``other.asset``'s children: a MujocoXML, or any object
        with an ``asset`` element, ours or xml.etree's) that this model lacks.

        An asset with the tag and name (for meshes, textures, height fields and skins
        without a name: the name MuJoCo gives them, their file's stem) of one already here
        is left out when identical, and refused when it differs; an asset without a name
        is always added.

        Raises:
            XMLError: an asset whose name is taken here by a different asset

        With ``rules="robosuite"`` (:func:`set_rules`), robosuite's rule instead: an asset
        whose tag and ``name`` are here already is left out, whatever its content.
        """
        if _settings.rules() == "robosuite":
            _stock.merge_assets(self, other)
            return
        names = {}
        for asset in self.asset:
            name = _asset_name(asset)
            if name is not None:
                names.setdefault((asset.tag, name), asset)
        clashes = []
        adding = []
        for asset in other.asset:
            name = _asset_name(asset)
            mine = names.get((asset.tag, name)) if name is not None else None
            if mine is None:
                adding.append(asset)
            elif not _same_subtree(mine, asset):
                clashes.append(
                    "asset <{}> '{}' differs from the base's <{}> '{}'".format(asset.tag, name, mine.tag, name)
                )
        if clashes:
            raise xml_error("\n".join(clashes))
        for asset in adding:
            self.asset.append(asset)

    def get_element_names(self, root, element_type):
        """The ``name`` of every element tagged ``element_type`` under ``root`` (document
        order, ``None`` for an unnamed one), as robosuite's.

        Args:
            root (Element): where to search
            element_type (str): tag, e.g. "site" or "camera"
        """
        names = []
        for child in root:
            if child.tag == element_type:
                names.append(child.get("name"))
            names += self.get_element_names(child, element_type)
        return names

    @staticmethod
    def _get_default_classes(default):
        """robosuite's helper: ``{class: {tag: element}}`` of a ``<default>`` element (kept
        for subclasses; loading already inlined every class exactly)."""
        default_dic = {}
        for cls in default:
            default_dic[cls.get("class")] = {child.tag: child for child in cls}
        return default_dic

    def _replace_defaults_inline(self, default_dic, root=None):
        """robosuite's helper: ``class`` attributes under ``root`` replaced by the
        attributes ``default_dic`` gives them (kept for subclasses; loading already inlined
        every class exactly, so on a loaded model there is nothing left to replace)."""
        if root is None:
            root = self.root
        cls_name = root.attrib.pop("class", None)
        if cls_name is not None:
            tag_attrs = default_dic[cls_name].get(root.tag, None)
            if tag_attrs is not None:
                for k, v in tag_attrs.items():
                    if root.get(k, None) is None:
                        root.set(k, v)
        for child in root:
            self._replace_defaults_inline(default_dic=default_dic, root=child)

    @property
    def name(self):
        """The ``model`` attribute of ``<mujoco>`` (None without one)."""
        return self.root.get("model")


# --------------------------------------------------------------------------------------
# MujocoModel
# --------------------------------------------------------------------------------------


class MujocoModel(object):
    """The interface of every simulation model (robosuite's ``MujocoModel``): names and
    the model's parts by role. Subclasses define the properties; ``correct_naming`` and
    ``set_sites_visibility`` are built on them."""

    def correct_naming(self, names):
        """``names`` as they are in the model: each given the ``naming_prefix`` unless
        ``exclude_from_prefixing`` says otherwise.

        Args:
            names (str, list, or dict): a name, a list of names, or a dict whose values are
                names or such lists or dicts (a new dict is returned)

        Raises:
            TypeError: anything else
        """
        if type(names) is str:
            return self.naming_prefix + names if not self.exclude_from_prefixing(names) else names
        elif type(names) is list:
            return [self.naming_prefix + name if not self.exclude_from_prefixing(name) else name for name in names]
        elif type(names) is dict:
            names = names.copy()
            for key, val in names.items():
                names[key] = self.correct_naming(val)
            return names
        else:
            raise TypeError("Error: type of 'names' must be str, list, or dict!")

    def set_sites_visibility(self, sim, visible):
        """Shows or hides every site of ``sites`` by the sign of its alpha.

        Args:
            sim: robosuite's ``MjSim``, anything with a ``model`` that is a
                ``mujoco.MjModel``, or a ``mujoco.MjModel``
            visible (bool): show (True) or hide the sites
        """
        model = getattr(sim, "model", sim)
        name2id = getattr(model, "site_name2id", None)
        if name2id is None:
            import mujoco

            def name2id(name):
                return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)

        for vis_g in self.sites:
            vis_g_id = name2id(vis_g)
            if (visible and model.site_rgba[vis_g_id][3] < 0) or (not visible and model.site_rgba[vis_g_id][3] > 0):
                model.site_rgba[vis_g_id][3] = -model.site_rgba[vis_g_id][3]

    def exclude_from_prefixing(self, inp):
        """Whether ``inp`` (an element, or a name) keeps its name(s) without prefix. Must
        be defined by subclasses."""
        raise NotImplementedError

    @property
    def name(self):
        """Unique name of this model."""
        raise NotImplementedError

    @property
    def naming_prefix(self):
        """Prefix of every name of this model."""
        raise NotImplementedError

    @property
    def root_body(self):
        """Name of the top-level body."""
        raise NotImplementedError

    @property
    def bodies(self):
        """Body names."""
        raise NotImplementedError

    @property
    def joints(self):
        """Joint names."""
        raise NotImplementedError

    @property
    def actuators(self):
        """Actuator names."""
        raise NotImplementedError

    @property
    def sites(self):
        """Site names."""
        raise NotImplementedError

    @property
    def sensors(self):
        """Sensor names."""
        raise NotImplementedError

    @property
    def contact_geoms(self):
        """Names of the geoms that make contact."""
        raise NotImplementedError

    @property
    def visual_geoms(self):
        """Names of the geoms drawn."""
        raise NotImplementedError

    @property
    def important_geoms(self):
        """Lists of geom names by role."""
        raise NotImplementedError

    @property
    def important_sites(self):
        """Site names by role."""
        raise NotImplementedError

    @property
    def important_sensors(self):
        """Sensor names by role."""
        raise NotImplementedError

    @property
    def bottom_offset(self):
        """Vector from the root body to the model's bottom."""
        raise NotImplementedError

    @property
    def top_offset(self):
        """Vector from the root body to the model's top."""
        raise NotImplementedError

    @property
    def horizontal_radius(self):
        """Largest horizontal distance from the root body to the model's geometry."""
        raise NotImplementedError


# --------------------------------------------------------------------------------------
# MujocoXMLModel
# --------------------------------------------------------------------------------------


class MujocoXMLModel(MujocoXML, MujocoModel):
    """A model read from an MJCF file, as one instance with its own name prefix (robosuite's
    ``MujocoXMLModel``).

    After reading (:class:`MujocoXML`): unnamed geoms of group 0 and 1 are named
    ``g{n}_col`` / ``g{n}_vis``; the elements are sorted by role into ``_elements``
    (robosuite's ``sort_elements``: ``root_body``, ``bodies``, ``joints``, ``actuators``,
    ``sites``, ``sensors``, ``contact_geoms``, ``visual_geoms``, live elements); every name
    and every reference to it gets ``naming_prefix`` (``"{idn}_"``) unless
    ``exclude_from_prefixing`` keeps it; collision geoms (group 0) are drawn in
    ``contact_geom_rgba``. Subclasses define ``contact_geom_rgba``, ``_important_geoms``,
    ``_important_sites``, ``_important_sensors``, ``top_offset`` and
    ``horizontal_radius``, as in robosuite.

    Args:
        fname (str): path to the MJCF file
        idn (int or str): this instance's identifier (the prefix is ``f"{idn}_"``)

    Raises:
        XMLError: a model without exactly one top-level body, or one that cannot be read
    """

    def __init__(self, fname, idn=0):
        super().__init__(fname)

        self.idn = idn
        self.mount = None

        if _native_sorting():
            # One native pass: the same sorting, naming and lists as the Python path below.
            self._elements, raw = self.document._sort_elements(name_geoms=True)
        else:
            raw = None
            group_mapping = {0: "col", 1: "vis"}
            ctr_mapping = {"col": 0, "vis": 0}

            def _add_default_name_filter(element, parent):
                filter_key = _element_filter(element=element, parent=parent)
                # Geoms of the tree only: a tendon's <geom> wrap takes no name.
                if filter_key in ("contact_geoms", "visual_geoms") and element.get("name") is None:
                    group = group_mapping[_group(element)]
                    element.set("name", f"g{ctr_mapping[group]}_{group}")
                    ctr_mapping[group] += 1
                return filter_key

            self._elements = sort_elements(root=self.root, element_filter=_add_default_name_filter)
        roots = self._elements.get("root_body", [])
        if len(roots) != 1:
            raise xml_error(
                "Invalid number of root bodies found for robot model. Expected 1, got {}".format(len(roots))
            )
        self._elements["root_body"] = roots[0]
        self._elements["bodies"] = (
            [self._elements["root_body"]] + self._elements["bodies"]
            if "bodies" in self._elements
            else [self._elements["root_body"]]
        )

        # As robosuite: None for an unnamed element (so that len(self._joints), robosuite's
        # RobotModel.dof, counts the joint elements); the public lists leave them out.
        if raw is not None:
            raw["bodies"] = raw["root_body"] + raw.get("bodies", [])
            names = raw.get  # fresh lists of the native call, owned here
        else:
            raw = {key: [e.get("name") for e in elements] for key, elements in self._elements.items()
                   if key != "root_body"}
            raw["root_body"] = [self._elements["root_body"].get("name")]
            names = raw.get

        self._root_body = raw["root_body"][0]
        self._bodies = names("bodies")
        self._joints = names("joints", [])
        self._actuators = names("actuators", [])
        self._sites = names("sites", [])
        self._sensors = names("sensors", [])
        self._contact_geoms = names("contact_geoms", [])
        self._visual_geoms = names("visual_geoms", [])
        self._base_offset = string_to_array(self._elements["root_body"].get("pos", "0 0 0"))

        self._add_prefix(self.naming_prefix)

        rgba = self.contact_geom_rgba
        if rgba is not None:
            value = array_to_string(rgba)
            self.document._set_all(self._elements.get("contact_geoms", []), "rgba", value, "material")

        if _instance_randomization():
            self._add_default_material()

    def _add_prefix(self, prefix):
        """Prefixes every name of the model and every reference to it (the library's
        prefixing, by MuJoCo's schema), keeping those ``exclude_from_prefixing`` excludes:
        a name it returns True for, and the name of an element it returns True for, stay
        as they are where declared and wherever referenced. With ``rules="robosuite"``, a
        name that already begins with the prefix stays too, as robosuite's ``add_prefix``
        leaves it."""
        exclude = self.exclude_from_prefixing
        kept = set()
        keep = None
        if type(self).exclude_from_prefixing is not MujocoXMLModel.exclude_from_prefixing:
            for element in self.root.iter():
                if exclude(element):
                    name = element.get("name")
                    if name is not None:
                        kept.add(name)

            def keep(name):
                return name in kept or bool(exclude(name))

        if _settings.rules() == "robosuite":
            # robosuite's add_prefix leaves a value that already begins with the prefix.
            excluded = keep

            def keep(name):
                return name.startswith(prefix) or (excluded is not None and excluded(name))

        try:
            self.document.prefix(prefix, exclude=keep)
        except MjcfError as e:
            raise _reraised(e) from None

    def _add_default_material(self):
        """robosuite's ``add_material`` with its default material: every visual geom
        (group 1) without a material gets ``{prefix}default_mat``."""
        tex_name = self.naming_prefix + "default_tex"
        mat_name = self.naming_prefix + "default_mat"
        used = False
        for geom in self._elements.get("visual_geoms", []):
            if geom.get("material") is None:
                geom.set("material", mat_name)
                used = True
        if used:
            ET.SubElement(
                self.asset,
                "texture",
                {"type": "cube", "builtin": "flat", "width": "100", "height": "100",
                 "rgb1": "1.0 1.0 1.0", "rgb2": "1.0 1.0 1.0", "name": tex_name},
            )
            ET.SubElement(self.asset, "material", {"name": mat_name, "texture": tex_name})

    def exclude_from_prefixing(self, inp):
        """By default nothing is excluded from prefixing."""
        return False

    @property
    def base_offset(self):
        """The root body's ``pos`` as read (zeros without one), a numpy array."""
        return self._base_offset

    @property
    def name(self):
        """``f"{type(self).__name__}{idn}"``."""
        return "{}{}".format(type(self).__name__, self.idn)

    @property
    def naming_prefix(self):
        """``f"{idn}_"``."""
        return "{}_".format(self.idn)

    @property
    def root_body(self):
        """The top-level body's name, prefixed (None for an unnamed one)."""
        return None if self._root_body is None else self.correct_naming(self._root_body)

    @property
    def bodies(self):
        """Names of the named bodies (prefixed), the root first."""
        return self.correct_naming(_named(self._bodies))

    @property
    def joints(self):
        """Names of the named ``<joint>`` s of the tree (prefixed)."""
        return self.correct_naming(_named(self._joints))

    @property
    def actuators(self):
        """Names of the named actuators (prefixed)."""
        return self.correct_naming(_named(self._actuators))

    @property
    def sites(self):
        """Names of the named sites of the tree (prefixed)."""
        return self.correct_naming(_named(self._sites))

    @property
    def sensors(self):
        """Names of the named sensors (prefixed)."""
        return self.correct_naming(_named(self._sensors))

    @property
    def contact_geoms(self):
        """Names of the geoms of group 0 (prefixed)."""
        return self.correct_naming(_named(self._contact_geoms))

    @property
    def visual_geoms(self):
        """Names of the geoms of group 1 (prefixed)."""
        return self.correct_naming(_named(self._visual_geoms))

    @property
    def important_sites(self):
        """``_important_sites``, prefixed."""
        return self.correct_naming(self._important_sites)

    @property
    def important_geoms(self):
        """``_important_geoms``, prefixed."""
        return self.correct_naming(self._important_geoms)

    @property
    def important_sensors(self):
        """``_important_sensors``, prefixed."""
        return self.correct_naming(self._important_sensors)

    @property
    def _important_sites(self):
        """Raw (unprefixed) site names by role. Defined by subclasses."""
        raise NotImplementedError

    @property
    def _important_geoms(self):
        """Raw (unprefixed) lists of geom names by role. Defined by subclasses."""
        raise NotImplementedError

    @property
    def _important_sensors(self):
        """Raw (unprefixed) sensor names by role. Defined by subclasses."""
        raise NotImplementedError

    @property
    def contact_geom_rgba(self):
        """RGBA of the collision geoms (group 0). Defined by subclasses (None: left as
        they are)."""
        raise NotImplementedError

    @property
    def bottom_offset(self):
        """By default ``base_offset``."""
        return self.base_offset

    @property
    def top_offset(self):
        """Defined by subclasses."""
        raise NotImplementedError

    @property
    def horizontal_radius(self):
        """Defined by subclasses."""
        raise NotImplementedError

