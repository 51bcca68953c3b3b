"""Model (our XmlModel, robosuite's MujocoXMLModel vocabulary): names against what MuJoCo
compiles, offsets against MuJoCo's own geometry (tests/judge/bounds.py), merging, errors."""
from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest

import bounds
from helpers import RS_ASSETS
from mjcf_forge import Document, MjcfError, Model

PANDA = RS_ASSETS / "robots" / "panda" / "robot.xml"
GRIPPER = RS_ASSETS / "grippers" / "panda_gripper.xml"
MOUNT = RS_ASSETS / "bases" / "rethink_mount.xml"
OBJECTS = [RS_ASSETS / "objects" / f"{n}.xml" for n in ("can", "milk", "bread", "cereal", "lemon")]


def names(m: mujoco.MjModel, kind: str, count: int) -> list[str]:
    return [n for n in (mujoco.mj_id2name(m, kind, i) for i in range(count)) if n]


def test_lists_are_the_named_objects_mujoco_compiles():
    robot = Model(PANDA, "robot0")
    assert robot.naming_prefix == "robot0_" and robot.name == "panda"
    assert robot.root_body == "robot0_base"
    m = mujoco.MjModel.from_xml_string(robot.to_xml())
    assert robot.bodies == names(m, mujoco.mjtObj.mjOBJ_BODY, m.nbody)[1:]  # no world
    assert robot.joints == names(m, mujoco.mjtObj.mjOBJ_JOINT, m.njnt)
    assert robot.actuators == names(m, mujoco.mjtObj.mjOBJ_ACTUATOR, m.nu)
    assert robot.sites == names(m, mujoco.mjtObj.mjOBJ_SITE, m.nsite)
    assert robot.sensors == names(m, mujoco.mjtObj.mjOBJ_SENSOR, m.nsensor)
    groups = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g): int(m.geom_group[g]) for g in range(m.ngeom)}
    assert robot.contact_geoms and all(groups[g] == 0 for g in robot.contact_geoms)
    assert robot.visual_geoms and all(groups[g] == 1 for g in robot.visual_geoms)
    assert len(robot.contact_geoms) + len(robot.visual_geoms) == sum(1 for v in groups.values() if v in (0, 1))
    # Collision geoms drawn in robosuite's colour, as robosuite does.
    for g in robot.contact_geoms:
        np.testing.assert_allclose(m.geom(g).rgba, [0, 0.5, 0, 1])
    info = json.loads(robot.info_json())
    assert info["joints"] == robot.joints


def test_lists_are_made_with_the_model_as_robosuites_are():
    robot = Model(PANDA, "robot0")
    joints = robot.joints
    robot.document.find_named("body", "robot0_link7").append("joint", {"name": "robot0_extra"})
    assert robot.document.find_named("joint", "robot0_extra") is not None
    assert robot.joints == joints  # as listed when the model was made


@pytest.mark.parametrize("path", [PANDA, GRIPPER, MOUNT, *OBJECTS], ids=lambda p: p.stem)
def test_offsets_are_mujocos_geometry(path, tmp_path):
    model = Model(path, 0)
    out = tmp_path / "m.xml"
    model.document.write(out)
    # "#1": the first top-level body (robosuite's objects leave their root unnamed).
    measured = bounds.measure(str(out), ["#1"], False)["results"][0]
    for value in (model.bottom_offset, model.top_offset, model.base_offset):
        assert isinstance(value, np.ndarray) and value.shape == (3,)
    np.testing.assert_allclose(model.bottom_offset, [0, 0, measured["min"][2]], rtol=0, atol=1e-7)
    np.testing.assert_allclose(model.top_offset, [0, 0, measured["max"][2]], rtol=0, atol=1e-7)
    assert model.horizontal_radius == pytest.approx(measured["horizontal_radius"], abs=1e-7)
    m = mujoco.MjModel.from_xml_path(str(out))
    np.testing.assert_allclose(model.base_offset, m.body_pos[1], rtol=0, atol=1e-12)


def test_offsets_can_be_set():
    can = Model(OBJECTS[0], "object0")
    can.set_offsets(bottom=[0, 0, -0.05], horizontal_radius=0.04)
    np.testing.assert_array_equal(can.bottom_offset, [0, 0, -0.05])
    assert can.horizontal_radius == 0.04


def test_merge_builds_robosuites_robot_with_gripper_and_mount():
    robot = Model(PANDA, "robot0")
    gripper = Model(GRIPPER, "gripper0")
    mount = Model(MOUNT, "mount0")
    joints_before = robot.joints
    robot.merge(gripper, body="robot0_right_hand")
    robot.merge(mount, body="robot0_base")
    assert robot.joints == joints_before + gripper.joints
    assert set(gripper.actuators) <= set(robot.actuators)
    m = mujoco.MjModel.from_xml_string(robot.to_xml())
    assert m.body_parentid[m.body(gripper.root_body).id] == m.body("robot0_right_hand").id
    assert m.body_parentid[m.body(mount.root_body).id] == m.body("robot0_base").id
    # The offsets grew with the mount below the base.
    assert robot.bottom_offset[2] < Model(PANDA, "robot0").bottom_offset[2]
    # Several at once, into the world, names checked once.
    arena = Model(RS_ASSETS / "objects" / "can.xml", "object0")
    arena.merge([Model(p, f"object{i + 1}") for i, p in enumerate(OBJECTS[1:])])
    compiled = mujoco.MjModel.from_xml_string(arena.to_xml())
    assert {f"object{i}_object" for i in range(5)} <= {compiled.body(i).name for i in range(compiled.nbody)}


