"""Disturbances that make wheel speed control matter, settable per run (navlab extensions, not Gazebo tags).

- ``wheel_radius_error``: [left, right] relative error of the simulated wheels' radius against the
  described one (0.02: the left wheel is 2 % larger than the odometry and the controllers believe).
- ``payload_mass``: kg added to the robot's root body after the model is built (the wheel motors'
  gains are not retuned for it).
- ``max_torque``: N m per wheel motor (0: the description's ``torque``).
- ``slip_patches``: floor regions where the wheels' friction is ``mu`` — rectangles
  ``{x, y, size_x, size_y, mu}`` (centre and full extents, m; optional ``yaw`` rad) or discs
  ``{x, y, radius, mu}``. A :class:`SlipPatchPlugin` sets each wheel's contact friction from where
  the wheel is, ``rate`` times a second.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

from navlab.core import Executor
from navlab.description import Geometry, RobotModel
from navlab.errors import did_you_mean
from navlab.sim.errors import SimError
from navlab.sim.plugins import SimPlugin
from navlab.sim.simulation import Simulation

KEYS = ("wheel_radius_error", "payload_mass", "max_torque", "slip_patches", "slip_rate")
PATCH_KEYS = ("x", "y", "size_x", "size_y", "yaw", "radius", "mu")


@dataclass(frozen=True)
class SlipPatch:
    """A low-friction floor region: a rectangle (``size_x``×``size_y`` m, turned by ``yaw``) or a disc."""

    x: float
    y: float
    mu: float
    size_x: float = 0.0
    size_y: float = 0.0
    yaw: float = 0.0
    radius: float = 0.0

    def contains(self, px: float, py: float) -> bool:
        """Whether the world point (px, py) (m) lies on the patch."""
        dx, dy = px - self.x, py - self.y
        if self.radius > 0:
            return dx * dx + dy * dy <= self.radius * self.radius
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return abs(c * dx + s * dy) <= self.size_x / 2 and abs(-s * dx + c * dy) <= self.size_y / 2


@dataclass
class Disturbances:
    """What to change in a run; see the module docstring. The defaults change nothing."""

    wheel_radius_error: tuple[float, float] = (0.0, 0.0)
    payload_mass: float = 0.0
    max_torque: float = 0.0
    slip_patches: list[SlipPatch] = field(default_factory=list)
    slip_rate: float = 100.0  # Hz: how often the wheels' friction follows their position

    @property
    def active(self) -> bool:
        """Whether anything is disturbed."""
        return bool(any(self.wheel_radius_error) or self.payload_mass or self.max_torque or self.slip_patches)


def _num(value: Any, where: str, *, low: float = -math.inf, strict: bool = False) -> float:
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or value < low or (strict and value <= low):
        rel = ">" if strict else ">="
        bound = f" {rel} {low:g}" if math.isfinite(low) else ""
        raise SimError(f"{where}: expected a finite number{bound}, got {value!r}")
    return float(value)


def parse_disturbances(params: dict[str, Any], *, where: str = "disturbances") -> Disturbances:
    """A validated :class:`Disturbances` from parameters (unknown keys: "did you mean")."""
    for key in params:
        if key not in KEYS:
            hint = did_you_mean(key, KEYS)
            raise SimError(f"{where}: unknown key '{key}'{hint} (keys: {', '.join(KEYS)})")
    out = Disturbances()
    if "wheel_radius_error" in params:
        err = params["wheel_radius_error"]
        if isinstance(err, int | float) and not isinstance(err, bool):
            err = [err, err]
        if not isinstance(err, list | tuple) or len(err) != 2:
            raise SimError(f"{where}.wheel_radius_error: expected [left, right] relative errors, got {err!r}")
        left, right = (_num(e, f"{where}.wheel_radius_error", low=-0.5, strict=True) for e in err)
        out.wheel_radius_error = (left, right)
    if "payload_mass" in params:
        out.payload_mass = _num(params["payload_mass"], f"{where}.payload_mass", low=0.0)
    if "max_torque" in params:
        out.max_torque = _num(params["max_torque"], f"{where}.max_torque", low=0.0)
    if "slip_rate" in params:
        out.slip_rate = _num(params["slip_rate"], f"{where}.slip_rate", low=0.0, strict=True)
    patches = params.get("slip_patches") or []
    if not isinstance(patches, list):
        raise SimError(
            f"{where}.slip_patches: expected a list of {{x, y, size_x, size_y, mu}} or "
            f"{{x, y, radius, mu}}, got {patches!r}"
        )
    for k, raw in enumerate(patches):
        w = f"{where}.slip_patches[{k}]"
        if not isinstance(raw, dict):
            raise SimError(f"{w}: expected a mapping, got {raw!r}")
        for key in raw:
            if key not in PATCH_KEYS:
                hint = did_you_mean(key, PATCH_KEYS)
                raise SimError(f"{w}: unknown key '{key}'{hint} (keys: {', '.join(PATCH_KEYS)})")
        for key in ("x", "y", "mu"):
            if key not in raw:
                raise SimError(f"{w}: missing '{key}'")
        vals = {k2: _num(v, f"{w}.{k2}") for k2, v in raw.items()}
        _num(vals["mu"], f"{w}.mu", low=0.0)
        disc = "radius" in vals
        if disc == ("size_x" in vals or "size_y" in vals):
            raise SimError(f"{w}: give either radius (a disc) or size_x and size_y (a rectangle)")
        for key in ("radius",) if disc else ("size_x", "size_y"):
            _num(vals.get(key), f"{w}.{key}", low=0.0, strict=True)
        out.slip_patches.append(SlipPatch(**vals))
    return out


def wheel_links(robot: RobotModel) -> tuple[str, str]:
    """(left, right) wheel links: the children of the diff-drive joints."""
    dd = robot.diff_drive
    if dd is None:
        raise SimError(f"robot {robot.name!r} has no diff_drive: wheel disturbances need its wheels")
    child = {j.name: j.child for j in robot.joints}
    return child[dd.left_joint], child[dd.right_joint]


def disturbed_robot(robot: RobotModel, d: Disturbances) -> RobotModel:
    """A copy of ``robot`` with the wheel radius errors and motor torque applied (payload: ``add_payload``)."""
    if not (any(d.wheel_radius_error) or d.max_torque):
        return robot
    out = copy.deepcopy(robot)
    if d.max_torque and out.diff_drive is not None:
        out.diff_drive.max_torque = d.max_torque
    for link_name, err in zip(wheel_links(out), d.wheel_radius_error, strict=True):
        if not err:
            continue
        link = out.links[link_name]
        shapes = []
        for shape in link.collisions:
            g = shape.geometry
            if g.kind in ("cylinder", "sphere"):
                size = (g.size[0] * (1.0 + err), *g.size[1:])
                shape = dataclasses.replace(shape, geometry=Geometry(g.kind, size))
            shapes.append(shape)
        link.collisions = shapes
    return out


def add_payload(sim: Simulation, mass: float) -> None:
    """Add ``mass`` kg at the robot root body's centre of mass (inertia scaled with the mass)."""
    if mass <= 0 or sim.robot is None:
        return
    name = sim.info.root_body
    body = sim.spec.body(name)
    b = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, name)
    scale = (float(sim.model.body_mass[b]) + mass) / float(sim.model.body_mass[b])
    body.mass = float(body.mass) * scale if body.mass else float(sim.model.body_mass[b]) + mass
    body.fullinertia = np.asarray(body.fullinertia, dtype=float) * scale
    sim.model.body_mass[b] *= scale
    sim.model.body_inertia[b] *= scale
    d = sim.data
    qpos, qvel = d.qpos.copy(), d.qvel.copy()
    mujoco.mj_setConst(sim.model, d)  # derived masses; it overwrites the state with qpos0: put it back
    d.qpos[:], d.qvel[:] = qpos, qvel
    mujoco.mj_forward(sim.model, d)


