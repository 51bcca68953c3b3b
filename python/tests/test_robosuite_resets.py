"""robosuite's hard resets through the process's model cache, judged by MuJoCo.

robosuite_resets.py runs in the robosuite venv (.cache/venv-robosuite-env: robosuite
1.5.2 with MuJoCo 3.9.0; a missing venv is a failure, not a skip) with
mjcf_forge.robosuite.use() on: every robosuite environment with Panda (two for the TwoArm
ones), made and hard-reset, plain and inside robosuite's DomainRandomizationWrapper; every
model a simulation is given is compared with MuJoCo compiling the same XML. The task
XMLs it writes are judged again here through a DocumentCache, under this venv's MuJoCo
(3.17.0, and 4.0.0 when scripts/test.sh runs test_document_cache.py's neighbours under
.cache/venv-mj4).
"""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import mujoco
import pytest

import judge
import mjcf_forge
from helpers import ROOT
from helpers import not_bit_identical

RS_ENV = ROOT / ".cache" / "venv-robosuite-env" / "bin" / "python"
SCRIPT = Path(__file__).parent / "drivers" / "robosuite_resets.py"
RESETS = 2


def run_in_robosuite(tmp: Path, *args: str) -> None:
    assert RS_ENV.exists(), f"{RS_ENV} missing: run scripts/setup_robosuite_env.sh"
    # This run's mjcf_forge alone on the path (its install folder holds another MuJoCo),
    # and the judge.
    only = tmp / "path"
    only.mkdir(exist_ok=True)
    if not (only / "mjcf_forge").exists():
        (only / "mjcf_forge").symlink_to(Path(mjcf_forge.__file__).resolve().parent)
    env = dict(os.environ, PYTHONPATH=f"{only}{os.pathsep}{ROOT / 'tests' / 'judge'}")
    env.pop("MJCF_FORGE_MODEL_CACHE", None)
    run = subprocess.run(
        [str(RS_ENV), str(SCRIPT), *args], cwd=tmp, env=env, capture_output=True, text=True,
        timeout=1200,
    )
    assert run.returncode == 0, run.stderr[-3000:]


@pytest.fixture(scope="module")
def judged(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("robosuite_resets")
    run_in_robosuite(tmp, "judge", str(tmp / "out.json"), "--resets", str(RESETS))
    return json.loads((tmp / "out.json").read_text())


ENVS = [
    "Door", "Lift", "NutAssembly", "NutAssemblyRound", "NutAssemblySingle",
    "NutAssemblySquare", "PickPlace", "PickPlaceBread", "PickPlaceCan", "PickPlaceCereal",
    "PickPlaceMilk", "PickPlaceSingle", "Stack", "ToolHang", "TwoArmHandover", "TwoArmLift",
    "TwoArmPegInHole", "TwoArmTransport", "Wipe",
]


def test_every_environment_was_judged(judged):
    assert set(judged) == {f"{e}{m}" for e in ENVS for m in ("", "+dr")}
    errors = {k: v["error"] for k, v in judged.items() if "error" in v}
    assert errors == {}, errors


@pytest.mark.parametrize("name", ENVS)
def test_every_model_a_hard_reset_gets_is_mujocos_compile(judged, name):
    for mode in ("", "+dr"):
        got = judged[name + mode]
        # The construction's simulation and each reset's.
        assert got["judged"] == 1 + RESETS, got
        assert got["diffs"] == [], got["diffs"]
        assert got["compiles"] + got["patches"] >= got["judged"]
        # robosuite never reads a robot's model compiled alone: never compiled.
        assert got["robot_models_compiled"] == 0
    # The wrapper changed every reset's model in place, and the next reset's model was
    # still MuJoCo's compile: its changes did not leak.
    assert judged[name + "+dr"]["randomized_resets"] == RESETS


def test_resets_of_a_fixed_structure_are_patches(judged):
    # PickPlace and NutAssembly place their objects after the compile: one structure.
    for name in ("PickPlace", "NutAssembly", "Door", "TwoArmLift"):
        assert judged[name]["patches"] >= RESETS, (name, judged[name])
        # Each such reset kept the simulation, its own model patched in place (the model
        # judged above), with and without the wrapper.
        for mode in ("", "+dr"):
            assert judged[name + mode]["kept_simulations"] == RESETS, (name, mode, judged[name + mode])


def test_random_arms_and_environments_get_mujocos_compile(tmp_path):
    # The differential harness over the switch: environments and arms drawn from a seed
    # (the driver's --robots random:SEED), hard-reset plain and inside the randomization
    # wrapper; every model a simulation gets is MuJoCo's compile of its XML.
    import random

    names = random.Random(29).sample([e for e in ENVS if e != "Wipe"], 3)
    run_in_robosuite(
        tmp_path, "judge", str(tmp_path / "out.json"), "--resets", str(RESETS),
        "--envs", ",".join(names), "--robots", "random:29",
    )
    out = json.loads((tmp_path / "out.json").read_text())
    assert {k: v.get("error") for k, v in out.items() if "error" in v} == {}
    for key, got in out.items():
        assert got["judged"] == 1 + RESETS and got["diffs"] == [], (key, got)
    assert len(out) == 6, sorted(out)
    # Arms other than Panda were drawn.
    assert {r for got in out.values() for r in got["robots"]} - {"Panda"}, out


@pytest.fixture(scope="module")
def task_xmls(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("robosuite_xml")
    names = "Lift,PickPlace,NutAssembly,Door,Stack,ToolHang,TwoArmTransport,Wipe"
    run_in_robosuite(tmp, "xml", str(tmp / "xml"), "--resets", "2", "--envs", names)
    return sorted((tmp / "xml").glob("*.xml"))


def test_robosuite_task_xmls_through_a_document_cache(task_xmls):
    """Under this venv's MuJoCo: the cache on robosuite's task XMLs (as text, as robosuite's
    MjSim gives them), each equal to MuJoCo's compile."""
    assert len(task_xmls) == 8 * 3
    cache = mjcf_forge.DocumentCache(max_models=16)
    for path in task_xmls:
        xml = path.read_text()
        model = cache.model(xml)
        ref = mujoco.MjModel.from_xml_string(xml)
        assert judge.compare_models(ref, model) == [], path.name
        assert not_bit_identical(ref, model) == [], path.name
        model.geom_rgba[:] = 0.3  # robosuite's modders, in place
        del model
    assert cache.patches >= 8
