"""The process's model cache of mjcf_forge.base (model_cache, set_model_cache): get_model
through it, judged by MuJoCo; off by the switch and by MJCF_FORGE_MODEL_CACHE=0; robosuite's
robot-alone model compiled only when read (mjcf_forge.robosuite's RobotModel hook)."""
from __future__ import annotations

import os
import subprocess
import sys

import mujoco
import pytest

import judge
import mjcf_forge
import mjcf_forge.robosuite as forge_robosuite
from helpers import RS_ASSETS
from mjcf_forge import base

PANDA = RS_ASSETS / "robots" / "panda" / "robot.xml"


@pytest.fixture
def fresh_cache():
    """A cache of the test's own, the process's put back after."""
    previous = base.set_model_cache(mjcf_forge.DocumentCache(max_models=4))
    yield base.model_cache()
    base.set_model_cache(previous)


def test_get_model_goes_through_the_process_cache_and_is_exact(fresh_cache):
    robot = base.MujocoXML(str(PANDA))
    first = robot.get_model()
    assert fresh_cache.compiles == 1
    for k in range(3):
        robot.worldbody.find(".//joint").set("damping", repr(0.1 * (k + 1)))
        model = robot.get_model()
        ref = mujoco.MjModel.from_xml_string(robot.get_xml())
        assert judge.compare_models(ref, model) == []
        # The first is still held: never patched, still the first document's compile.
        assert model is not first
        del model
    assert fresh_cache.compiles == 1 and fresh_cache.patches == 3


def test_the_switch_turns_the_cache_off_and_back():
    previous = base.set_model_cache(None)
    try:
        assert base.model_cache() is None
        robot = base.MujocoXML(str(PANDA))
        a, b = robot.get_model(), robot.get_model()
        assert a is not b and judge.compare_models(a, b) == []
        assert base.set_model_cache(True) is None
        assert isinstance(base.model_cache(), mjcf_forge.DocumentCache)
        with pytest.raises(TypeError, match="DocumentCache, True, False or None"):
            base.set_model_cache("yes")
    finally:
        base.set_model_cache(previous)


def test_the_environment_variable_turns_the_default_off():
    code = "from mjcf_forge import base; print(base.model_cache() is None)"
    for value, off in (("0", "True"), ("off", "True"), ("1", "False")):
        env = dict(os.environ, MJCF_FORGE_MODEL_CACHE=value)
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
        assert out.stdout.strip() == off, out.stderr


def test_a_document_mujoco_refuses_leaves_the_process_cache_alone(fresh_cache, tmp_path):
    path = tmp_path / "bad.xml"
    path.write_text("<mujoco>\n<worldbody>\n  <geom type='mesh' mesh='none'/>\n</worldbody>\n</mujoco>\n")
    with pytest.raises(ValueError, match=r"bad.xml:3:3: .*mesh"):
        base.MujocoXML(str(path)).get_model()
    assert len(fresh_cache) == 0 and fresh_cache.compiles == 0


class _Robot:
    """Stands in for robosuite's RobotModel: what the hook needs of it."""

    def __init__(self) -> None:
        self.xml = base.MujocoXML(str(PANDA))
        self.document = self.xml.document
        self.mujoco_model = None


def test_the_robot_alone_is_compiled_only_when_read(fresh_cache):
    forge_robosuite._lazy_robot_model(_Robot)
    robot = _Robot()
    assert robot.mujoco_model is None
    robot.set_mujoco_model()
    expected = mujoco.MjModel.from_xml_string(robot.xml.get_xml())
    # The robot changes after set_mujoco_model (robosuite places its base): the model read
    # later is the robot as it was.
    robot.xml.worldbody.find("body").set("pos", "1 2 3")
    assert fresh_cache.compiles == 0
    model = robot.mujoco_model
    assert fresh_cache.compiles == 1 and robot.mujoco_model is model
    assert judge.compare_models(expected, model) == []
    robot.set_mujoco_model(expected)
    assert robot.mujoco_model is expected
