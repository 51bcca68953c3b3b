"""mjcf_forge.base: robosuite's MujocoXML / MujocoModel / MujocoXMLModel over our documents.

Every attribute and hook robosuite's classes have, subclassing in each form robosuite uses,
errors, and the comparison with robosuite 1.5.2's own classes (imported from the unpacked
wheel, as benches/compare/bench_robosuite.py does): compiled models equal, except where robosuite
breaks a MuJoCo rule, each such case a test here (corpora/base/) and a line of
docs/model-hierarchy.md ("Where MuJoCo's rules differ from robosuite's").
"""
from __future__ import annotations

import importlib.util
import os
import sys
import types
import xml.etree.ElementTree as XET

import mujoco
import numpy as np
import pytest

import judge
import merge_judge
from helpers import ROOT, RS_ASSETS, stub_robosuite
import mjcf_forge
from mjcf_forge import Element, MjcfError
from mjcf_forge import base
from mjcf_forge.base import MujocoModel, MujocoXML, MujocoXMLModel, XMLError

WORLD = RS_ASSETS / "base.xml"  # robosuite's world: MujocoWorldBase reads base.xml
TABLE = RS_ASSETS / "arenas" / "table_arena.xml"
CAN = RS_ASSETS / "objects" / "can.xml"
PANDA = RS_ASSETS / "robots" / "panda" / "robot.xml"
GRIPPER = RS_ASSETS / "grippers" / "panda_gripper.xml"
MOUNT = RS_ASSETS / "bases" / "rethink_mount.xml"
CASES = ROOT / "corpora" / "base"
SECTIONS = ["worldbody", "actuator", "sensor", "asset", "tendon", "equality", "contact"]


class MyModel(MujocoXMLModel):
    """The issue's example model, on robosuite's can (whose one geom is unnamed: g0_col)."""

    def __init__(self, idn=0):
        super().__init__(str(CAN), idn=idn)

    @property
    def _important_geoms(self):
        return {"body": ["g0_col"]}

    @property
    def _important_sites(self):
        return {}

    @property
    def _important_sensors(self):
        return {}

    @property
    def contact_geom_rgba(self):
        return [0, 1, 0, 0.3]

    @property
    def top_offset(self):
        return np.array([0, 0, 0.1])

    @property
    def horizontal_radius(self):
        return 0.2


def plain_model(module, path, idn=0, rgba=(0, 0.5, 0, 1), **props):
    """A MujocoXMLModel subclass of ``module`` (ours or robosuite's) made with ``type``."""
    attrs = {
        "contact_geom_rgba": property(lambda self: list(rgba) if rgba is not None else None),
        "_important_geoms": property(lambda self: {}),
        "_important_sites": property(lambda self: {}),
        "_important_sensors": property(lambda self: {}),
    }
    attrs.update({k: property(lambda self, v=v: v) for k, v in props.items()})
    cls = type("Plain", (module.MujocoXMLModel,), attrs)
    return cls(str(path), idn=idn)


def compiled(xml: str) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(xml)


# ------------------------------------------------------------------------------------
# robosuite's own classes, for comparison
# ------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def rs():
    """robosuite.models.base of the unpacked 1.5.2 wheel, without robosuite/__init__.py
    (which imports every environment). Stand-ins for PIL and termcolor when they are not
    installed: the code compared never calls them. Unloaded afterwards."""
    before = set(sys.modules)
    stub_robosuite()
    import robosuite.models.base as theirs

    yield theirs
    for name in set(sys.modules) - before:
        if name.split(".")[0] in ("robosuite", "PIL", "termcolor"):
            del sys.modules[name]


def outcome(f):
    """What ``f()`` returns, or the type of what it raises."""
    try:
        return f()
    except Exception as e:  # noqa: BLE001 - the kind of failure is what is compared
        return type(e)


# ------------------------------------------------------------------------------------
# The issue's example
# ------------------------------------------------------------------------------------


def test_the_issue_example_runs_on_robosuites_files():
    world = MujocoXML(str(WORLD))
    arena = MujocoXML(str(TABLE))
    world.merge(arena)
    xml_string = world.get_xml()
    model = world.get_model(mode="mujoco")
    assert isinstance(model, mujoco.MjModel) and xml_string.startswith('<mujoco model="base">')
    can = MyModel()
    assert can.important_geoms == {"body": ["0_g0_col"]}
    m = can.get_model()
    assert m.geom("0_g0_col").id == 0 and list(m.geom_rgba[0]) == pytest.approx([0, 1, 0, 0.3])
    assert can.top_offset[2] == 0.1 and can.horizontal_radius == 0.2


