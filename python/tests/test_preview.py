"""Scene.preview(): contact sheets drawn by mujoco.Renderer (needs mujoco and a headless
OpenGL: EGL or OSMesa). The sheet is a picture, written as a PNG that reads back as the
returned array; cells differ where variants differ and not where they do not; every
placed object is drawn in its cell, where its manifest pose projects through the camera.
"""
from __future__ import annotations

import math
import os
import struct
import subprocess
import sys
import zlib

import numpy as np
import pytest

from helpers import ROOT, RS_ASSETS

import mjcf_forge
from mjcf_forge import MjcfError, Scene
from mjcf_forge import _preview

DEMO = ROOT / "corpora" / "scenes" / "demo" / "demo.toml"
LIFT5 = ROOT / "benches" / "scenes" / "lift5.toml"


def read_png(path) -> np.ndarray:
    """An 8-bit RGB PNG with filter 0 rows (what _preview writes) as an array."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat = 8, b""
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        (crc,) = struct.unpack(">I", data[pos + 8 + n : pos + 12 + n])
        assert crc == zlib.crc32(kind + body) & 0xFFFFFFFF
        if kind == b"IHDR":
            width, height = struct.unpack(">II", body[:8])
            assert body[8:] == b"\x08\x02\x00\x00\x00"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    rows = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, width * 3 + 1)
    assert (rows[:, 0] == 0).all()
    return rows[:, 1:].reshape(height, width, 3)


def cell(sheet: np.ndarray, k: int, columns: int, size) -> np.ndarray:
    x, y = _preview.cell_origin(k, columns, size)
    return sheet[y : y + size[1], x : x + size[0]]


@pytest.fixture(scope="module")
def demo() -> Scene:
    return Scene.load(DEMO)


def test_sheet_is_a_picture_written_as_png(demo, tmp_path):
    out = tmp_path / "sheet.png"
    sheet = demo.preview([0, 1, 1, 5], out, cell=(160, 120), columns=3)
    assert sheet.shape == (2 * 120 + 2, 3 * 160 + 2 * 2, 3) and sheet.dtype == np.uint8
    assert (read_png(out) == sheet).all()
    assert sheet.var() > 100
    cells = [cell(sheet, k, 3, (160, 120)) for k in range(4)]
    for c in cells:
        assert c.var() > 100
    # The same index twice: the same pixels; different variants: many pixels differ.
    assert (cells[1] == cells[2]).all()
    for a, b in [(0, 1), (0, 3), (1, 3)]:
        differing = (cells[a] != cells[b]).any(axis=2).sum()
        assert differing > 160 * 120 // 10, (a, b, differing)
    # The grid's unused cell is the gap colour; labels are in the corner only.
    assert (cell(sheet, 5, 3, (160, 120)) == _preview.GAP_COLOR).all()
    bare = demo.preview([1], cell=(160, 120), labels=False)
    corner = (bare != cells[1]).any(axis=2)
    assert corner.any() and not corner[30:, :].any() and not corner[:, 60:].any()


def test_default_grid_and_errors(demo, tmp_path):
    sheet = demo.preview(5, cell=(40, 30))  # range(5): 3 columns, 2 rows
    assert sheet.shape == (2 * 30 + 2, 3 * 40 + 2 * 2, 3)
    with pytest.raises(ValueError, match="no camera named 'back'.*its cameras: front"):
        demo.preview([0], cell=(40, 30), camera="back")
    with pytest.raises(ValueError, match="unknown geom set"):
        demo.preview([0], geoms="some")
    with pytest.raises(ValueError, match="at least one variant"):
        demo.preview([])
    bad = tmp_path / "seg.png"
    with pytest.raises(ValueError, match="pass no path"):
        demo.preview([0], bad, segmentation=True)
    assert not bad.exists()


def placed_bodies(model, body: str) -> set[int]:
    """Geom ids of `body` and of every body under it."""
    import mujoco

    root = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    assert root > 0, body

    def under(b: int) -> bool:
        while b != 0:
            if b == root:
                return True
            b = model.body_parentid[b]
        return False

    return {g for g in range(model.ngeom) if under(model.geom_bodyid[g])}


def project(point, free, fovy_deg, size):
    """Pixel (column, row) of a world point seen by the sheet's free camera."""
    lookat, distance, azimuth, elevation = free
    az, el = math.radians(azimuth), math.radians(elevation)
    forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    eye = lookat - distance * forward
    right = np.cross(forward, [0, 0, 1])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rel = np.asarray(point) - eye
    depth = rel @ forward
    focal = size[1] / 2 / math.tan(math.radians(fovy_deg) / 2)
    return size[0] / 2 + focal * (rel @ right) / depth, size[1] / 2 - focal * (rel @ up) / depth


def check_every_placed_object(scene, indices, size, **options):
    import mujoco

    seg = scene.preview(indices, cell=size, segmentation=True, **options)
    columns = _preview.default_columns(len(indices))
    first = scene.variant(indices[0]).compile()
    free = _preview.free_camera(mujoco, first)
    for k, index in enumerate(indices):
        v = scene.variant(index)
        model = v.compile()
        data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, data)
        ids = cell(seg, k, columns, size)
        assert len(np.unique(ids)) > 3
        assert v.params["objects"]
        for obj in v.params["objects"]:
            geoms = placed_bodies(model, obj["body"])
            mask = np.isin(ids, list(geoms))
            assert mask.sum() > 0, f"variant {index}: {obj['body']} not drawn"
            if "camera" in options:
                continue
            # The manifest's pose, where the compiled model has the body, projects onto
            # the object's own pixels (or next to them: the origin may sit behind an edge).
            pos = np.array(obj["pos"], dtype=float)
            body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, obj["body"])
            assert np.allclose(data.xpos[body], pos, atol=1e-9)
            u, w = project(pos, free, model.vis.global_.fovy, size)
            r = 3
            window = mask[
                max(0, int(w) - r) : int(w) + r + 1, max(0, int(u) - r) : int(u) + r + 1
            ]
            assert window.any(), f"variant {index}: {obj['body']} not at its pose ({u}, {w})"


def test_every_placed_object_is_drawn_demo(demo):
    check_every_placed_object(demo, [0, 1, 2, 3, 4, 5], (320, 240))
    check_every_placed_object(demo, [6, 7], (320, 240), camera="front", geoms="visual")


def test_every_placed_object_is_drawn_lift5():
    if not RS_ASSETS.is_dir():
        pytest.fail(f"{RS_ASSETS} missing: run scripts/setup.sh")
    scene = Scene.load(LIFT5)
    check_every_placed_object(scene, [0, 1, 2], (320, 240))
    check_every_placed_object(scene, [3], (320, 240), camera="agentview")


def test_mujoco_gl_defaults_to_egl_when_unset(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    code = (
        "import os, mjcf_forge\n"
        "s = mjcf_forge.Scene.load()\n"
        "a = s.preview([0], cell=(32, 24))\n"
        "print(os.environ['MUJOCO_GL'], a.shape)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert out.stdout.split()[0] in ("egl", "osmesa")


def test_mujoco_imported_first_without_a_display_is_a_clear_error():
    # mujoco picks GLFW when imported with MUJOCO_GL unset, and GLFW without a display
    # ends the process: preview() says what to do instead.
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY", "WAYLAND_DISPLAY")}
    code = (
        "import mujoco, mjcf_forge\n"
        "try:\n"
        "    mjcf_forge.Scene.load().preview([0], cell=(32, 24))\n"
        "except RuntimeError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "set MUJOCO_GL=egl" in out.stdout
