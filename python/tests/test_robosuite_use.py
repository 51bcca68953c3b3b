"""mjcf_forge.robosuite.use(): robosuite's own classes built on mjcf_forge.base.

The hook itself is checked here on robosuite's unpacked wheel (its light modules only).
The comparison builds robosuite's arenas, grippers, mount, objects, robots and a Lift task
both ways in the robosuite venv (.cache/venv-robosuite-env: robosuite 1.5.2 with MuJoCo
3.9.0, made by scripts/setup_robosuite_env.sh, which scripts/test.sh runs; a missing venv
is a failure, not a skip), in two processes
(robosuite_build.py), and compares what MuJoCo compiles from each.
"""
from __future__ import annotations

import inspect
import json
import os
import subprocess
import sys
import types
from pathlib import Path

import mujoco
import numpy as np
import pytest

import judge
import mjcf_forge
import mjcf_forge.robosuite as forge_robosuite
from helpers import ROOT, stub_robosuite
from mjcf_forge import base, etree

RS_ENV = ROOT / ".cache" / "venv-robosuite-env" / "bin" / "python"


@pytest.fixture
def clean_imports(monkeypatch):
    """sys.meta_path and robosuite's modules as they were, after the test."""
    monkeypatch.setattr(sys, "meta_path", list(sys.meta_path))
    before = set(sys.modules)
    rules = base.rules()
    yield
    base.set_rules(rules)
    for name in set(sys.modules) - before:
        if name.split(".")[0] in ("robosuite", "PIL", "termcolor"):
            del sys.modules[name]


def test_use_rebinds_robosuites_base_classes_and_et(clean_imports):
    assert not forge_robosuite.in_use()
    stub_robosuite()
    assert base.rules() == "mujoco"  # mjcf_forge.base on its own: MuJoCo's rules
    forge_robosuite.use()
    assert base.rules() == "robosuite"  # the switch: stock robosuite's models
    forge_robosuite.use(rules="mujoco")  # again: only the rules change
    assert forge_robosuite.in_use() and sys.meta_path.count(forge_robosuite._FINDER) == 1
    assert base.rules() == "mujoco"
    with pytest.raises(ValueError, match="rules are 'mujoco' or 'robosuite', not 'exact'"):
        forge_robosuite.use(rules="exact")
    import robosuite.models.base as rs_base
    import robosuite.utils.mjcf_utils as rs_utils
    from robosuite.models.world import MujocoWorldBase

    assert rs_base.MujocoXML is base.MujocoXML and rs_base.MujocoXMLModel is base.MujocoXMLModel
    assert rs_base.MujocoModel is base.MujocoModel
    assert rs_base.ET is etree and rs_utils.ET is etree
    world = MujocoWorldBase()
    assert isinstance(world, base.MujocoXML) and world.root.find("option").get("timestep") == "0.002"
    body = rs_utils.new_body(name="b", pos=(0, 0, 1))
    assert isinstance(body, mjcf_forge.Element)
    world.worldbody.append(body)
    assert body.parent is world.worldbody
    # robosuite's loaders still answer for their modules (inspect reads the source).
    assert inspect.getsource(MujocoWorldBase).startswith("class MujocoWorldBase(MujocoXML):")


def test_use_refuses_to_come_after_robosuite(monkeypatch, clean_imports):
    monkeypatch.setitem(sys.modules, "robosuite.models", types.ModuleType("robosuite.models"))
    with pytest.raises(RuntimeError, match="before robosuite is imported: robosuite.models is already"):
        forge_robosuite.use()
    assert not forge_robosuite.in_use()


