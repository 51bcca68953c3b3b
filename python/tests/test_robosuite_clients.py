"""robosuite's clients through their own code paths, stock against the switch, each in
its own process (drivers/robosuite_clients.py says what each step runs):

- robosuite's collection path: ``DataCollectionWrapper`` episodes of seeded random
  actions (CI samples: 2 demos of 20 steps in Lift and Door on 1.5.2, Lift on 1.4.0;
  scripts/clients_full.sh: 10 demos of 50 steps in Lift, PickPlaceCan,
  NutAssemblySquare, Stack and Door everywhere) gathered by robosuite's
  ``gather_demonstrations_as_hdf5``: every saved model
  file (``env.sim.model.get_xml()``) byte for byte stock's, every state bit for bit;
- each mode's dataset replayed by the other mode (a dataset saved on the switch replayed
  on stock, and the reverse): robosuite's playback loop (forced states, and the actions
  open loop, which reach the recorded states bit for bit), robomimic 0.3.0's
  ``dataset_states_to_obs`` conversion with agentview and wrist images, a MimicGen-style
  generation loop, and every ``get_xml()`` those clients read: the two replays equal;
- every environment of ``robosuite.ALL_ENVIRONMENTS`` (robosuite 1.5.2; Lift and Door on
  1.4.0 with MuJoCo 3.3.1, Lift with 2.3.7; all of them in scripts/clients_full.sh)
  with its default robots: the compiled model, ``get_xml()`` and the observations with an
  agentview image; robosuite's ``CameraMover`` and its frames; ``get_xml()`` inside
  ``DomainRandomizationWrapper``, which carries the wrapper's changes to the live model.

Three robosuite venvs: robosuite 1.5.2 with MuJoCo 3.9.0 (.cache/venv-robosuite-env),
LIBERO's robosuite 1.4.0 with MuJoCo 3.3.1 (.cache/venv-libero), and robosuite 1.4.0 with
MuJoCo 2.3.7 (.cache/venv-mj2: the oldest MuJoCo robosuite 1.4.0 accepts, where the
switch's model cache is off and says so once); a missing venv is a failure with the
setup step to run. Runs under any Python MuJoCo of this suite (it only
reads what the drivers wrote); scripts/test.sh runs it once.
"""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import mjcf_forge
import numpy as np
import pytest

from helpers import ROOT

SCRIPT = Path(__file__).parent / "drivers" / "robosuite_clients.py"
# scripts/clients_full.sh sets it: more demos, longer, every environment everywhere.
FULL = os.environ.get("MJCF_FORGE_CLIENTS_FULL") == "1"
RECORDED = ["Lift", "PickPlaceCan", "NutAssemblySquare", "Stack", "Door"]
# CI's sample of robosuite 1.5.2's 19 environments: one of each task class (the single-
# object NutAssembly and PickPlace variants are subclasses of the two kept), every two-arm
# one; scripts/clients_full.sh builds all 19 in every venv.
SAMPLED = ["Lift", "Stack", "NutAssembly", "PickPlace", "Door", "Wipe", "ToolHang",
           "TwoArmLift", "TwoArmPegInHole", "TwoArmHandover", "TwoArmTransport"]
# venv -> (python, (setup script), environments recorded, environments of `envs`)
VENVS = {
    "robosuite-1.5.2": (
        ROOT / ".cache" / "venv-robosuite-env" / "bin" / "python",
        "scripts/setup_robosuite_env.sh",
        RECORDED if FULL else ["Lift", "Door"],
        None if FULL else SAMPLED,  # None: all of robosuite.ALL_ENVIRONMENTS
    ),
    "robosuite-1.4.0": (
        ROOT / ".cache" / "venv-libero" / "bin" / "python",
        "scripts/setup_libero_env.sh",
        RECORDED if FULL else ["Lift"],
        None if FULL else ["Lift", "Door"],
    ),
    # The oldest MuJoCo robosuite 1.4.0 accepts: the switch's model cache is off there
    # (it needs 3.3), said once per process, and every client reads what stock gives.
    "robosuite-1.4.0-mujoco-2.3.7": (
        ROOT / ".cache" / "venv-mj2" / "bin" / "python",
        "scripts/setup_mj2_env.sh",
        RECORDED if FULL else ["Lift"],
        None if FULL else ["Lift"],
    ),
}
OLD_MUJOCO_WARNING = "mjcf_forge: the model cache needs MuJoCo 3.3 or newer, and this is 2.3.7"
DEMOS, STEPS = (10, 50) if FULL else (2, 20)


