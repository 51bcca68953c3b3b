"""LIBERO's own tasks, unmodified, stock and on the switch (``mjcf_forge.robosuite.use()``,
robosuite's rules): one task of each of LIBERO's five suites, built by libero_run.py in
the LIBERO venv (.cache/venv-libero: LIBERO 0.1.1, robosuite 1.4.0, MuJoCo 3.3.1, the
oldest MuJoCo the package supports), once each way, and compared here bit for bit:

- the model the environment simulates (every array of the ``MjModel``, names included,
  every size, option, statistic and visual field);
- with LIBERO's first init state of the task (``set_init_state``) and the same 20 actions
  (scripts/libero_check.sh: 50), every observation (robot state, object states, agentview and wrist images at 128x128)
  and LIBERO's success predicate after each step, and the simulator's state at the end;
- after one more hard reset, the observations it returns and, after ``set_init_state``,
  those after 5 steps; on the switch that reset keeps the simulation and its render
  context (its model patched in place), and stock's makes them again.

The other 125 tasks: scripts/libero_check.sh (results in docs/fidelity.md).
"""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import mjcf_forge
import numpy as np
import pytest

from helpers import ROOT

LIBERO_PY = ROOT / ".cache" / "venv-libero" / "bin" / "python"
CONFIG = ROOT / ".cache" / "libero-config"
SCRIPT = Path(__file__).parent / "drivers" / "libero_run.py"
# One task of each suite; three with LIBERO's flat stove, whose part repeats an asset name
# of the scene with other content (stock keeps the scene's: robosuite's asset rule).
TASKS = ["libero_spatial:0", "libero_object:0", "libero_goal:1", "libero_10:2", "libero_90:20"]


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """The model store the switch's processes share (MJCF_FORGE_STORE): empty when the
    records' switch process starts (every structure compiled and stored), then read by the
    evaluations (their task's structure loaded from it, by two processes at once)."""
    return tmp_path_factory.mktemp("store")


def run(mode: str, out: Path, tmp: Path, store: Path) -> subprocess.Popen:
    assert LIBERO_PY.exists(), f"{LIBERO_PY} missing: run scripts/setup_libero_env.sh"
    only = tmp / "path"
    only.mkdir(exist_ok=True)
    if not (only / "mjcf_forge").exists():
        (only / "mjcf_forge").symlink_to(Path(mjcf_forge.__file__).resolve().parent)
    env = dict(os.environ, PYTHONPATH=str(only), PYTHONHASHSEED="0", LIBERO_CONFIG_PATH=str(CONFIG))
    env.setdefault("MUJOCO_GL", "egl")
    env["MJCF_FORGE_STORE"] = str(store) if mode == "switch" else "off"
    return subprocess.Popen(
        [str(LIBERO_PY), str(SCRIPT), mode, str(out), *TASKS, "--cameras", "--steps", "20", "--resets", "1", "--again"],
        cwd=tmp, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )


@pytest.fixture(scope="module")
def records(tmp_path_factory, store):
    tmp = tmp_path_factory.mktemp("libero")
    procs = {mode: run(mode, tmp / mode, tmp, store) for mode in ("stock", "switch")}
    for mode, proc in procs.items():
        out, err = proc.communicate(timeout=1800)
        assert proc.returncode == 0, err[-3000:]
        assert out.split() == [w for t in TASKS for w in (t, "ok")], (mode, out, err[-3000:])
    # Read lazily, an array at a time: the records hold each task's whole model (LIBERO's
    # textures alone are 190 MB a task), 2.1 GB for the ten.
    loaded = {
        mode: {t: np.load(tmp / mode / (t.replace(":", "-") + ".npz")) for t in TASKS}
        for mode in procs
    }
    yield loaded
    for by_task in loaded.values():
        for record in by_task.values():
            record.close()


def differing(a: dict, b: dict, prefix: str) -> list:
    keys = {k for k in a if k.startswith(prefix)} | {k for k in b if k.startswith(prefix)}
    out = []
    for k in sorted(keys):
        x, y = a.get(k), b.get(k)
        if x is None or y is None or x.shape != y.shape or x.dtype != y.dtype or x.tobytes() != y.tobytes():
            out.append(k)
    return out


@pytest.mark.parametrize("task", TASKS)
def test_a_libero_tasks_model_is_stocks_bit_for_bit(records, task):
    stock, switch = records["stock"][task], records["switch"][task]
    assert len([k for k in stock if k.startswith("model/")]) > 300
    assert differing(stock, switch, "model/") == []


@pytest.mark.parametrize("task", TASKS)
def test_a_libero_tasks_saved_xml_is_stocks_byte_for_byte(records, task):
    # env.sim.model.get_xml() (mujoco.mj_saveLastXML), what a dataset saves with each demo:
    # after the first reset and after a hard reset that kept the simulation.
    stock, switch = records["stock"][task], records["switch"][task]
    keys = sorted(k for k in stock if k.startswith("xml/"))
    assert keys == ["xml/first", "xml/reset0"]
    assert differing(stock, switch, "xml/") == []
    assert "<worldbody>" in str(stock["xml/first"])


