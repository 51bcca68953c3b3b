"""The judge must be able to fail: each model in corpora/judge/ differs from
base.xml in one known way, and the judge has to name that difference.

Run: .cache/venv/bin/python -m pytest tests/judge -q   (after scripts/setup.sh)
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import mujoco
import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))

import judge  # noqa: E402

CORPUS = ROOT / "corpora" / "judge"
BASE = CORPUS / "base.xml"
MODELS_TXT = ROOT / ".cache" / "corpus" / "models.txt"


def c(name: str, prefix: str = "") -> list[str]:
    return judge.compare(BASE, CORPUS / name, prefix)


def starting(diffs: list[str], head: str) -> list[str]:
    return [d for d in diffs if d.startswith(head)]


def test_base_equals_itself():
    assert judge.compare(BASE, BASE) == []


def test_base_equals_fresh_compile_of_itself():
    # Bypass the judge's compile cache: two independent compiles.
    a = mujoco.MjModel.from_xml_path(str(BASE))
    b = mujoco.MjModel.from_xml_path(str(BASE))
    assert a is not b
    assert judge.compare_models(a, b) == []


def test_changed_value():
    diffs = c("changed_value.xml")
    # link2_geom (geom 3) is 0.1 half-length instead of 0.125.
    assert "geom_size[3,1]: 0.1 != 0.125" in diffs
    # ... and everything derived from it moves too.
    assert starting(diffs, "body_mass[3]: ")
    assert starting(diffs, "stat.extent: ")


def test_dropped_default():
    diffs = c("dropped_default.xml")
    # The top-level default friction 0.7 is gone: MuJoCo's default 1.0 applies.
    assert starting(diffs, "geom_friction[0,0]: 0.7 != 1.0")
    assert len(diffs) == 1, diffs


def test_renamed_body():
    assert c("renamed_body.xml") == ["body name 2: 'link1' != 'arm1'"]


def test_changed_text_data():
    diffs = c("changed_text.xml")
    assert len(diffs) == 1 and diffs[0].startswith("text_data[6]: "), diffs


def test_prefixed_equal_with_prefix():
    assert c("prefixed.xml", prefix="p_") == []


def test_prefixed_different_without_prefix():
    diffs = c("prefixed.xml")
    assert "body name 2: 'link1' != 'p_link1'" in diffs
    assert "geom name 0: 'floor' != 'p_floor'" in diffs
    assert "text name 0: 'note' != 'p_note'" in diffs
    # The world body keeps its name.
    assert not starting(diffs, "body name 0:")


def test_base_is_not_prefixed():
    diffs = c("base.xml", prefix="p_")
    assert "body name 1: 'p_base' != 'base'" in diffs


def test_moved_file_is_equal(tmp_path):
    # Mesh path written differently (../meshes): same model.
    assert c("moved/base.xml") == []
    # A copy elsewhere: the asset paths buffer differs, the model does not.
    shutil.copytree(CORPUS / "meshes", tmp_path / "meshes")
    shutil.copy(BASE, tmp_path / "base.xml")
    assert judge.compare(BASE, tmp_path / "base.xml") == []


def test_compile_error_is_a_difference(tmp_path):
    broken = tmp_path / "broken.xml"
    broken.write_text('<mujoco><worldbody><geom type="sphere"/></worldbody></mujoco>')
    diffs = judge.compare(BASE, broken)
    assert len(diffs) == 1
    assert diffs[0].startswith(f"B ({broken}) does not compile: ")
    assert "size" in diffs[0]  # MuJoCo's own message about the missing size
    missing = judge.compare(tmp_path / "nope.xml", BASE)
    assert missing[0].startswith("A (") and "does not compile" in missing[0]


def test_size_difference(tmp_path):
    extra = tmp_path / "extra.xml"
    shutil.copytree(CORPUS / "meshes", tmp_path / "meshes")
    extra.write_text(BASE.read_text().replace(
        '<site name="tip1" pos="0 0 0.2"/>',
        '<site name="tip1" pos="0 0 0.2"/><site name="tip1b" pos="0 0 0.1"/>'))
    diffs = judge.compare(BASE, extra)
    assert "nsite: 2 != 3" in diffs
    assert "site_pos: shape (2, 3) != (3, 3)" in diffs
    assert "site names: count 2 != 3" in diffs


def test_exclusions_are_only_names_and_paths():
    m = judge.load(BASE)
    arrays = [n for n in dir(m) if not n.startswith("_")
              and hasattr(getattr(m, n), "dtype") and judge.excluded_array(n)]
    assert all(n in ("names_map", "tex_contenttypeadr") or n.startswith("name_") or n.endswith("_pathadr")
               for n in arrays), arrays
    assert "numeric_data" not in arrays and "text_adr" not in arrays


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(HERE / "judge.py"), *args],
                          capture_output=True, text=True, cwd=ROOT)


def test_cli_pair():
    r = run_cli(str(BASE), str(CORPUS / "renamed_body.xml"))
    assert r.returncode == 1
    assert r.stdout.strip() == "body name 2: 'link1' != 'arm1'"
    r = run_cli(str(BASE), str(CORPUS / "prefixed.xml"), "--prefix", "p_")
    assert r.returncode == 0 and r.stdout == ""


def test_cli_batch(tmp_path):
    pairs = tmp_path / "pairs.tsv"
    rel = lambda p: str((CORPUS / p).relative_to(ROOT))  # noqa: E731
    pairs.write_text(
        "# comment\n"
        f"{rel('base.xml')}\t{rel('base.xml')}\t\n"
        f"{rel('base.xml')}\t{rel('prefixed.xml')}\tp_\n"
        f"{rel('base.xml')}\t{rel('dropped_default.xml')}\n"
        "\n")
    r = run_cli("--pairs", str(pairs))
    lines = r.stdout.splitlines()
    assert r.returncode == 1, r.stdout + r.stderr
    assert len(lines) == 4
    assert lines[0].startswith("ok ") and lines[1].startswith("ok ")
    assert lines[2].startswith("FAIL ") and "geom_friction[0,0]" in lines[2]
    assert lines[-1] == "2 passed, 1 failed"

    r = run_cli("--pairs", str(pairs), "--json")
    lines = r.stdout.splitlines()
    objs = [json.loads(l) for l in lines[:-1]]
    assert [o["ok"] for o in objs] == [True, True, False]
    assert objs[1]["prefix"] == "p_"
    assert objs[2]["differences"][0].startswith("geom_friction[0,0]: 0.7 != 1.0")
    assert lines[-1] == "2 passed, 1 failed"


def test_cli_batch_a_rejected_mode(tmp_path):
    """A case for another MuJoCo version passes only when this version rejects its input."""
    bad = tmp_path / "bad.xml"
    bad.write_text('<mujoco><worldbody><geom size="x"/></worldbody></mujoco>')
    pairs = tmp_path / "pairs.tsv"
    base = str(CORPUS / "base.xml")
    pairs.write_text(f"{bad}\t{base}\t\ta-rejected\n{base}\t{base}\t\ta-rejected\n")
    r = run_cli("--pairs", str(pairs))
    lines = r.stdout.splitlines()
    assert r.returncode == 1, r.stdout + r.stderr
    assert lines[0].startswith("ok ") and "[a-rejected]" in lines[0]
    assert lines[1].startswith("FAIL ") and "the case says this version rejects it" in lines[1]
    assert lines[-1] == "1 passed, 1 failed"
    pairs.write_text(f"{base}\t{base}\t\tnope\n")
    r = run_cli("--pairs", str(pairs))
    assert r.returncode != 0 and "MODE" in r.stderr


def _real_models() -> list[str]:
    if not MODELS_TXT.exists():
        return []
    return [l for l in MODELS_TXT.read_text().splitlines() if l.strip()]


REAL = _real_models()
# One robot with meshes if present, else the first model listed.
REAL_PICK = next((p for p in REAL if p.endswith("robots/panda/robot.xml")), REAL[0] if REAL else None)


@pytest.mark.skipif(REAL_PICK is None, reason="no .cache/corpus/models.txt (run scripts/setup.sh)")
def test_real_model_equals_itself():
    path = ROOT / REAL_PICK
    assert judge.compare(path, path) == []
    a = mujoco.MjModel.from_xml_path(str(path))
    b = mujoco.MjModel.from_xml_path(str(path))
    assert judge.compare_models(a, b) == []


@pytest.mark.skipif(REAL_PICK is None, reason="no .cache/corpus/models.txt (run scripts/setup.sh)")
def test_real_model_perturbed_is_different():
    path = ROOT / REAL_PICK
    a = mujoco.MjModel.from_xml_path(str(path))
    spec = mujoco.MjSpec.from_file(str(path))
    g = spec.geoms[-1]
    g.friction = [g.friction[0] + 0.25, g.friction[1], g.friction[2]]
    b = spec.compile()
    diffs = judge.compare_models(a, b)
    assert len(diffs) == 1 and diffs[0].startswith(f"geom_friction[{a.ngeom - 1},0]: "), diffs


def _png(path: Path, w: int = 4, h: int = 4) -> None:
    import struct
    import zlib

    raw = b"".join(b"\0" + b"".join(bytes([x * 60 % 256, y * 60 % 256, 100]) for x in range(w))
                   for y in range(h))

    def chunk(t: bytes, d: bytes) -> bytes:
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)

    path.write_bytes(b"\x89PNG\r\n\x1a\n"
                     + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                     + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


TEXTURED = """<mujoco><compiler texturedir="{d}"/>
  <asset><texture name="t" type="2d" file="t.png" {ct}/><material name="m" texture="t"/></asset>
  <worldbody><geom size=".1" material="m"/></worldbody></mujoco>"""


def test_texture_paths_ignored_content_type_compared(tmp_path):
    for d in ("a/tex", "b/deeper/tex"):
        (tmp_path / d).mkdir(parents=True)
        _png(tmp_path / d / "t.png")
    a, b, c2 = tmp_path / "a/m.xml", tmp_path / "b/m.xml", tmp_path / "b/m2.xml"
    a.write_text(TEXTURED.format(d="tex", ct='content_type="image/png"'))
    b.write_text(TEXTURED.format(d="deeper/tex", ct='content_type="image/png"'))
    c2.write_text(TEXTURED.format(d="deeper/tex", ct=""))
    assert judge.compare(a, b) == []  # paths buffer and its offsets differ
    assert judge.compare(a, c2) == ["texture content_type 0: 'image/png' != ''"]


def test_model_name_compared(tmp_path):
    shutil.copytree(CORPUS / "meshes", tmp_path / "meshes")
    other = tmp_path / "other.xml"
    other.write_text(BASE.read_text().replace('model="judge_base"', 'model="other"'))
    assert judge.compare(BASE, other) == ["model name: 'judge_base' != 'other'"]
    # Not prefixed either.
    assert judge.compare(CORPUS / "base.xml", CORPUS / "prefixed.xml", "p_") == []
