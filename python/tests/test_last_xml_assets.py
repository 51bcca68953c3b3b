"""MuJoCo's last loaded XML model as stock leaves it where MuJoCo writes which of a model's
meshes were read from disk and which were taken from its asset cache (a ``content_type``
for the first: MuJoCo 3.3.1 and 3.9.0, the robosuite venvs' MuJoCo): the switch's model
cache compiles a structure once, and the model store compiles it in no process, so this
process's asset cache is not stock's; ``mjcf_forge._asset_cache`` keeps both and brings
the cache to stock's before the slot is loaded again. Each expectation is stock robosuite's
own output for the sequence, in a process of its own (drivers/last_xml_assets.py).
"""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import mjcf_forge
import pytest

from helpers import ROOT

DRIVER = Path(__file__).parent / "drivers" / "last_xml_assets.py"
VENVS = {
    "3.3.1": ROOT / ".cache" / "venv-libero" / "bin" / "python",
    "3.9.0": ROOT / ".cache" / "venv-robosuite-env" / "bin" / "python",
}
TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
PART = '<mujoco model="part"><asset><mesh name="a" file="a.obj"/></asset><worldbody><body name="p"><freejoint/><geom type="mesh" mesh="a"/></body></worldbody></mujoco>'
SCENE = '<mujoco model="scene"><asset><mesh name="a" file="a.obj"/><mesh name="b" file="b.obj" scale="2 2 2"/></asset><worldbody><geom name="g" type="mesh" mesh="b"/><body name="p"><freejoint/><geom type="mesh" mesh="a"/></body></worldbody></mujoco>'


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("assets")
    for name in ("a.obj", "b.obj"):
        (d / name).write_text(TETRA)
    (d / "part.xml").write_text(PART)
    (d / "scene.xml").write_text(SCENE)
    only = d / "path"
    only.mkdir()
    (only / "mjcf_forge").symlink_to(Path(mjcf_forge.__file__).resolve().parent)
    return d


def written(python: Path, mode: str, sequence: str, folder: Path, store: str) -> str:
    assert python.exists(), f"{python} missing: run scripts/setup.sh"
    out = folder / f"{python.parent.parent.name}-{mode}-{sequence}-{abs(hash(store))}.txt"
    env = dict(os.environ, PYTHONPATH=str(folder / "path"), MJCF_FORGE_STORE=store)
    done = subprocess.run(
        [str(python), str(DRIVER), mode, sequence, str(folder), str(out)],
        env=env, capture_output=True, text=True, timeout=300,
    )
    assert done.returncode == 0 and done.stdout.split() == ["ok"], done.stderr[-3000:]
    return out.read_text()


@pytest.mark.parametrize("version", sorted(VENVS))
@pytest.mark.parametrize("sequence", ["once", "twice"])
def test_the_saved_xml_is_stocks_whatever_the_asset_cache_held(folder, version, sequence, tmp_path):
    python = VENVS[version]
    expected = written(python, "stock", sequence, folder, "off")
    assert "<mesh" in expected
    # MuJoCo writes where the meshes came from (the premise of this file).
    assert ("content_type" in expected) == (sequence == "once")
    store = str(tmp_path / "store")
    # No store; a cold store (the structure compiled, then stored); the same store warm
    # (the structure loaded from it: no compile read the meshes in that process).
    for label in ("off", "cold", "warm"):
        got = written(python, "switch", sequence, folder, "off" if label == "off" else store)
        assert got == expected, (label, version, sequence)
    assert list(Path(store).glob("*.mjfs"))  # what the warm run loaded


@pytest.mark.parametrize("version", sorted(VENVS))
def test_a_cache_state_the_switch_cannot_give_is_refused_not_written(folder, version):
    """The part's model read mesh a, then the scene's read b from disk and a from the cache:
    this process compiled both meshes' models, and no compile gives that state here."""
    python = VENVS[version]
    expected = written(python, "stock", "part-then-scene", folder, "off")
    assert expected.count("content_type") == 1  # b's, read from disk
    got = written(python, "switch", "part-then-scene", folder, "off")
    assert got.startswith("error: LastXmlError: mujoco.mj_saveLastXML: MuJoCo's asset cache held 1 of")
