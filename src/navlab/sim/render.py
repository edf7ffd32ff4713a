"""Offscreen pictures of the simulated world (MuJoCo's Renderer; ``MUJOCO_GL=egl`` when headless).

The camera looks at the robot (or the world's centre) from above at an angle, like Gazebo's
screenshots in the paper's Figs. 4 and 5. Only visual geoms (group 2) are drawn.
"""

from __future__ import annotations

import io
import os
from pathlib import Path
from typing import Protocol

import numpy as np

from navlab.sim.builder import GROUP_VISUAL
from navlab.sim.errors import SimError
from navlab.sim.simulation import Simulation


class _GLContext(Protocol):
    """What navlab uses of ``mujoco.egl.GLContext`` / ``mujoco.osmesa.GLContext``."""

    def make_current(self) -> None: ...

    def free(self) -> None: ...


def _world_extent(sim: Simulation) -> tuple[np.ndarray, float]:
    """Centre (x, y, 0) and radius (m) of the static world geometry (walls), for framing."""
    import mujoco

    m, d = sim.model, sim.data
    plane = mujoco.mjtGeom.mjGEOM_PLANE
    geoms = [
        g
        for g in range(m.ngeom)
        if m.geom_group[g] == GROUP_VISUAL and m.geom_type[g] != plane and m.geom_bodyid[g] == 0
    ]
    if not geoms:
        return np.zeros(3), 3.0
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for g in geoms:  # world-axis bounding box of each geom's local box
        rot = d.geom_xmat[g].reshape(3, 3)
        centre = d.geom_xpos[g] + rot @ m.geom_aabb[g, :3]
        half = np.abs(rot) @ m.geom_aabb[g, 3:]
        lo = np.minimum(lo, (centre - half)[:2])
        hi = np.maximum(hi, (centre + half)[:2])
    centre = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, 0.0])
    return centre, float(max(hi - lo) / 2)


def render_image(
    sim: Simulation,
    *,
    width: int = 960,
    height: int = 720,
    azimuth: float = 135.0,
    elevation: float = -40.0,
    distance: float | None = None,
    lookat: tuple[float, float, float] | None = None,
) -> np.ndarray:
    """An RGB image (height × width × 3, uint8) of the world; camera angles in degrees (MuJoCo's
    free camera), ``lookat`` (m, world) defaults to the middle of the world and ``distance`` frames it."""
    import mujoco

    centre, radius = _world_extent(sim)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = centre if lookat is None else lookat
    cam.distance = distance if distance is not None else 2.6 * radius
    cam.azimuth, cam.elevation = azimuth, elevation
    option = mujoco.MjvOption()
    option.geomgroup[:] = 0
    option.geomgroup[GROUP_VISUAL] = 1
    option.sitegroup[:] = 0
    model, data = sim.model, sim.data
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
    model.vis.global_.offheight = max(model.vis.global_.offheight, height)
    ctx = gl_context(width, height)
    try:
        ctx.make_current()
        mjr = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
        try:
            mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, mjr)
            scene = mujoco.MjvScene(model, maxgeom=max(1000, 2 * model.ngeom))
            mujoco.mj_forward(model, data)
            mujoco.mjv_updateScene(model, data, option, None, cam, mujoco.mjtCatBit.mjCAT_ALL, scene)
            viewport = mujoco.MjrRect(0, 0, width, height)
            mujoco.mjr_render(viewport, scene, mjr)
            rgb = np.empty((height, width, 3), dtype=np.uint8)
            mujoco.mjr_readPixels(rgb, None, viewport, mjr)
        finally:
            mjr.free()
    finally:
        ctx.free()
    return np.flipud(rgb).copy()


def gl_context(width: int, height: int) -> _GLContext:
    """An offscreen OpenGL context: MUJOCO_GL's choice if it is egl/osmesa, else EGL, then OSMesa."""
    wanted = os.environ.get("MUJOCO_GL", "").lower()
    order = [wanted] if wanted in ("egl", "osmesa") else ["egl", "osmesa"]
    errors = []
    for backend in order:
        try:
            if backend == "egl":
                from mujoco.egl import GLContext
            else:
                from mujoco.osmesa import GLContext
            return GLContext(width, height)
        except Exception as exc:  # a missing library or device: try the next backend
            errors.append(f"{backend}: {exc}")
    raise SimError("cannot render offscreen (" + "; ".join(errors) + "); install EGL or OSMesa")


def save_png(image: np.ndarray, out: str | os.PathLike[str]) -> Path:
    """Write an RGB image as PNG atomically; returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from navlab.io import write_bytes_atomic

    buf = io.BytesIO()
    plt.imsave(buf, image, format="png")
    path = Path(out)
    write_bytes_atomic(path, buf.getvalue())
    return path
