"""Contact sheets of a scene's variants: :meth:`Scene.preview`.

Each variant is compiled with the user's ``mujoco`` (``Variant.compile()``) and drawn by
``mujoco.Renderer`` at its initial pose into one cell of a grid, labelled with its index;
the grid is returned as a numpy array and written as PNG (zlib and struct, no Pillow).
The camera and the geom sets are the command line's (``mjcf-forge preview``,
docs/cli.md); the labels are drawn with a small bitmap font here, so the cells are not
the command line's pixel for pixel.

The OpenGL platform is ``mujoco``'s, chosen by ``MUJOCO_GL`` when ``mujoco`` is imported:
when ``MUJOCO_GL`` is unset and ``mujoco`` not imported yet, this module sets it to
``egl``, or to ``osmesa`` when no EGL context can be made.
"""

from __future__ import annotations

import math
import os
import struct
import sys
import zlib
from typing import Iterable, Optional, Sequence, Tuple, Union

import numpy as np

from ._files import write_atomic

GAP = 2
"""Pixels between cells."""
GAP_COLOR = (32, 32, 32)
"""The colour between cells (and of unused cells)."""

GEOMS = ("default", "visual", "collision", "all")

# 3x5 digits, a row per string, '#' lit; drawn scaled.
_DIGITS = {
    "0": ("###", "#.#", "#.#", "#.#", "###"),
    "1": (".#.", "##.", ".#.", ".#.", "###"),
    "2": ("###", "..#", "###", "#..", "###"),
    "3": ("###", "..#", "###", "..#", "###"),
    "4": ("#.#", "#.#", "###", "..#", "..#"),
    "5": ("###", "#..", "###", "..#", "###"),
    "6": ("###", "#..", "###", "#.#", "###"),
    "7": ("###", "..#", "..#", "..#", "..#"),
    "8": ("###", "#.#", "###", "#.#", "###"),
    "9": ("###", "#.#", "###", "..#", "###"),
}


def _choose_gl() -> None:
    """Sets ``MUJOCO_GL`` before ``mujoco`` is imported, when the user has not."""
    if os.environ.get("MUJOCO_GL") or "mujoco" in sys.modules:
        return
    if sys.platform.startswith("linux"):
        os.environ["MUJOCO_GL"] = "egl" if _egl_works() else "osmesa"


def _egl_works() -> bool:
    """Whether libEGL opens and offers a display (without importing mujoco or PyOpenGL)."""
    import ctypes

    try:
        egl = ctypes.CDLL("libEGL.so.1")
    except OSError:
        return False
    egl.eglGetDisplay.restype = ctypes.c_void_p
    egl.eglGetDisplay.argtypes = [ctypes.c_void_p]
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
    # mujoco's egl backend needs a device display (EGL_EXT_platform_device).
    return bool(egl.eglGetProcAddress(b"eglQueryDevicesEXT"))


def _mujoco():
    imported_before = "mujoco" in sys.modules
    _choose_gl()
    try:
        import mujoco
    except ImportError as e:
        raise ImportError(f"Scene.preview() needs the mujoco package (pip install mujoco): {e}")
    if (
        imported_before
        and not os.environ.get("MUJOCO_GL")
        and sys.platform.startswith("linux")
        and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    ):
        # mujoco chose GLFW when it was imported, which needs a display: without one it
        # ends the process. Say what to do instead.
        raise RuntimeError(
            "Scene.preview(): mujoco was imported before MUJOCO_GL was set and there is no "
            "display: set MUJOCO_GL=egl (or osmesa) before importing mujoco, for example "
            "`MUJOCO_GL=egl python script.py`, or import mjcf_forge's preview first"
        )
    return mujoco


def free_camera(mujoco, model) -> Tuple[np.ndarray, float, float, float]:
    """The sheet's free camera for ``model``: lookat, distance, azimuth, elevation.

    From MuJoCo's default azimuth and elevation (``mjv_defaultFreeCamera``), looking at
    the centre of the bounding box of every geom of a body other than the world (world
    geoms and planes left out) at ``qpos0``, from the distance at which the sphere around
    that box fits ``<visual><global fovy>``; ``mjv_defaultFreeCamera`` as it is when every
    geom is the world's. The command line's rule, the same numbers.
    """
    cam = mujoco.MjvCamera()
    mujoco.mjv_defaultFreeCamera(model, cam)
    lookat = np.array(cam.lookat, dtype=float)
    distance = float(cam.distance)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    keep = (model.geom_bodyid != 0) & (model.geom_type != mujoco.mjtGeom.mjGEOM_PLANE)
    if keep.any():
        r = model.geom_rbound[keep][:, None]
        pos = data.geom_xpos[keep]
        lo, hi = (pos - r).min(axis=0), (pos + r).max(axis=0)
        lookat = (lo + hi) / 2
        radius = math.sqrt(float(((hi - lo) ** 2).sum()) / 4)
        s = math.sin(model.vis.global_.fovy * math.pi / 360)
        if radius > 0 and s > 0:
            distance = radius / s
    return lookat, distance, float(cam.azimuth), float(cam.elevation)