def run_both(python: Path, tmp: Path, command: str, args: dict) -> dict:
    """The driver's ``command`` stock and on the switch, side by side; ``args[mode]``
    are each mode's extra arguments. Returns each mode's standard error."""
    only = tmp / "path"
    only.mkdir(exist_ok=True)
    if not (only / "mjcf_forge").exists():
        (only / "mjcf_forge").symlink_to(Path(mjcf_forge.__file__).resolve().parent)
    env = dict(os.environ, PYTHONPATH=str(only), PYTHONHASHSEED="0")
    env.setdefault("MUJOCO_GL", "egl")
    env.pop("MJCF_FORGE_MODEL_CACHE", None)
    procs = {
        mode: subprocess.Popen(
            [str(python), str(SCRIPT), command, mode, *args[mode]], cwd=tmp, env=env,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )
        for mode in ("stock", "switch")
    }
    errors = {}
    for mode, proc in procs.items():
        _, errors[mode] = proc.communicate(timeout=1800)
        assert proc.returncode == 0, (command, mode, errors[mode][-3000:])
    return errors


@pytest.fixture(scope="module", params=sorted(VENVS))
def clients(request, tmp_path_factory):
    python, setup, recorded, envs = VENVS[request.param]
    assert python.exists(), f"{python} missing: run {setup}"
    tmp = tmp_path_factory.mktemp(request.param)
    names = ",".join(recorded)
    errors = run_both(python, tmp, "record", {
        mode: [str(tmp / "record" / mode), "--envs", names, "--demos", str(DEMOS), "--steps", str(STEPS)]
        for mode in ("stock", "switch")
    })
    # Each mode replays the other's dataset.
    other = {"stock": "switch", "switch": "stock"}
    errors2 = run_both(python, tmp, "replay", {
        mode: [str(tmp / "replay" / mode), "--data", str(tmp / "record" / other[mode]), "--envs", names]
        for mode in ("stock", "switch")
    })
    every = ["--envs", ",".join(envs)] if envs else []
    errors3 = run_both(python, tmp, "envs", {
        mode: [str(tmp / "envs" / mode), "--steps", "10", *every] for mode in ("stock", "switch")
    })
    warned = [e["switch"].count(OLD_MUJOCO_WARNING) for e in (errors, errors2, errors3)]
    stock_warned = [e["stock"].count("mjcf_forge") for e in (errors, errors2, errors3)]
    (tmp / "warnings.json").write_text(json.dumps({"switch": warned, "stock": stock_warned}))
    return request.param, tmp, recorded


def demos(folder: Path) -> list:
    """(actions, model file, states) per demo of ``folder/demo.hdf5``, in the order of
    their actions, as the driver read them back from the file robosuite wrote."""
    arrays = np.load(folder / "demos.npz")
    files = json.loads((folder / "demos.json").read_text())
    return [(arrays[f"actions/{i}"], xml, arrays[f"states/{i}"]) for i, xml in enumerate(files)]


def differing(a: dict, b: dict) -> list:
    assert set(a) == set(b), sorted(set(a) ^ set(b))[:10]
    return [k for k in a if not np.array_equal(a[k], b[k])]


def test_the_saved_model_files_and_states_are_stocks(clients):
    venv, tmp, recorded = clients
    for name in recorded:
        stock = demos(tmp / "record" / "stock" / name)
        switch = demos(tmp / "record" / "switch" / name)
        assert len(stock) == len(switch) == DEMOS, (venv, name)
        for (a_stock, xml_stock, s_stock), (a_switch, xml_switch, s_switch) in zip(stock, switch):
            assert np.array_equal(a_stock, a_switch)
            assert xml_stock == xml_switch, (venv, name)
            assert np.array_equal(s_stock, s_switch), (venv, name)
        # Lift draws its cube's size at every hard reset: each episode's file is another
        # scene (the others place their objects after the compile: one text).
        if name == "Lift":
            assert len({xml for _, xml, _ in stock}) == DEMOS, venv


def test_a_dataset_saved_on_the_switch_replays_on_stock_to_stocks_states(clients):
    venv, tmp, recorded = clients
    for name in recorded:
        on_stock = dict(np.load(tmp / "replay" / "stock" / f"{name}.npz"))  # switch's data
        on_switch = dict(np.load(tmp / "replay" / "switch" / f"{name}.npz"))  # stock's data
        assert differing(on_stock, on_switch) == [], (venv, name)
        for i in range(DEMOS):
            # The actions played open loop from the first state reach every recorded
            # state (robosuite's reset_from_xml_string trick), on stock from the switch's.
            assert np.array_equal(on_stock[f"played/{i}"][:-1], on_stock[f"recorded/{i}"][1:]), (venv, name, i)
        texts_stock = json.loads((tmp / "replay" / "stock" / f"{name}.json").read_text())
        texts_switch = json.loads((tmp / "replay" / "switch" / f"{name}.json").read_text())
        assert texts_stock == texts_switch, (venv, name)
        assert len(texts_stock) == 2 * DEMOS + 3