def test_world_and_arena_compile_as_robosuites_but_for_the_tables_inertia(rs):
    ours, theirs = MujocoXML(str(WORLD)), rs.MujocoXML(str(WORLD))
    ours.merge(MujocoXML(str(TABLE)))
    theirs.merge(rs.MujocoXML(str(TABLE)))
    diffs = judge.compare_models(theirs.get_model(), ours.get_model())
    # base.xml says inertiagrouprange="0 0", table_arena.xml leaves MuJoCo's "0 5": alone,
    # the table's visual geoms (group 1) count for its inertia. robosuite's merge drops the
    # arena's compiler and so its table weighs its collision box only; ours keeps the
    # table's own mass, written out as the installed MuJoCo compiles the arena alone.
    assert sorted(d.split("[")[0].split(":")[0] for d in diffs) == [
        "body_inertia", "body_mass", "body_subtreemass", "stat.meanmass"
    ], diffs
    table = ours.get_model().body("table")
    alone = mujoco.MjModel.from_xml_path(str(TABLE)).body("table")
    assert table.mass == alone.mass and list(table.inertia) == list(alone.inertia)
    # The merge judge: every part compiles inside the merged model as it does alone.
    assert merge_judge.compare_merge_models(
        ours.get_model(), compiled(MujocoXML(str(WORLD)).get_xml()),
        [(mujoco.MjModel.from_xml_path(str(TABLE)), "", None)],
    ) == []


@pytest.mark.parametrize("path", [CAN, PANDA, GRIPPER, MOUNT], ids=lambda p: p.stem)
def test_models_compile_and_list_as_robosuites(rs, path):
    ours, theirs = plain_model(base, path, idn=3), plain_model(rs, path, idn=3)
    assert judge.compare_models(theirs.get_model(), ours.get_model()) == []
    for attr in ["naming_prefix", "name", "important_geoms"]:
        assert getattr(ours, attr) == getattr(theirs, attr), attr
    for attr in ["bodies", "joints", "actuators", "sites", "sensors", "contact_geoms",
                 "visual_geoms"]:
        # robosuite lists an unnamed element as None, which its correct_naming refuses.
        assert getattr(ours, "_" + attr) == getattr(theirs, "_" + attr), attr
        named = [n for n in getattr(theirs, "_" + attr) if n is not None]
        assert getattr(ours, attr) == theirs.correct_naming(named), attr
    if theirs._root_body is not None:
        assert ours.root_body == theirs.root_body
    assert list(ours.base_offset) == list(theirs.base_offset)
    assert {k: [e.get("name") for e in v] if isinstance(v, list) else v.get("name")
            for k, v in ours._elements.items()} == \
        {k: [e.get("name") for e in v] if isinstance(v, list) else v.get("name")
         for k, v in theirs._elements.items()}
    # Our get_xml() is the same model as theirs, as MuJoCo compiles each.
    assert judge.compare_models(compiled(theirs.get_xml()), compiled(ours.get_xml())) == []


def test_the_robot_with_gripper_and_mount_compiles_as_robosuites(rs):
    def build(module):
        robot = plain_model(module, PANDA, idn="robot0")
        gripper = plain_model(module, GRIPPER, idn="gripper0")
        mount = plain_model(module, MOUNT, idn="mount0")
        robot.merge(gripper, merge_body="robot0_right_hand")
        mount._elements["root_body"].set("pos", "0 0 -0.1")
        robot.merge(mount, merge_body=robot.root_body)
        return robot

    assert judge.compare_models(build(rs).get_model(), build(base).get_model()) == []


# ------------------------------------------------------------------------------------
# MujocoXML
# ------------------------------------------------------------------------------------


def test_mujoco_xml_attributes_and_live_sections():
    can = MujocoXML(str(CAN))
    assert can.file == str(CAN) and can.folder == str(CAN.parent)
    assert can.tree.getroot() is can.root and can.root.tag == "mujoco"
    assert can.name == "can" and can.document.root is can.root
    for tag in SECTIONS:
        section = getattr(can, tag)
        assert isinstance(section, Element) and section.tag == tag
        assert section is can.root.find(tag) and section.parent is can.root
    # Missing sections are created at the end, in robosuite's order.
    assert [e.tag for e in can.root] == ["asset", "worldbody", "actuator", "sensor", "tendon",
                                          "equality", "contact"]
    # Sections stay live across merges: the same objects, holding the merged content.
    world = MujocoXML(str(WORLD))
    held = {tag: getattr(world, tag) for tag in SECTIONS}
    world.merge(can)
    for tag in SECTIONS:
        assert getattr(world, tag) is held[tag] is world.root.find(tag)
    assert world.worldbody.find(".//body[@name='object']") is not None
    assert [a.get("name") for a in world.asset] == ["can_mesh", "tex-can", "coke"]
    # Edits through the sections are the model's.
    world.actuator.append(base.ET.Element("motor", name="m", joint="nothing"))
    assert '<motor name="m" joint="nothing"/>' in world.get_xml()