def _choose_geoms(model, geoms: str, option) -> None:
    """What each geom set keeps, as the command line does: kept geoms in group 0, the
    others in the last group, only group 0 drawn; ``default`` changes nothing."""
    option.sitegroup[:] = 0
    if geoms == "default":
        return
    ngroup = len(option.geomgroup)
    if geoms == "all":
        option.geomgroup[:] = 1
        return
    collides = (model.geom_contype != 0) | (model.geom_conaffinity != 0)
    if geoms == "collision":
        keep = collides
    else:
        has_visual = np.zeros(model.nbody, dtype=bool)
        has_visual[model.geom_bodyid[~collides]] = True
        keep = ~collides | ~has_visual[model.geom_bodyid]
    model.geom_group[:] = np.where(keep, 0, ngroup - 1)
    option.geomgroup[:] = 0
    option.geomgroup[0] = 1


def _label(cell: np.ndarray, text: str, scale: int) -> None:
    """``text`` (digits) in white on a dark box in the top left corner of ``cell``."""
    pad = scale
    w = len(text) * 4 * scale - scale + 2 * pad
    h = 5 * scale + 2 * pad
    cell[:h, :w] = (cell[:h, :w] * 0.3).astype(np.uint8)
    for n, ch in enumerate(text):
        for row, bits in enumerate(_DIGITS.get(ch, _DIGITS["0"])):
            for col, bit in enumerate(bits):
                if bit == "#":
                    y = pad + row * scale
                    x = pad + (n * 4 + col) * scale
                    cell[y : y + scale, x : x + scale] = 255


def png_bytes(image: np.ndarray) -> bytes:
    """An RGB ``uint8`` array (height, width, 3) as a PNG file's bytes."""
    image = np.ascontiguousarray(image, dtype=np.uint8)
    height, width, _ = image.shape
    raw = np.zeros((height, width * 3 + 1), dtype=np.uint8)  # filter byte 0 per row
    raw[:, 1:] = image.reshape(height, width * 3)

    def chunk(kind: bytes, body: bytes) -> bytes:
        crc = zlib.crc32(kind + body) & 0xFFFFFFFF
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", crc)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw.tobytes(), 9))
        + chunk(b"IEND", b"")
    )


def cell_origin(k: int, columns: int, cell: Tuple[int, int]) -> Tuple[int, int]:
    """The top left corner (x, y) of cell ``k`` in a sheet of ``columns`` columns."""
    return (k % columns) * (cell[0] + GAP), (k // columns) * (cell[1] + GAP)


def default_columns(n: int) -> int:
    """The smallest number of columns whose square holds ``n`` cells."""
    return max(1, math.ceil(math.sqrt(n) - 1e-9))


def preview(
    scene,
    indices: Union[int, Iterable[int]],
    path: Union[None, str, os.PathLike] = None,
    *,
    cell: Sequence[int] = (320, 240),
    columns: Optional[int] = None,
    camera: Optional[str] = None,
    geoms: str = "default",
    labels: bool = True,
    segmentation: bool = False,
) -> np.ndarray:
    """See :meth:`Scene.preview`."""
    if isinstance(indices, int):
        indices = range(indices)
    indices = [int(i) for i in indices]
    if not indices:
        raise ValueError("a contact sheet needs at least one variant")
    width, height = (int(v) for v in cell)
    if not (1 <= width <= 4096 and 1 <= height <= 4096):
        raise ValueError(f"cell {width}x{height}: each side must be 1 to 4096 pixels")
    if geoms not in GEOMS:
        raise ValueError(f"unknown geom set {geoms!r} (default, visual, collision, all)")
    if columns is not None and columns < 1:
        raise ValueError("columns must be at least 1")
    if segmentation and path is not None:
        raise ValueError("a segmentation sheet is returned, not written: pass no path")
    mujoco = _mujoco()
    columns = min(columns or default_columns(len(indices)), len(indices))
    rows = -(-len(indices) // columns)
    sheet_w = columns * (width + GAP) - GAP
    sheet_h = rows * (height + GAP) - GAP
    if segmentation:
        sheet = np.full((sheet_h, sheet_w), -1, dtype=np.int32)
    else:
        sheet = np.empty((sheet_h, sheet_w, 3), dtype=np.uint8)
        sheet[:] = GAP_COLOR
    scale = max(1, min(width, height) // 60)
    free = None
    for k, index in enumerate(indices):
        model = scene.variant(index).compile()
        if free is None:
            free = free_camera(mujoco, model)
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, height)
        if segmentation:
            model.vis.quality.offsamples = 0
        option = mujoco.MjvOption()
        _choose_geoms(model, geoms, option)
        if camera is None:
            cam = mujoco.MjvCamera()
            cam.type = mujoco.mjtCamera.mjCAMERA_FREE
            cam.lookat[:] = free[0]
            cam.distance, cam.azimuth, cam.elevation = free[1:]
        else:
            cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
            if cam < 0:
                names = [model.camera(i).name for i in range(model.ncam)]
                known = ", ".join(n for n in names if n) or "none"
                raise ValueError(
                    f"{scene.file}: variant {index}: the model has no camera named "
                    f"{camera!r} (its cameras: {known})"
                )
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        with mujoco.Renderer(model, height, width) as renderer:
            if segmentation:
                renderer.enable_segmentation_rendering()
            renderer.update_scene(data, camera=cam, scene_option=option)
            pixels = renderer.render()
        x, y = cell_origin(k, columns, (width, height))
        if segmentation:
            geom = np.where(
                pixels[:, :, 1] == int(mujoco.mjtObj.mjOBJ_GEOM), pixels[:, :, 0], -1
            )
            sheet[y : y + height, x : x + width] = geom
        else:
            out = sheet[y : y + height, x : x + width]
            out[:] = pixels
            if labels:
                _label(out, str(index), scale)
    if path is not None:
        write_atomic(path, png_bytes(sheet))
    return sheet