class SlipPatchPlugin(SimPlugin):
    """Sets the wheels' floor friction from the slip patches under them, ``rate`` times a second.

    ``wheel_friction`` holds the current (left, right) sliding friction, for tests and monitors.
    """

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "slip_patches",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
        sim: Simulation,
        patches: list[SlipPatch],
        rate: float = 100.0,
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace, sim=sim)
        self.patches = list(patches)
        self.links = wheel_links(self.robot)
        self._model: Any = None
        self._geoms: list[np.ndarray] = []
        self._base_mu: list[np.ndarray] = []
        self.wheel_friction = (math.nan, math.nan)
        self.create_timer(1.0 / rate, self.update, priority=-1)
        self.update()

    def _resolve(self) -> None:
        """Geom ids of each wheel's floor contacts (its robot spheres), again after a recompile."""
        m = self.sim.model
        self._model = m
        self._geoms, self._base_mu = [], []
        for link in self.links:
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, self.sim.info.link_bodies[link])
            g = np.flatnonzero(
                (m.geom_bodyid == b) & (m.geom_type == mujoco.mjtGeom.mjGEOM_SPHERE) & (m.geom_contype != 0)
            )
            if g.size == 0:
                raise SimError(f"slip patches: wheel link {link!r} has no floor contact geom")
            self._geoms.append(g)
            self._base_mu.append(m.geom_friction[g, 0].copy())

    def update(self) -> None:
        """Friction of each wheel: the patch's ``mu`` when its centre is over a patch, else its own."""
        if self._model is not self.sim.model:
            self._resolve()
        mus = []
        for link, geoms, base in zip(self.links, self._geoms, self._base_mu, strict=True):
            x, y, _ = self.sim.base_pose2d(link)
            patch = next((p for p in self.patches if p.contains(x, y)), None)
            mu = base if patch is None else np.full(len(geoms), patch.mu)
            self.sim.model.geom_friction[geoms, 0] = mu
            mus.append(float(np.min(mu)))
        self.wheel_friction = (mus[0], mus[1])