@pytest.mark.parametrize("task", TASKS)
def test_a_libero_task_observes_and_succeeds_as_stock(records, task):
    stock, switch = records["stock"][task], records["switch"][task]
    images = [k for k in stock if k.startswith("obs/") and k.endswith("_image")]
    assert sorted(images) == ["obs/agentview_image", "obs/robot0_eye_in_hand_image"]
    assert stock["obs/agentview_image"].shape == (21, 128, 128, 3)
    assert stock["obs/agentview_image"].std() > 10  # a scene, not a blank frame
    assert len(stock["success"]) == 20
    for prefix in ("obs/", "success", "state", "reset/", "again/"):
        assert differing(stock, switch, prefix) == [], prefix


@pytest.mark.parametrize("task", TASKS)
def test_a_second_environment_of_a_libero_task_is_stocks_bit_for_bit(records, task):
    """The task's environment closed, another made in the same process: its model (every
    array's digest) and its observations (images included) after set_init_state and 5
    steps are stock's; on the switch it runs on the first environment's simulation (its
    model patched, its render context kept), where stock makes everything again."""
    stock, switch = records["stock"][task], records["switch"][task]
    assert len([k for k in stock if k.startswith("second/model/")]) > 300
    assert "second/obs/agentview_image" in stock
    assert differing(stock, switch, "second/model/") == []
    assert differing(stock, switch, "second/obs/") == []
    assert (int(stock["second/kept"]), int(switch["second/kept"])) == (0, 1)


@pytest.mark.parametrize("task", TASKS)
def test_a_libero_hard_reset_on_the_switch_keeps_the_simulation(records, task):
    """The hard reset above (its observations, images included, are stock's) kept the
    simulation, its model patched and its render context as it was; stock's never does."""
    assert int(records["stock"][task]["kept"]) == 0
    assert int(records["switch"][task]["kept"]) == 1


EVAL = Path(__file__).parent / "drivers" / "libero_eval.py"
EVAL_TASK = "libero_object:0"


@pytest.fixture(scope="module")
def evaluations(tmp_path_factory, store):
    """libero_eval.py on one task: twice on the switch (two processes, each with two
    evaluations in one environment and one in LIBERO's SubprocVectorEnv of two workers),
    and once stock without the vector environment. The switch's processes share the
    records' store (``store``), which holds the task's structure after them."""
    tmp = tmp_path_factory.mktemp("libero_eval")
    only = tmp / "path"
    only.mkdir()
    (only / "mjcf_forge").symlink_to(Path(mjcf_forge.__file__).resolve().parent)
    env = dict(os.environ, PYTHONPATH=str(only), LIBERO_CONFIG_PATH=str(CONFIG))
    env.setdefault("MUJOCO_GL", "egl")
    env["MJCF_FORGE_STORE"] = str(store)
    runs = {"switch-a": [], "switch-b": [], "stock": ["--stock", "--no-vector"]}
    procs = {
        name: subprocess.Popen(
            [str(LIBERO_PY), str(EVAL), str(tmp / f"{name}.npz"), EVAL_TASK, *flags],
            cwd=tmp, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )
        for name, flags in runs.items()
    }
    for name, proc in procs.items():
        out, err = proc.communicate(timeout=900)
        assert proc.returncode == 0 and out.split() == ["ok"], (name, err[-3000:])
    return {name: dict(np.load(tmp / f"{name}.npz")) for name in runs}


def episodes(record: dict, source: str) -> dict:
    return {k[len(source):]: v for k, v in record.items() if k.startswith(source)}


def test_evaluations_with_the_same_seeds_roll_out_bit_equal_on_the_switch(evaluations):
    """Each hard reset on the switch restores what stock's does (the data reset, the model as
    compiled from the task, LIBERO's placements from its seeded generator): evaluations
    with the same seed, one after the other in one environment, in two processes, and in
    the worker of LIBERO's SubprocVectorEnv with that seed, give the same rollouts, bit for
    bit, and stock's. With another seed they differ, from the same init states: what a
    reset drew outlives LIBERO's set_init_state (it writes qpos and qvel only)."""
    a = evaluations["switch-a"]
    by_seed = {0: episodes(a, "single/0/"), 1: episodes(a, "single/2/")}
    assert len([k for k in by_seed[0] if k.endswith("/obs/robot0_joint_pos")]) == 2
    for record in (evaluations["switch-a"], evaluations["switch-b"]):
        for source, seed in (("single/0/", 0), ("single/1/", 0), ("single/2/", 1),
                             ("vector/0/", 0), ("vector/1/", 1)):
            assert differing(by_seed[seed], episodes(record, source), "") == [], source
        # Every hard reset of the single evaluations kept the simulation.
        assert int(record["kept"]) == 6
    stock = evaluations["stock"]
    for source, seed in (("single/0/", 0), ("single/1/", 0), ("single/2/", 1)):
        assert differing(episodes(stock, source), by_seed[seed], "") == [], source
    assert int(stock["kept"]) == 0
    assert differing(by_seed[0], by_seed[1], "") != []


def test_evaluations_load_the_task_from_the_records_store(records, evaluations, store):
    """Every structure the records' switch process compiled went into the shared store
    (written whole, keyed by the structure, MuJoCo and the files); the two evaluation
    processes, starting together, then had every miss of theirs loaded from it, none
    compiled. Their rollouts above are stock's bit for bit."""
    assert len(list(store.glob("*.mjfs"))) >= len(TASKS)
    assert not [p for p in store.iterdir() if p.suffix != ".mjfs"]  # no half-written entry
    for name in ("switch-a", "switch-b"):
        loads, compiles = (int(v) for v in evaluations[name]["loads"])
        assert loads >= 1 and loads == compiles, (name, loads, compiles)