def test_defaults_includes_and_paths_are_read_as_mujoco_reads_them(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # relative paths resolve from the file, not the cwd
    for name in ["defaults.xml", "with_include.xml"]:
        model = MujocoXML(str(CASES / name))
        assert model.root.find(".//default") is None and "class=" not in model.get_xml()
        assert judge.compare_models(mujoco.MjModel.from_xml_path(str(CASES / name)),
                                    model.get_model()) == []
    table = MujocoXML(str(TABLE))
    assert all(os.path.isabs(t.get("file")) for t in table.asset.findall("./*[@file]"))
    # robosuite's hooks stay callable (and change nothing on a loaded model).
    xml = table.get_xml()
    table.resolve_asset_dependency()
    table._replace_defaults_inline(default_dic={})
    assert table.get_xml() == xml
    default = base.ET.fromstring('<default><default class="c"><geom rgba="1 0 0 1"/></default></default>')
    classes = MujocoXML._get_default_classes(default)
    assert list(classes) == ["c"] and classes["c"]["geom"].get("rgba") == "1 0 0 1"


def test_create_default_element_and_get_element_names():
    world = MujocoXML(str(WORLD))
    option = world.root.find("option")
    assert world.create_default_element("option") is option
    keyframe = world.create_default_element("keyframe")
    assert keyframe is world.root[-1] and keyframe.tag == "keyframe" and len(keyframe) == 0
    assert world.create_default_element("keyframe") is keyframe
    table = MujocoXML(str(TABLE))
    assert table.get_element_names(table.worldbody, "camera") == [
        "frontview", "birdview", "agentview", "sideview"]
    assert table.get_element_names(table.worldbody, "light") == [None]


def test_merge_forms_list_none_and_a_body():
    world = MujocoXML(str(WORLD))
    a, b = MujocoXML(str(CASES / "part.xml")), MujocoXML(str(CASES / "keyed.xml"))
    piece = a.worldbody.find("body")
    world.merge([a, b])
    assert [e.get("name") for e in world.worldbody] == ["piece", "slider"]
    assert piece.parent is world.worldbody  # the part's element followed its copy
    assert a.worldbody.find("body") is not piece and a.get_xml() == MujocoXML(str(CASES / "part.xml")).get_xml()
    # merge_body=None: every section but the world body's children.
    world = MujocoXML(str(WORLD))
    world.merge(MujocoXML(str(TABLE)), merge_body=None)
    assert len(world.worldbody) == 0 and world.asset.find("material[@name='table_ceramic']") is not None
    # Into a body: the part's bodies become children of that body.
    robot = plain_model(base, PANDA, idn="robot0")
    robot.merge(plain_model(base, GRIPPER, idn="gripper0"), merge_body="robot0_right_hand")
    hand = robot.worldbody.find(".//body[@name='robot0_right_hand']")
    assert hand.find("body").get("name") == "gripper0_right_gripper"


def test_merge_refusals_leave_both_sides_as_they_were():
    world = MujocoXML(str(WORLD))
    world.merge(MujocoXML(str(TABLE)))
    before = world.get_xml()
    with pytest.raises(XMLError) as err:
        world.merge([MujocoXML(str(CAN)), "can.xml"])
    assert str(err.value) == "<class 'str'> is not a MujocoXML instance."
    assert world.get_xml() == before
    # An unknown body, with the names closest to it.
    part = MujocoXML(str(CASES / "part.xml"))
    piece = part.worldbody.find("body")
    with pytest.raises(XMLError) as err:
        world.merge(part, merge_body="tabel")
    assert str(err.value) == "merge_body 'tabel' is not a body of 'base' (did you mean 'table'?)"
    with pytest.raises(XMLError, match=r"^merge_body 'zzz' is not a body of 'base'$"):
        world.merge(part, merge_body="zzz")
    # A name clash (the second table), with its position; nothing merged of the first part.
    with pytest.raises(XMLError) as err:
        world.merge([part, MujocoXML(str(TABLE))])
    assert isinstance(err.value, MjcfError) and isinstance(err.value, ValueError)
    assert any("duplicate" in line and "table" in line for line in err.value.errors)
    assert world.get_xml() == before and part.get_xml() == MujocoXML(str(CASES / "part.xml")).get_xml()
    assert piece.parent is part.worldbody  # handles of a refused part stay where they were


def test_merge_converts_compiler_mass_settings_with_the_installed_mujoco():
    world = MujocoXML(str(CASES / "empty.xml"))
    part_file = ROOT / "corpora" / "errors" / "merge" / "part_settotalmass.xml"
    part = MujocoXML(str(part_file))
    world.merge(part)
    alone = mujoco.MjModel.from_xml_path(str(part_file))
    assert merge_judge.compare_merge_models(world.get_model(), compiled(MujocoXML(str(CASES / "empty.xml")).get_xml()),
                                            [(alone, "", None)]) == []


def test_merge_assets_shares_identical_refuses_different_adds_unnamed():
    red = MujocoXML(str(CASES / "paint_red.xml"))
    red.merge_assets(MujocoXML(str(CASES / "paint_red.xml")))
    assert len(red.asset) == 1
    with pytest.raises(XMLError, match="asset <material> 'paint' differs"):
        red.merge_assets(MujocoXML(str(CASES / "paint_blue.xml")))
    assert len(red.asset) == 1
    # Anything with an `asset` element: robosuite's MujocoObjects hold xml.etree ones.
    holder = types.SimpleNamespace(asset=XET.fromstring(
        '<asset><texture builtin="flat" width="8" height="8" type="skybox"/>'
        '<material name="other" rgba="0 1 0 1"/><material name="paint" rgba="1 0 0 1"/></asset>'))
    red.merge_assets(holder)
    assert [(a.tag, a.get("name")) for a in red.asset] == [
        ("material", "paint"), ("texture", None), ("material", "other")]
    red.merge_assets(holder)  # an unnamed asset is always added, as Document.merge does
    assert len(red.asset) == 4


def test_get_model_equals_mujoco_compiling_get_xml_and_refuses_other_modes():
    world = MujocoXML(str(WORLD))
    world.merge([MujocoXML(str(TABLE)), MujocoXML(str(CAN))])
    assert judge.compare_models(compiled(world.get_xml()), world.get_model()) == []
    with pytest.raises(ValueError) as err:
        world.get_model(mode="mujoco_py")
    assert str(err.value) == "Unkown model mode: mujoco_py. Available options are: mujoco"
    assert type(err.value) is ValueError  # robosuite's exception, not ours


@pytest.mark.parametrize("pretty", [False, True])
def test_save_model_round_trips(tmp_path, pretty):
    world = MujocoXML(str(WORLD))
    world.merge(MujocoXML(str(TABLE)))
    out = tmp_path / "scene.xml"
    world.save_model(str(out), pretty=pretty)
    text = out.read_text()
    assert (text.count("\n") > 10) == pretty
    again = MujocoXML(str(out))
    assert again.get_xml() == world.get_xml()
    assert judge.compare_models(world.get_model(), again.get_model()) == []
    assert os.listdir(tmp_path) == ["scene.xml"]  # no temporary file left


def test_load_errors_are_xml_errors(tmp_path):
    with pytest.raises(XMLError) as err:
        MujocoXML(str(tmp_path / "missing.xml"))
    assert "missing.xml" in str(err.value) and err.value.errors
    # A prefix MuJoCo would read as two names.
    with pytest.raises(XMLError, match="prefix 'a b_' holds white space"):
        MyModel(idn="a b")


def test_files_are_read_through_the_file_cache_and_always_as_they_are_now(tmp_path, monkeypatch):
    monkeypatch.setattr(base, "FILE_CACHE", mjcf_forge.LoadCache(4))
    path = tmp_path / "m.xml"
    path.write_text('<mujoco><worldbody><body name="b"><geom size="1"/></body></worldbody></mujoco>')
    first = MujocoXML(str(path))
    first.worldbody.find("body").set("pos", "1 2 3")  # an edit of one instance
    second = MujocoXML(str(path))
    assert base.FILE_CACHE.hits == 1 and second.worldbody.find("body").get("pos") is None
    # A changed file is read again, and what it now says is what comes back.
    path.write_text('<mujoco><worldbody><body name="c"><geom size="2"/></body></worldbody></mujoco>')
    assert MujocoXML(str(path)).worldbody.find("body").get("name") == "c"
    assert base.FILE_CACHE.hits == 1
    # Without the cache: read every time, the same document.
    monkeypatch.setattr(base, "FILE_CACHE", None)
    assert MujocoXML(str(path)).get_xml() == second.get_xml().replace('name="b"', 'name="c"').replace(
        'size="1"', 'size="2"')


def test_load_cache_serves_copies_and_keeps_no_errors(tmp_path):
    files = mjcf_forge.LoadCache(2)
    path = tmp_path / "m.xml"
    path.write_text('<mujoco><worldbody><geom name="g" size="1"/></worldbody></mujoco>')
    a = files.load(path)
    a.prefix("p_")
    b = files.load(str(path))
    assert (files.hits, len(files)) == (1, 1)
    assert b.to_xml() == mjcf_forge.Document.load(path).to_xml() != a.to_xml()
    with pytest.raises(MjcfError, match="missing.xml"):
        files.load(tmp_path / "missing.xml")
    assert len(files) == 1
    files.clear()
    assert len(files) == 0


# ------------------------------------------------------------------------------------
# MujocoXMLModel
# ------------------------------------------------------------------------------------


def test_mujoco_xml_model_attributes():
    can = MyModel(idn=7)
    assert (can.idn, can.mount, can.name, can.naming_prefix) == (7, None, "MyModel7", "7_")
    assert can.root_body is None  # can.xml's root body has no name
    assert can._bodies == [None, "object"]  # robosuite's raw list; the public one is named
    assert can.bodies == ["7_object"] and can.joints == [] and can.actuators == []
    assert can.sites == ["7_bottom_site", "7_top_site", "7_horizontal_radius_site"]
    assert can.sensors == [] and can.contact_geoms == ["7_g0_col"] and can.visual_geoms == []
    assert can.important_geoms == {"body": ["7_g0_col"]}
    assert can.important_sites == {} and can.important_sensors == {}
    assert list(can.base_offset) == [0, 0, 0] and can.bottom_offset is can.base_offset
    assert can.contact_geom_rgba == [0, 1, 0, 0.3]
    geom = can._elements["contact_geoms"][0]
    assert geom.get("rgba") == "0 1 0 0.3" and geom.get("material") is None
    # _elements are the live elements of the model.
    assert can._elements["root_body"] is can.worldbody[0]
    can._elements["root_body"].set("pos", "0 0 0.5")
    assert can.get_model().body_pos[1][2] == 0.5
    robot = plain_model(base, PANDA, idn="robot0")
    assert robot.root_body == "robot0_base" and robot.bodies[0] == "robot0_base"
    assert robot.joints == [f"robot0_joint{i}" for i in range(1, 8)]
    assert robot.actuators == [f"robot0_torq_j{i}" for i in range(1, 8)]
    assert list(robot.base_offset) == [0, 0, 0]
    m = robot.get_model()
    assert all(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, g) >= 0 for g in robot.contact_geoms)
    # robosuite's defaults: subclasses define these.
    bare = type("Bare", (MujocoXMLModel,), {"contact_geom_rgba": property(lambda self: None)})(str(CAN))
    for attr in ["important_geoms", "important_sites", "important_sensors", "top_offset",
                 "horizontal_radius"]:
        with pytest.raises(NotImplementedError):
            getattr(bare, attr)
    with pytest.raises(NotImplementedError):
        MujocoXMLModel(str(CAN))  # contact_geom_rgba is the subclass's