def test_model_from_a_document_copies_it_and_takes_options():
    doc = Document.load(GRIPPER)
    g = Model(doc, prefix="left_", contact_geom_rgba=None, name="grip")
    assert g.naming_prefix == "left_" and g.name == "grip"
    doc.prefix("changed_")
    assert all(b.startswith("left_") for b in g.bodies)
    m = mujoco.MjModel.from_xml_string(g.to_xml())
    plain = mujoco.MjModel.from_xml_path(str(GRIPPER))
    np.testing.assert_array_equal(m.geom_rgba, plain.geom_rgba)  # colours left alone
    kept = Model(GRIPPER, "g", exclude_from_prefixing=["right_gripper"])
    assert kept.root_body == "right_gripper"
    assert kept.correct_naming("x") == "g_x"
    assert kept.correct_naming(["a", "right_gripper"]) == ["g_a", "right_gripper"]
    assert kept.correct_naming({"k": "a"}) == {"k": "g_a"}
    kept.set_important(sites={"grip_site": "grip_site"})
    assert kept.important_sites == {"grip_site": "g_grip_site"}


def test_model_errors():
    two = Document.from_string("<mujoco><worldbody><body name='a'/><body name='b'/></worldbody></mujoco>")
    with pytest.raises(MjcfError) as err:
        Model(two, 0)
    assert err.value.errors == ["<string>:1:9: expected exactly one top-level body in <worldbody>, found 2"]
    with pytest.raises(TypeError):
        Model(PANDA)  # neither idn nor prefix
    with pytest.raises(TypeError):
        Model(42, 0)
    robot = Model(PANDA, "robot0")
    before = robot.to_xml()
    with pytest.raises(MjcfError):
        robot.merge(Model(PANDA, "robot0"))  # every name clashes
    assert robot.to_xml() == before
    with pytest.raises(MjcfError):
        robot.merge(Model(GRIPPER, "g"), body="robot0_no_such_body")
    assert robot.to_xml() == before


@pytest.mark.parametrize("path", [PANDA, GRIPPER, *OBJECTS[:2]], ids=lambda p: p.stem)
def test_model_tells_what_the_command_lines_info_tells(path, forge_cli):
    import subprocess

    cli = json.loads(subprocess.run(
        [str(forge_cli), "info", str(path), "--prefix", "m0_", "--json"],
        check=True, capture_output=True, text=True,
    ).stdout)
    model = Model(path, "m0")
    assert json.loads(model.info_json()) == cli
    for key in ["name", "naming_prefix", "root_body", "bodies", "joints", "actuators", "sites",
                "sensors", "contact_geoms", "visual_geoms"]:
        assert getattr(model, key) == cli[key], key
    np.testing.assert_allclose(model.bottom_offset, cli["bottom_offset"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.top_offset, cli["top_offset"], rtol=0, atol=1e-12)
    assert model.horizontal_radius == pytest.approx(cli["horizontal_radius"], abs=1e-12)


def test_root_body_is_the_name_the_same_object_has_in_a_variant(tmp_path):
    # can.xml wraps its body "object" in an unnamed one (robosuite's MujocoXMLModel raises
    # TypeError for its root_body): named "root" before prefixing, as scenes name it.
    from mjcf_forge import Scene

    can = Model(OBJECTS[0], "object1")
    assert can.root_body == "object1_root" and can.bodies[:2] == ["object1_root", "object1_object"]
    m = mujoco.MjModel.from_xml_string(can.to_xml())
    assert m.body(can.root_body).parentid[0] == 0
    scene = Scene.from_toml(
        f'base = "{RS_ASSETS / "arenas" / "empty_arena.xml"}"\n'
        "[[objects]]\nname = \"object\"\n"
        f'pool = ["{OBJECTS[0]}"]\ncount = 2\nprefix = "object{{i}}_"\nfree_joint = false\n'
        "[objects.placement]\nx = [-1, 1]\ny = [-1, 1]\n",
        tmp_path,
    )
    placed = {o["prefix"]: o["body"] for o in scene.variant(0).params["objects"]}
    assert placed["object1_"] == can.root_body
    # A body already named "root" keeps its name; the unnamed top one takes the next free.
    doc = Document.from_string(
        "<mujoco><worldbody><body><body name='root'><geom size='0.1'/></body></body></worldbody></mujoco>"
    )
    assert Model(doc, 0).root_body == "0_root1"
    named = Model(PANDA, "robot0")
    assert named.root_body == "robot0_base"


def test_instance_ids_are_ints_or_strs():
    assert Model(OBJECTS[0], 3).naming_prefix == "3_"
    assert Model(OBJECTS[0], "left").naming_prefix == "left_"
    assert Model(OBJECTS[0], np.int64(7)).naming_prefix == "7_"
    for bad in (1.5, True, None.__class__, object(), [1], b"x"):
        with pytest.raises(TypeError, match="idn is an int or a str"):
            Model(OBJECTS[0], bad)
    with pytest.raises(TypeError):
        Model(OBJECTS[0], prefix=3)


def test_a_missing_model_file_is_a_file_not_found_error(tmp_path):
    from mjcf_forge import MjcfFileNotFoundError

    with pytest.raises(FileNotFoundError) as err:
        Model(tmp_path / "nope.xml", 0)
    assert isinstance(err.value, MjcfFileNotFoundError) and isinstance(err.value, MjcfError)
    assert err.value.filename == str(tmp_path / "nope.xml")
