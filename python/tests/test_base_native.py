"""mjcf_forge.base's native common path (Document._sort_elements, _sections, _set_all)
against its Python path: the same elements, names, lists and output; and every hook a
subclass or the module's user replaces is honoured (the Python path then runs).
"""
from __future__ import annotations

import pytest

from helpers import ROOT, RS_ASSETS
from mjcf_forge import base
from mjcf_forge.base import MujocoXML, MujocoXMLModel

CASES = ROOT / "corpora" / "base"
FILES = [
    RS_ASSETS / "robots" / "panda" / "robot.xml",
    RS_ASSETS / "grippers" / "panda_gripper.xml",
    RS_ASSETS / "bases" / "rethink_mount.xml",
    RS_ASSETS / "objects" / "can.xml",
    CASES / "tendon.xml",
    CASES / "frame_and_sensor.xml",
    CASES / "unnamed_geom_groups.xml",
    CASES / "refs_world.xml",
]

ODD_GROUPS = """<mujoco><worldbody><body name="b">
  <geom size=".1"/><geom size=".1" group=" +1 "/><geom size=".1" group="1_0"/>
  <geom size=".1" group="x"/><geom size=".1" group="-0"/><geom size=".1" group="&#x2003;1"/>
  <frame><replicate count="2"><body><geom size=".1" group="1"/></body></replicate></frame>
  <geom size=".1" name=""/>
</body></worldbody>
<actuator><motor joint="j"/></actuator><sensor><jointpos joint="j"/></sensor>
</mujoco>"""


def make(path, idn=0, cls=None):
    attrs = {
        "contact_geom_rgba": property(lambda self: [0, 0.5, 0, 1]),
        "_important_geoms": property(lambda self: {}),
        "_important_sites": property(lambda self: {}),
        "_important_sensors": property(lambda self: {}),
    }
    return type("Plain", (cls or MujocoXMLModel,), attrs)(str(path), idn=idn)


def summary(model):
    elements = {
        k: [(e.tag, e.get("name")) for e in v] if isinstance(v, list) else (v.tag, v.get("name"))
        for k, v in model._elements.items()
    }
    lists = {a: getattr(model, "_" + a) for a in
             ["root_body", "bodies", "joints", "actuators", "sites", "sensors",
              "contact_geoms", "visual_geoms"]}
    return list(model._elements), elements, lists, model.get_xml()


@pytest.fixture
def odd(tmp_path):
    path = tmp_path / "odd.xml"
    path.write_text(ODD_GROUPS)
    return path


@pytest.mark.parametrize("path", FILES + ["odd"], ids=lambda p: getattr(p, "stem", p))
def test_native_sorting_equals_the_python_path(path, odd, monkeypatch):
    path = odd if path == "odd" else path
    assert base._native_sorting()
    native = summary(make(path, idn="n"))
    monkeypatch.setattr(base, "_native_sorting", lambda: False)
    assert summary(make(path, idn="n")) == native


def test_odd_group_spellings_are_read_as_pythons_int(odd):
    model = make(odd)
    names = [g.get("name") for g in model.worldbody.iter("geom")]
    # int(" +1 ") == 1, int("1_0") == 10, "x" no int, int("-0") == 0, an em space stripped.
    assert names == ["0_g0_col", "0_g0_vis", None, None, "0_g1_col", "0_g1_vis", "0_g2_vis", ""]
    assert model._actuators == [None] and model._sensors == [None]
    assert model._bodies == ["b", None]