def test_unnamed_geoms_get_robosuites_names_in_groups_0_and_1_only():
    model = plain_model(base, CASES / "unnamed_geom_groups.xml")
    assert [g.get("name") for g in model.worldbody.iter("geom")] == ["0_g0_col", "0_g0_vis", None]
    assert model.contact_geoms == ["0_g0_col"] and model.visual_geoms == ["0_g0_vis"]


def test_correct_naming_of_str_list_dict_and_other_types():
    can = MyModel()
    assert can.correct_naming("a") == "0_a"
    assert can.correct_naming(["a", "b"]) == ["0_a", "0_b"]
    names = {"x": "a", "y": ["b", "c"], "z": {"w": "d"}}
    assert can.correct_naming(names) == {"x": "0_a", "y": ["0_b", "0_c"], "z": {"w": "0_d"}}
    assert names == {"x": "a", "y": ["b", "c"], "z": {"w": "d"}}  # a copy
    for bad in [("a",), 3, None, {"a"}]:
        with pytest.raises(TypeError, match=r"^Error: type of 'names' must be str, list, or dict!$"):
            can.correct_naming(bad)


class SharedMaterial(MujocoXMLModel):
    """Keeps the material 'paint' and the body 'a' (as an element) unprefixed."""

    contact_geom_rgba = property(lambda self: None)

    def exclude_from_prefixing(self, inp):
        if isinstance(inp, str):
            return inp == "paint"
        return inp.tag == "body" and inp.get("name") == "a"