def test_robomimics_conversion_and_a_generation_loop_read_what_stock_gives(clients):
    venv, tmp, recorded = clients
    for name in recorded:
        got = dict(np.load(tmp / "replay" / "switch" / f"{name}.npz"))
        images = [k for k in got if k.startswith("robomimic/") and k.endswith("_image")]
        # Two cameras, every step of every demo, and not blank.
        assert len(images) == 2 * DEMOS * (STEPS + 1), (venv, name, len(images))
        assert all(got[k].std() > 0 for k in images)
        assert [k for k in got if k.startswith("attempt/")], (venv, name)


def test_every_environment_builds_observes_and_writes_stocks_xml(clients):
    venv, tmp, _ = clients
    stock_models = json.loads((tmp / "envs" / "stock" / "models.json").read_text())
    switch_models = json.loads((tmp / "envs" / "switch" / "models.json").read_text())
    assert stock_models == switch_models
    if venv == "robosuite-1.5.2":
        assert len(stock_models) == (19 if FULL else len(SAMPLED))
    for name in stock_models:
        stock_xml = (tmp / "envs" / "stock" / f"{name}.xml").read_text()
        assert stock_xml == (tmp / "envs" / "switch" / f"{name}.xml").read_text(), (venv, name)
        assert 'name="agentview"' in stock_xml
    stock = dict(np.load(tmp / "envs" / "stock" / "envs.npz"))
    switch = dict(np.load(tmp / "envs" / "switch" / "envs.npz"))
    assert differing(stock, switch) == []
    assert len([k for k in stock if k.endswith("agentview_image")]) == 11 * len(stock_models)


def test_camera_mover_moves_stocks_camera(clients):
    venv, tmp, _ = clients
    stock = (tmp / "envs" / "stock" / "camera_mover.xml").read_text()
    assert stock == (tmp / "envs" / "switch" / "camera_mover.xml").read_text()
    # CameraMover's own edit of get_xml(): the mocap body it adds for the camera.
    assert 'name="frontview_cameramover"' in stock
    frames = np.load(tmp / "envs" / "switch" / "envs.npz")["camera_mover/frames"]
    assert np.array_equal(frames, np.load(tmp / "envs" / "stock" / "envs.npz")["camera_mover/frames"])
    assert all(not np.array_equal(a, b) for a, b in zip(frames, frames[1:]))


def test_on_a_mujoco_the_caches_do_not_run_on_the_switch_says_so_once(clients):
    venv, tmp, _ = clients
    warned = json.loads((tmp / "warnings.json").read_text())
    # One warning per switched process on MuJoCo 2.3.7 (record, replay, envs), none on
    # the MuJoCos the caches run on; stock never hears of the package.
    assert warned["switch"] == ([1, 1, 1] if venv.endswith("mujoco-2.3.7") else [0, 0, 0]), warned
    assert warned["stock"] == [0, 0, 0], warned


def test_get_xml_carries_domain_randomization_as_stock(clients):
    venv, tmp, _ = clients
    if venv != "robosuite-1.5.2":
        # robosuite 1.4.0's wrapper fails at its first hard reset, stock too.
        assert not (tmp / "envs" / "stock" / "randomized.json").exists()
        return
    stock = json.loads((tmp / "envs" / "stock" / "randomized.json").read_text())
    assert stock == json.loads((tmp / "envs" / "switch" / "randomized.json").read_text())
    # The wrapper changed the model between each reset and its steps, and across resets.
    assert len(set(stock)) == len(stock) == 6, venv


def test_a_recording_loads_each_scene_into_mujocos_last_xml_once(clients):
    venv, tmp, recorded = clients
    state = json.loads((tmp / "record" / "switch" / "last_xml.json").read_text())
    if venv.endswith("mujoco-2.3.7"):
        # The model cache is off there: every load was stock's own, nothing was owed.
        assert (state["paid"], state["rewritten"]) == (0, 0), state
        return
    # One load per environment, at its first get_xml(); Lift's later episodes (a new
    # cube size each) are written through that load (MuJoCo before 3.16 writes a body's
    # inertia only where it was given), the others' texts repeat.
    assert state["paid"] == len(recorded), state
    assert state["rewritten"] == DEMOS - 1, state
