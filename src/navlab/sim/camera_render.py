"""A robot camera's colour image from MuJoCo's offscreen renderer (headless EGL or OSMesa, as ``navlab render``).

The camera sits at its link's true pose composed with the sensor's ``<pose>`` and looks along the sensor's +x
(Gazebo's camera convention), with the vertical field of view that the ``<horizontal_fov>`` and the image's
aspect give. Only visual geoms (group 2) are drawn; shadows, reflections, fog and skybox are off (the cost of
a frame on a software renderer); edges are multisampled with ``<image><anti_aliasing>`` samples per pixel
(SDF's default 4; 0 or 1: off). The GL context is made once and kept; a recompiled model (spawn/delete)
rebuilds the render context.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from navlab.description import CameraConfig
from navlab.sim.builder import GROUP_VISUAL
from navlab.sim.render import gl_context
from navlab.sim.sensors3d import sensor_pose
from navlab.sim.simulation import Simulation

_OFF = ("mjRND_SHADOW", "mjRND_REFLECTION", "mjRND_SKYBOX", "mjRND_FOG", "mjRND_HAZE")


class CameraRenderer:
    """Renders ``cfg``'s image (height x width x 3 uint8, RGB, row 0 at the top) from ``sim``; call :meth:`close`."""

    def __init__(self, sim: Simulation, cfg: CameraConfig) -> None:
        self.sim, self.cfg = sim, cfg
        cam = cfg.camera
        self.ctx = gl_context(cam.width, cam.height)
        self.model: mujoco.MjModel | None = None
        self.mjr: mujoco.MjrContext | None = None
        self.option = mujoco.MjvOption()
        self.option.geomgroup[:] = 0
        self.option.geomgroup[GROUP_VISUAL] = 1
        self.option.sitegroup[:] = 0
        self.free = mujoco.MjvCamera()
        self.free.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.viewport = mujoco.MjrRect(0, 0, cam.width, cam.height)
        self.rgb = np.empty((cam.height, cam.width, 3), dtype=np.uint8)
        self.fovy = math.degrees(2 * math.atan(math.tan(cam.horizontal_fov / 2) * cam.height / cam.width))

    def _context(self) -> None:
        m = self.sim.model
        if self.model is m:
            return
        if self.mjr is not None:
            self.mjr.free()
        cam = self.cfg.camera
        m.vis.global_.offwidth = max(m.vis.global_.offwidth, cam.width)
        m.vis.global_.offheight = max(m.vis.global_.offheight, cam.height)
        samples = m.vis.quality.offsamples
        m.vis.quality.offsamples = cam.anti_aliasing  # the context's multisampling; the model's own is kept
        try:
            self.mjr = mujoco.MjrContext(m, mujoco.mjtFontScale.mjFONTSCALE_100)
        finally:
            m.vis.quality.offsamples = samples
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self.mjr)
        self.scene = mujoco.MjvScene(m, maxgeom=max(1000, 2 * m.ngeom))
        for flag in _OFF:
            self.scene.flags[getattr(mujoco.mjtRndFlag, flag)] = 0
        self.model = m

    def render(self) -> np.ndarray:
        """The current image (a new array)."""
        self.ctx.make_current()
        self._context()
        m, d = self.sim.model, self.sim.data
        pos, rot = sensor_pose(self.sim, self.cfg.link, self.cfg.origin)
        vis = m.vis
        fovy, znear, zfar = vis.global_.fovy, vis.map.znear, vis.map.zfar
        extent = m.stat.extent
        vis.global_.fovy = self.fovy  # the scene's frustum comes from the model: set it for this camera only
        vis.map.znear, vis.map.zfar = self.cfg.camera.near / extent, self.cfg.camera.far / extent
        try:
            mujoco.mjv_updateScene(m, d, self.option, None, self.free, mujoco.mjtCatBit.mjCAT_ALL, self.scene)
        finally:
            vis.global_.fovy, vis.map.znear, vis.map.zfar = fovy, znear, zfar
        for glcam in self.scene.camera:  # the sensor's exact pose (with roll), both eyes
            glcam.pos[:] = pos
            glcam.forward[:] = rot[:, 0]
            glcam.up[:] = rot[:, 2]
        assert self.mjr is not None
        mujoco.mjr_render(self.viewport, self.scene, self.mjr)
        mujoco.mjr_readPixels(self.rgb, None, self.viewport, self.mjr)
        return np.flipud(self.rgb).copy()

    def close(self) -> None:
        """Free the render and GL contexts."""
        if self.mjr is not None:
            self.ctx.make_current()
            self.mjr.free()
            self.mjr = None
        self.ctx.free()