# Bodies of robosuite's table arena that robosuite's world (base.xml, inertiagrouprange
# "0 0") makes lighter than the arena compiles alone ("0 5"): the table's visual geoms and
# the mocap targets' geoms (group 2) count alone. Ours keep their masses (docs: row 5 of
# "Where MuJoCo's rules differ from robosuite's").
ARENA_BODIES = {"table", "left_eef_target", "right_eef_target"}
# What a body's mass and inertia change in the compiled model.
INERTIA_ARRAYS = {
    "body_mass", "body_inertia", "body_ipos", "body_iquat", "body_sameframe", "body_simple",
    "body_subtreemass", "body_invweight0", "dof_invweight0", "dof_M0", "bvh_aabb",
    "stat.meanmass", "stat.meaninertia", "stat.meansize", "stat.extent", "stat.center",
    "cam_poscom0", "light_poscom0",  # cameras and lights placed from subtree centres of mass
}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """robosuite_build.py's output, robosuite's way and ours."""
    assert RS_ENV.exists(), f"{RS_ENV} missing: run scripts/setup_robosuite_env.sh"
    tmp = tmp_path_factory.mktemp("robosuite_use")
    # The robosuite venv imports this test run's mjcf_forge, and only it: the package's
    # folder is linked alone into a folder of its own, since the folder it is installed in
    # holds another MuJoCo, which would shadow the robosuite venv's.
    only = tmp / "path"
    only.mkdir()
    (only / "mjcf_forge").symlink_to(Path(mjcf_forge.__file__).resolve().parent)
    env = dict(os.environ, PYTHONPATH=str(only))
    out = {}
    for mode in ("robosuite", "forge", "forge-mujoco"):
        path = tmp / f"{mode}.json"
        run = subprocess.run(
            [str(RS_ENV), str(Path(__file__).parent / "drivers" / "robosuite_build.py"), mode, str(path), "--env"],
            cwd=tmp, env=env, capture_output=True, text=True, timeout=900,
        )
        assert run.returncode == 0, run.stderr[-3000:]
        out[mode] = json.loads(path.read_text())
    return out


def test_robosuite_builds_every_case_on_ours(built):
    theirs, ours = built["robosuite"], built["forge-mujoco"]
    assert set(ours) == set(theirs) and len(ours) >= 16
    assert [k for k, v in ours.items() if v.startswith("ERROR")] == []
    assert [k for k, v in theirs.items() if v.startswith("ERROR")] == []
    # robosuite's Lift environment makes, resets and steps on ours.
    assert json.loads(ours["lift_env"]) == json.loads(theirs["lift_env"]) == {"nbody": 26, "steps": 10}


def test_with_robosuites_rules_every_case_compiles_to_stocks_model(built):
    theirs, ours = built["robosuite"], built["forge"]
    assert set(ours) == set(theirs)
    for name, text in theirs.items():
        if name == "lift_env":
            assert json.loads(ours[name]) == json.loads(text)
            continue
        a, b = mujoco.MjModel.from_xml_string(text), mujoco.MjModel.from_xml_string(ours[name])
        assert judge.compare_models(a, b) == [], name
        assert a.names == b.names and a.body_mass.tobytes() == b.body_mass.tobytes(), name


@pytest.mark.parametrize("name", [
    "table_arena", "bins_arena", "empty_arena", "PandaGripper", "RethinkGripper",
    "JacoThreeFingerGripper", "Robotiq140Gripper", "rethink_mount", "can", "milk", "bread", "box",
    "cylinder", "ball", "panda_gripper_mount", "sawyer_gripper_mount",
])
def test_robosuites_models_compile_the_same_on_ours(built, name):
    theirs = mujoco.MjModel.from_xml_string(built["robosuite"][name])
    ours = mujoco.MjModel.from_xml_string(built["forge-mujoco"][name])
    assert judge.compare_models(theirs, ours) == []


def test_the_lift_task_differs_only_by_the_arenas_own_inertias(built):
    theirs = mujoco.MjModel.from_xml_string(built["robosuite"]["lift_task"])
    ours = mujoco.MjModel.from_xml_string(built["forge-mujoco"]["lift_task"])
    arena = mujoco.MjModel.from_xml_string(built["forge-mujoco"]["lift_task_arena"])
    diffs = judge.compare_models(theirs, ours)
    assert diffs and {d.split("[")[0].split(":")[0] for d in diffs} <= INERTIA_ARRAYS, diffs
    assert theirs.nbody == ours.nbody and theirs.ngeom == ours.ngeom
    changed = set()
    for i in range(theirs.nbody):
        name = theirs.body(i).name
        a, b = theirs.body(i), ours.body(name)
        if a.mass != b.mass or not np.array_equal(a.inertia, b.inertia):
            changed.add(name)
    assert changed == ARENA_BODIES
    for name in ARENA_BODIES:  # ours: as the arena compiles alone
        assert ours.body(name).mass == arena.body(name).mass
        assert np.array_equal(ours.body(name).inertia, arena.body(name).inertia)