def test_exclude_from_prefixing_keeps_names_and_their_references():
    model = SharedMaterial(str(CASES / "paint_red.xml"), idn="p")
    xml = model.get_xml()
    assert '<material name="paint"' in xml and 'material="paint"' in xml
    assert '<body name="a">' in xml and 'name="p_ga"' in xml
    assert model.correct_naming(["paint", "ga"]) == ["paint", "p_ga"]
    assert model.get_model().nmat == 1


def test_set_sites_visibility_flips_alpha():
    can = MyModel()
    m = can.get_model()
    site = m.site("0_top_site").id
    m.site_rgba[site][3] = 0.5
    can.set_sites_visibility(m, visible=False)
    assert m.site_rgba[site][3] == -0.5
    can.set_sites_visibility(types.SimpleNamespace(model=m), visible=True)
    assert m.site_rgba[site][3] == 0.5

    class RobosuiteSim:  # robosuite's MjSim: model.site_name2id
        def __init__(self, model):
            self.model = types.SimpleNamespace(
                site_rgba=model.site_rgba, site_name2id=lambda n: model.site(n).id)

    can.set_sites_visibility(RobosuiteSim(m), visible=False)
    assert m.site_rgba[site][3] == -0.5


def test_instance_randomization_adds_robosuites_default_material(monkeypatch):
    monkeypatch.setattr(base, "USING_INSTANCE_RANDOMIZATION", True)
    monkeypatch.delitem(sys.modules, "robosuite.macros", raising=False)  # else robosuite's wins
    model = plain_model(base, CASES / "unnamed_geom_groups.xml")
    assert model.worldbody.find(".//geom[@name='0_g0_vis']").get("material") == "0_default_mat"
    assert [a.get("name") for a in model.asset] == ["0_default_tex", "0_default_mat"]
    assert model.get_model().nmat == 1


def test_models_merge_into_each_other_and_into_a_world():
    world = MujocoXML(str(WORLD))
    world.merge(MujocoXML(str(TABLE)))
    cans = [MyModel(idn=i) for i in range(3)]
    for i, can in enumerate(cans):
        can._elements["root_body"].set("pos", f"0 {0.1 * i} 0.9")
    world.merge(cans)
    m = world.get_model()
    assert [m.body(f"{i}_object").id > 0 for i in range(3)] == [True] * 3
    # Each can's elements now stand for its copy in the world.
    cans[1]._elements["root_body"].set("pos", "0 0 2")
    assert world.get_model().body_pos[m.body("1_object").parentid[0]][2] == 2


