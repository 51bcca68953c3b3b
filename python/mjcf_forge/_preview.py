"""Contact sheets of a scene's variants: :meth:`Scene.preview`.

Each variant is compiled with the user's ``mujoco`` (``Variant.compile()``) and drawn by
``mujoco.Renderer`` at its initial pose into one cell of a grid, labelled with its index;
the grid is returned as a numpy array and written as PNG. Only the drawing is here, over
the user's ``mujoco``: every rule is the extension's, the command line's own
(``mjcf-forge preview``, docs/cli.md; ``mjcf_forge::sheet``): the grid (``SheetLayout``),
the placing, the labels and the PNG (``ContactSheet``), the free camera
(``sheet_free_camera``, over the values read here) and the geom sets
(``sheet_geom_groups``).

The OpenGL platform is ``mujoco``'s, chosen by ``MUJOCO_GL`` when ``mujoco`` is imported:
when ``MUJOCO_GL`` is unset and ``mujoco`` not imported yet, this module sets it to
``egl``, or to ``osmesa`` when no EGL context can be made.
"""

from __future__ import annotations

import os
import sys
from typing import Iterable, Optional, Sequence, Tuple, Union

import numpy as np

from . import _mjcf_forge as _native
from ._files import write_atomic

GAP = _native.SHEET_GAP
"""Pixels between cells."""
GAP_COLOR = _native.SHEET_GAP_COLOR
"""The colour between cells (and of unused cells)."""

GEOMS = _native.SHEET_GEOMS


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

    The command line's rule (``mjcf_forge::sheet::FreeCamera::framing``: the bodies other
    than the world framed at ``qpos0``), over what the user's ``mujoco`` gives:
    ``mjv_defaultFreeCamera``, the geoms after ``mj_kinematics``, ``vis.global_.fovy``.
    """
    cam = mujoco.MjvCamera()
    mujoco.mjv_defaultFreeCamera(model, cam)
    default = [*cam.lookat, cam.distance, cam.azimuth, cam.elevation]
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    x, y, z, distance, azimuth, elevation = _native.sheet_free_camera(
        [float(v) for v in default],
        model.geom_bodyid.tolist(),
        (model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE).tolist(),
        data.geom_xpos.ravel().tolist(),
        model.geom_rbound.tolist(),
        float(model.vis.global_.fovy),
    )
    return np.array([x, y, z]), distance, azimuth, elevation


def _choose_geoms(model, geoms: str, option) -> None:
    """Sets the geom set's groups (``mjcf_forge::sheet::Geoms::choose``) on ``model`` and
    ``option``; sites are not drawn."""
    option.sitegroup[:] = 0
    collides = (model.geom_contype != 0) | (model.geom_conaffinity != 0)
    groups, on = _native.sheet_geom_groups(
        geoms, collides.tolist(), model.geom_bodyid.tolist(), model.nbody, len(option.geomgroup)
    )
    if groups is not None:
        model.geom_group[:] = groups
    if on is not None:
        option.geomgroup[:] = on


def png_bytes(image: np.ndarray) -> bytes:
    """An RGB ``uint8`` array (height, width, 3) as a PNG file's bytes (the extension's
    encoder, the command line's)."""
    image = np.ascontiguousarray(image, dtype=np.uint8)
    height, width, _ = image.shape
    sheet = _native.ContactSheet(_native.SheetLayout(1, width, height))
    sheet.place(0, image.tobytes())
    return sheet.png()


def cell_origin(k: int, columns: int, cell: Tuple[int, int]) -> Tuple[int, int]:
    """The top left corner (x, y) of cell ``k`` in a sheet of ``columns`` columns."""
    return _native.SheetLayout(max(k + 1, columns), cell[0], cell[1], columns).origin(k)


def default_columns(n: int) -> int:
    """The smallest number of columns whose square holds ``n`` cells."""
    return _native.SheetLayout(max(1, n), 1, 1).columns


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
    layout = _native.SheetLayout(len(indices), width, height, columns)
    if segmentation:
        ids = np.full((layout.height, layout.width), -1, dtype=np.int32)
    else:
        sheet = _native.ContactSheet(layout)
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
        if segmentation:
            x, y = layout.origin(k)
            geom = np.where(
                pixels[:, :, 1] == int(mujoco.mjtObj.mjOBJ_GEOM), pixels[:, :, 0], -1
            )
            ids[y : y + height, x : x + width] = geom
        else:
            rgb = np.ascontiguousarray(pixels, dtype=np.uint8).tobytes()
            sheet.place(k, rgb, str(index) if labels else None)
    if segmentation:
        return ids
    if path is not None:
        write_atomic(path, sheet.png())
    rgb = np.frombuffer(sheet.rgb(), dtype=np.uint8)
    return rgb.reshape(layout.height, layout.width, 3).copy()