@pytest.mark.parametrize("path", FILES + ["odd"], ids=lambda p: getattr(p, "stem", p))
def test_sort_elements_default_path_is_native_and_equals_the_python_filter(path, odd, monkeypatch):
    """_mjcf_utils.sort_elements with the default filter over our elements runs the one
    native sort (mjcf_forge::sort); a filter passed in, or a replaced rule function of the
    module, runs the Python filter: the same elements, for the document and a subtree."""
    from mjcf_forge import Document, _mjcf_utils

    doc = Document.load(str(odd if path == "odd" else path))
    root = doc.getroot()
    world = root.find("worldbody")
    for top, parent in [(root, None), (world, root)]:
        assert _mjcf_utils._native_default(top, parent)
        native = _mjcf_utils.sort_elements(top, parent)
        python = _mjcf_utils.sort_elements(top, parent, element_filter=_mjcf_utils.element_filter)
        assert list(native) == list(python)
        assert all(all(a is b for a, b in zip(native[k], python[k])) for k in native)
        assert all(len(native[k]) == len(python[k]) for k in native)
    # Not its own parent: the filter reads the one passed.
    assert not _mjcf_utils._native_default(world, None)
    monkeypatch.setattr(_mjcf_utils, "group", lambda element: 0)
    assert not _mjcf_utils._native_default(root, None)


def test_model_lists_and_base_lists_are_one_sort(odd):
    """mjcf_forge.Model's lists (XmlModel, MuJoCo's lists) and MujocoXMLModel's (robosuite's
    keys) come from one sort: the same geoms, sites, bodies; Model lists <freejoint>s too,
    as MuJoCo lists its joints."""
    from mjcf_forge import Document, Model

    def named(names):
        # An empty name: robosuite's prefixing makes it "s_", MuJoCo's (Model's) keeps it.
        return [n for n in names if n not in ("", "s_")]

    for path in FILES + [odd]:
        ours = make(path, idn="s")
        model = Model(Document.load(str(path)), "s")
        assert named(model.contact_geoms) == named(ours.contact_geoms), path
        assert named(model.visual_geoms) == named(ours.visual_geoms), path
        assert model.sites == ours.sites, path
        # Model names an unnamed root body (`root`); robosuite's classes leave it unnamed.
        assert model.bodies[1:] == ours.bodies[1 if ours.root_body else 0 :], path
        free = [j.get("name") for j in ours.worldbody.iter("freejoint") if j.get("name")]
        assert sorted(model.joints) == sorted(ours.joints + free), path


def test_a_replaced_element_filter_is_honoured(monkeypatch):
    seen = []
    original = base._element_filter

    def only_joints(element, parent):
        seen.append(element.tag)
        key = original(element, parent)
        return key if key in ("root_body", "joints") else None

    monkeypatch.setattr(base, "_element_filter", only_joints)
    assert not base._native_sorting()
    model = make(RS_ASSETS / "robots" / "panda" / "robot.xml", idn="r")
    assert seen and set(model._elements) == {"root_body", "bodies", "joints"}
    assert model.joints == [f"r_joint{i}" for i in range(1, 8)] and model.sites == []


def test_a_replaced_sort_elements_is_honoured(monkeypatch):
    calls = []
    original = base.sort_elements

    def counting(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(base, "sort_elements", counting)
    model = make(RS_ASSETS / "objects" / "can.xml")
    assert calls == [1] and model.contact_geoms == ["0_g0_col"]


def test_overridden_hooks_are_called():
    calls = []

    class Hooked(MujocoXMLModel):
        contact_geom_rgba = property(lambda self: None)

        def create_default_element(self, name):
            calls.append(("section", name))
            return super().create_default_element(name)

        def resolve_asset_dependency(self):
            calls.append(("assets",))
            super().resolve_asset_dependency()

        @property
        def naming_prefix(self):
            return "own_"

        def exclude_from_prefixing(self, inp):
            return isinstance(inp, str) and inp == "object"

    model = Hooked(str(RS_ASSETS / "objects" / "can.xml"))
    assert calls == [("section", t) for t in base._SECTIONS] + [("assets",)]
    assert model.bodies == ["object"] and model.contact_geoms == ["own_g0_col"]
    assert model.worldbody.find(".//body[@name='object']") is not None
    assert model.worldbody.find(".//geom[@name='own_g0_col']") is not None


def test_sections_are_the_hooks_elements():
    world = MujocoXML(str(RS_ASSETS / "base.xml"))
    for tag in base._SECTIONS:
        assert getattr(world, tag) is world.create_default_element(tag) is world.root.find(tag)