# ------------------------------------------------------------------------------------
# Subclassing in every form robosuite uses
# ------------------------------------------------------------------------------------


def test_a_subclass_with_a_metaclass_registers_itself():
    registry = {}

    class Meta(type):
        def __new__(meta, name, bases, class_dict):
            cls = super().__new__(meta, name, bases, class_dict)
            if name not in ("RobotModel",):
                registry[name] = cls
            return cls

    class RobotModel(MujocoXMLModel, metaclass=Meta):
        def __init__(self, fname, idn=0):
            super().__init__(fname, idn=idn)
            self.cameras = self.get_element_names(self.worldbody, "camera")
            for joint in self._elements["joints"]:
                if joint.get("damping") is None:
                    joint.set("damping", "0.1")

        contact_geom_rgba = property(lambda self: [0, 0.5, 0, 1])

        @property
        def naming_prefix(self):
            return "robot{}_".format(self.idn)

    class Panda(RobotModel):
        def __init__(self, idn=0):
            super().__init__(str(PANDA), idn=idn)

    panda = registry["Panda"](idn=1)
    assert list(registry) == ["Panda"] and type(panda) is Panda
    assert panda.root_body == "robot1_base" and panda.name == "Panda1"
    assert panda.cameras == ["robot1_robotview", "robot1_eye_in_hand"]
    assert (panda.get_model().dof_damping[:7] > 0).all()


def test_a_mixin_calling_mujoco_xml_init_itself():
    class ObjectLike(MujocoModel):
        """Like robosuite's MujocoObject: a MujocoModel with its own naming."""

        def __init__(self):
            super().__init__()
            self._name = None

        @property
        def name(self):
            return self._name

        @property
        def naming_prefix(self):
            return "{}_".format(self.name)

        def exclude_from_prefixing(self, inp):
            return False

        @property
        def sites(self):
            return self.correct_naming(["default_site"])

    class XMLObject(ObjectLike, MujocoXML):
        """Like robosuite's MujocoXMLObject(MujocoObject, MujocoXML)."""

        def __init__(self, fname, name):
            MujocoXML.__init__(self, fname)
            self._name = name
            obj = self.worldbody.find("./body/body[@name='object']")
            obj.attrib["name"] = "main"
            obj.append(base.ET.Element("joint", name="joint0", type="free"))  # MujocoXMLObject's
            base.ET.SubElement(obj, "site", name="default_site", rgba="1 0 0 0")
            self._obj = obj
            self.document.prefix(self.naming_prefix)

    can = XMLObject(str(CAN), "can")
    assert can.name == "can" and can.sites == ["can_default_site"]
    assert can._obj.get("name") == "can_main" and can._obj.find("joint").get("name") == "can_joint0"
    # robosuite's Task.merge_objects: the object's assets, then its body into the world.
    world = MujocoXML(str(WORLD))
    world.merge(MujocoXML(str(TABLE)))
    world.merge_assets(can)
    world.worldbody.append(can._obj)
    assert can._obj.parent is world.worldbody
    m = world.get_model()
    assert m.site("can_default_site").id >= 0 and m.njnt == 1 and m.jnt_type[0] == 0
    # The MRO is robosuite's: the object's naming first.
    assert XMLObject.__mro__[1:4] == (ObjectLike, MujocoModel, MujocoXML)


def test_classes_made_at_run_time_with_type():
    Dyn = type("Dyn", (MyModel,), {"naming_prefix": property(lambda self: f"dyn{self.idn}_")})
    model = Dyn(idn=2)
    assert model.name == "Dyn2" and model.contact_geoms == ["dyn2_g0_col"]
    twice = type("Twice", (Dyn,), {})(idn=5)
    assert twice.bodies == ["dyn5_object"] and isinstance(twice, MujocoXMLModel)


# ------------------------------------------------------------------------------------
# The error type
# ------------------------------------------------------------------------------------


def test_xml_error_is_also_robosuites_once_robosuite_is_imported(monkeypatch):
    with pytest.raises(XMLError) as err:
        MujocoXML(str(WORLD)).merge(3)
    assert isinstance(err.value, MjcfError) and isinstance(err.value, ValueError)
    assert err.value.errors == ["<class 'int'> is not a MujocoXML instance."]
    # robosuite's own errors module (a file without imports), under its own name.
    path = ROOT / ".cache" / "corpus" / "robosuite-1.5.2" / "robosuite" / "utils" / "errors.py"
    spec = importlib.util.spec_from_file_location("robosuite.utils.errors", path)
    errors = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(errors)
    monkeypatch.setitem(sys.modules, "robosuite.utils.errors", errors)
    for catch in [errors.XMLError, errors.robosuiteError, XMLError, MjcfError, ValueError]:
        try:
            MujocoXML(str(WORLD)).merge(MujocoXML(str(WORLD)), merge_body="nope")
        except catch as e:
            assert type(e).__name__ == "XMLError" and isinstance(e, XMLError)
        else:
            pytest.fail("not raised")


# ------------------------------------------------------------------------------------
# Where we differ from robosuite: each case, robosuite's outcome and ours
# ------------------------------------------------------------------------------------


def test_difference_default_classes_are_inlined_as_mujoco_does(rs):
    path = CASES / "defaults.xml"
    truth = mujoco.MjModel.from_xml_path(str(path))
    # robosuite reads only top-level classes, ignores childclass and the main class.
    assert outcome(lambda: rs.MujocoXML(str(path)).get_model()) is KeyError
    assert judge.compare_models(truth, MujocoXML(str(path)).get_model()) == []


def test_difference_includes_are_expanded_from_the_files_folder(rs, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = CASES / "with_include.xml"
    # robosuite leaves <include> in the text: MuJoCo then looks for part.xml in the cwd.
    assert outcome(lambda: rs.MujocoXML(str(path)).get_model()) is ValueError
    assert judge.compare_models(mujoco.MjModel.from_xml_path(str(path)),
                                MujocoXML(str(path)).get_model()) == []


@pytest.mark.parametrize("case,idn", [("refs_world", "r"), ("refs_refname", "r"),
                                      ("names_with_the_prefix", "b")])
def test_difference_every_name_and_reference_is_prefixed_exactly(rs, case, idn):
    path = CASES / f"{case}.xml"
    # robosuite prefixes `world` (no body of the model), misses `refname`, and skips names
    # that already begin with the prefix (here making two bodies "b_x").
    assert outcome(lambda: plain_model(rs, path, idn=idn).get_model()) is ValueError
    ours = plain_model(base, path, idn=idn, rgba=None)
    assert judge.compare_models(mujoco.MjModel.from_xml_path(str(path)), ours.get_model(),
                                prefix=f"{idn}_") == []


def test_difference_same_asset_name_with_other_content_is_refused(rs):
    # robosuite keeps the base's 'paint' and drops the part's: the blue geom turns red.
    theirs = rs.MujocoXML(str(CASES / "paint_red.xml"))
    theirs.merge(rs.MujocoXML(str(CASES / "paint_blue.xml")))
    m = theirs.get_model()
    assert list(m.mat_rgba[m.geom_matid[m.geom("gb").id]]) == [1, 0, 0, 1]
    ours = MujocoXML(str(CASES / "paint_red.xml"))
    with pytest.raises(XMLError, match="paint_blue.xml:2:10: asset <material> 'paint' differs"):
        ours.merge(MujocoXML(str(CASES / "paint_blue.xml")))


def test_difference_a_tendons_sites_and_geoms_are_no_elements_of_the_tree(rs):
    path = CASES / "tendon.xml"
    # robosuite lists the tendon's <site site=...> as unnamed sites (then fails to prefix
    # None) and names its <geom geom=...> wrap (which MuJoCo then refuses).
    theirs = plain_model(rs, path)
    assert outcome(lambda: theirs.sites) is TypeError
    assert outcome(theirs.get_model) is ValueError
    ours = plain_model(base, path, rgba=None)
    assert ours.sites == ["0_s0", "0_s1"] and ours.contact_geoms == ["0_wrap", "0_g"]
    assert judge.compare_models(mujoco.MjModel.from_xml_path(str(path)), ours.get_model(),
                                prefix="0_") == []


def test_difference_a_body_in_a_frame_is_no_root_and_every_sensor_counts(rs):
    path = CASES / "frame_and_sensor.xml"
    # robosuite takes the body inside the <frame> for a second root body.
    assert outcome(lambda: plain_model(rs, path)) is AssertionError
    ours = plain_model(base, path, rgba=None)
    assert ours.root_body == "0_base" and ours.bodies == ["0_base", "0_arm"]
    # robosuite's list of sensor types lacks jointactuatorfrc (it would list "angle" only).
    assert ours.sensors == ["0_torque", "0_angle"] and ours.joints == ["0_j"]
    assert judge.compare_models(mujoco.MjModel.from_xml_path(str(path)), ours.get_model(),
                                prefix="0_") == []


def test_difference_a_parts_keyframes_are_merged(rs):
    # robosuite's merge drops every section but seven: the slider's "home" key is lost.
    theirs = rs.MujocoXML(str(CASES / "empty.xml"))
    theirs.merge(rs.MujocoXML(str(CASES / "keyed.xml")))
    assert theirs.get_model().nkey == 0
    ours = MujocoXML(str(CASES / "empty.xml"))
    ours.merge(MujocoXML(str(CASES / "keyed.xml")))
    assert merge_judge.compare_merge_models(
        ours.get_model(), compiled(MujocoXML(str(CASES / "empty.xml")).get_xml()),
        [(mujoco.MjModel.from_xml_path(str(CASES / "keyed.xml")), "", None)]) == []


def test_difference_errors_are_xml_errors_that_say_what_is_wrong(rs):
    part = str(CASES / "part.xml")
    theirs = rs.MujocoXML(str(CASES / "paint_red.xml"))
    assert outcome(lambda: theirs.merge(rs.MujocoXML(part), merge_body="aa")) is AttributeError
    with pytest.raises(XMLError, match="did you mean 'a'"):
        MujocoXML(str(CASES / "paint_red.xml")).merge(MujocoXML(part), merge_body="aa")
    assert outcome(lambda: plain_model(rs, CASES / "empty.xml")) is KeyError
    with pytest.raises(XMLError, match="Expected 1, got 0"):
        plain_model(base, CASES / "empty.xml")
    # An unnamed geom of group 2: robosuite's naming has no name for its group.
    assert outcome(lambda: plain_model(rs, CASES / "unnamed_geom_groups.xml")) is KeyError
    # An unnamed root body: robosuite's root_body and bodies fail on None.
    assert outcome(lambda: plain_model(rs, CAN).root_body) is TypeError
    assert plain_model(base, CAN).root_body is None


def test_merge_converts_a_part_that_refers_to_materials_it_gets_later(tmp_path):
    """robosuite's TwoArmPegInHole puts a peg with its material into each robot and merges
    the material into the task afterwards: the robot, compiled alone for its inertias (its
    compiler mass settings differ from the world's), refers to a material it lacks.
    Materials weigh nothing, so the part is compiled without them."""
    world = tmp_path / "world.xml"
    world.write_text('<mujoco><compiler inertiagrouprange="0 0"/><worldbody/></mujoco>')
    part = tmp_path / "part.xml"
    part.write_text('<mujoco><worldbody><body name="arm"><joint/><geom size="0.1" group="1"/>'
                    '<geom size="0.05" material="peg_mat"/></body></worldbody></mujoco>')
    scene = MujocoXML(str(world))
    scene.merge(MujocoXML(str(part)))
    scene.asset.append(Element("material", {"name": "peg_mat", "rgba": "0 1 0 1"}))
    alone = mujoco.MjModel.from_xml_string(part.read_text().replace(' material="peg_mat"', ""))
    merged = scene.get_model()
    assert merged.body("arm").mass == alone.body("arm").mass  # both geoms count, as alone
    assert np.array_equal(merged.body("arm").inertia, alone.body("arm").inertia)


# --------------------------------------------------------------------------------------
# The rules: MuJoCo's (the default of mjcf_forge.base) or robosuite's (the switch's)
# --------------------------------------------------------------------------------------


@pytest.fixture
def robosuite_rules():
    previous = base.set_rules("robosuite")
    yield
    base.set_rules(previous)


def merged_rules_case():
    world = MujocoXML(str(CASES / "rules_base.xml"))
    world.merge(MujocoXML(str(CASES / "rules_part.xml")))
    return world


def test_mujocos_rules_keep_the_parts_physics_and_refuse_a_clashing_asset():
    assert base.rules() == "mujoco"
    world = MujocoXML(str(CASES / "rules_base.xml"))
    with pytest.raises(XMLError, match="asset <texture> 'tex' differs from the base's"):
        world.merge(MujocoXML(str(CASES / "rules_part.xml")))


def test_robosuites_rules_build_what_robosuite_builds(robosuite_rules):
    model = merged_rules_case().get_model()
    alone = mujoco.MjModel.from_xml_path(str(CASES / "rules_part.xml"))
    # The part's <compiler> (none: degrees) is dropped: its range is read as radians.
    assert model.joint("hinge").range.tolist() == [0.0, 90.0]
    assert alone.joint("hinge").range.tolist() == pytest.approx([0.0, np.pi / 2])
    # The main class's density is dropped with the <default>: MuJoCo's 1000.
    assert model.body("door").mass[0] == pytest.approx(1000 * 0.2**3 + 1000 * 4 / 3 * np.pi * 0.02**3)
    assert alone.body("door").mass[0] == pytest.approx(500 * 0.2**3 + 500 * 4 / 3 * np.pi * 0.02**3)
    # The top-level class is inlined with its own attributes.
    assert model.geom("knob").group == 1 and model.geom("knob").rgba.tolist() == [0, 0, 1, 1]
    # The base's texture is kept, and the part's material takes it.
    assert model.ntex == 1 and model.tex_width[0] == 8
    assert model.mat_texid[model.material("mat").id].max() == 0
    red = model.tex_data[: 3].tolist()
    assert red == [255, 0, 0]


def test_robosuites_rules_name_a_class_robosuite_cannot_inline(robosuite_rules):
    with pytest.raises(XMLError) as e:
        MujocoXML(str(CASES / "defaults.xml"))
    assert "<geom name='g1'> has class 'finger', which is not a class directly under the first <default>" in str(e.value)
    assert str(CASES / "defaults.xml") in str(e.value)


def test_robosuites_rules_leave_names_that_begin_with_the_prefix(robosuite_rules):
    class Part(MujocoXMLModel):
        contact_geom_rgba = None

    part = Part(str(CASES / "names_with_the_prefix.xml"), idn="b")
    names = sorted(e.get("name") for e in part.root.iter() if e.get("name"))
    # robosuite's add_prefix leaves "b_x" and "b_g"; MuJoCo's rules would write "b_b_x".
    assert names == ["b_g", "b_g", "b_j", "b_x", "b_x"]
