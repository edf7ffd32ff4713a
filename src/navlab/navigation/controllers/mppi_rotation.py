"""Nav2's rotation shim (``nav2_rotation_shim_controller``) in front of MPPI, for a robot standing still.

MPPI averages its samples: a robot that stands facing away from its path, with turns to the left and to the right
about equally good, gets the mean of the two, which is to stand still; in a gap where the footprint can turn only in
place, MPPI's rollouts that drive while turning all collide, and it stays there until the recoveries give up. Nav2's
RotationShimController turns the robot in place toward the path first and hands over to the primary controller once
the heading is within ``angular_dist_threshold``. Here it runs inside MPPI (``use_rotation_shim``, off by default)
and only when the robot moves slower than ``rotation_shim_max_speed`` m/s (Nav2's shim engages on every new path;
navlab's move_base sends the plan every cycle, and turning in place at speed would stop the robot mid-field).

Its parameters keep Nav2's names and defaults: the path point ``forward_sampling_distance`` m ahead sets the heading;
the turn is ``rotate_to_heading_angular_vel`` rad/s reached within ``max_angular_accel`` rad/s², slowed to stop at
the heading; the turn is checked ``simulate_ahead_time`` s ahead with the footprint on the local costmap (a turn
that would put an edge on a LETHAL or unknown cell is not taken: MPPI keeps the robot). Frames: grid-local (see
``common``); units m, rad, s.

navlab adds what a driver does when that turn is blocked (``rotation_shim_backup_dist`` > 0; 0, the default, is
Nav2's shim): a box robot standing in a gap, its corners too near the posts to turn, backs out straight, along its
own heading (the way it came in), at up to ``rotation_shim_backup_speed`` m/s within ``ax_max`` m/s², to the
nearest point at most ``rotation_shim_backup_dist`` m back from which the turn is free, slowing to stop there; then
it turns. Every footprint pose on the way back is checked; if the way back is blocked, or no point within the
distance frees the turn, MPPI keeps the robot as before (MPPI's samples in such a gap average to creeping).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from navlab.geometry import wrap_angle
from navlab.navigation.controllers.rollout import footprint_costs

CHECK_STEP = 0.05  # rad between the footprint poses checked along a turn
BACKUP_STEP = 0.05  # m between the footprint poses checked backing out


@dataclass(frozen=True)
class RotationShim:
    """The shim's settings (Nav2's names and defaults; ``max_speed`` is ``rotation_shim_max_speed``)."""

    angular_dist_threshold: float = 0.785  # rad
    forward_sampling_distance: float = 0.5  # m
    rotate_to_heading_angular_vel: float = 1.8  # rad/s
    max_angular_accel: float = 3.2  # rad/s²
    simulate_ahead_time: float = 1.0  # s
    max_speed: float = 0.1  # m/s
    backup_dist: float = 0.0  # m: ``rotation_shim_backup_dist``, how far back it may back out to turn (0: never)
    backup_speed: float = 0.25  # m/s: ``rotation_shim_backup_speed``
    backup_accel: float = 3.0  # m/s²: MPPI's ``ax_max``

    @classmethod
    def of(cls, params: Any) -> RotationShim | None:
        """The shim MPPI's ``params`` (``MppiParams``) ask for; None with ``use_rotation_shim`` off."""
        if not params.use_rotation_shim:
            return None
        keys = ("angular_dist_threshold", "forward_sampling_distance", "rotate_to_heading_angular_vel")
        more = ("max_angular_accel", "simulate_ahead_time", "rotation_shim_max_speed")
        back = ("rotation_shim_backup_dist", "rotation_shim_backup_speed", "ax_max")
        shim = cls(*(float(getattr(params, k)) for k in (*keys, *more, *back)))
        reverse = max(0.0, -float(params.vx_min))  # never back faster than MPPI may (vx_min 0: never back)
        return (
            shim
            if shim.backup_speed <= reverse
            else replace(shim, backup_speed=reverse, backup_dist=shim.backup_dist * (reverse > 0))
        )

    def heading_error(self, pose: tuple[float, float, float], path: np.ndarray) -> float | None:
        """The angle (rad, (-pi, pi]) from the robot's heading to the first path point ``forward_sampling_distance``
        m or more from it; None when no point is that far (the goal is near: MPPI's goal critics turn the robot)."""
        if len(path) == 0:
            return None
        d = np.hypot(path[:, 0] - pose[0], path[:, 1] - pose[1])
        far = np.nonzero(d >= self.forward_sampling_distance)[0]
        if not len(far):
            return None
        x, y = path[far[0], :2]
        return float(wrap_angle(math.atan2(y - pose[1], x - pose[0]) - pose[2]))

    def _turn(self, pose: tuple[float, float, float], err: float) -> np.ndarray:
        """The footprint poses (N, 3) of the in-place turn toward ``err`` (rad) within ``simulate_ahead_time``."""
        sweep = min(abs(err), self.rotate_to_heading_angular_vel * self.simulate_ahead_time)
        n = max(1, math.ceil(sweep / CHECK_STEP))
        poses = np.empty((n, 3))
        poses[:, 0], poses[:, 1] = pose[0], pose[1]
        poses[:, 2] = pose[2] + math.copysign(sweep, err) * np.arange(1, n + 1) / n
        return poses

    def _backup_needed(
        self,
        pose: tuple[float, float, float],
        path: np.ndarray,
        grid: np.ndarray,
        resolution: float,
        outline: np.ndarray | None,
    ) -> float | None:
        """How far (m, a multiple of ``BACKUP_STEP``) the robot must back straight out for its turn toward ``path``
        to be free (or no longer needed); None when the way back is blocked first or it is over ``backup_dist``."""
        n = int(self.backup_dist / BACKUP_STEP + 1e-9)
        if n < 1:
            return None
        d = BACKUP_STEP * np.arange(1, n + 1)
        back = np.column_stack([pose[0] - d * math.cos(pose[2]), pose[1] - d * math.sin(pose[2]), np.full(n, pose[2])])
        free = footprint_costs(grid, resolution, back, outline) >= 0
        for k in range(n):
            if not free[k]:
                return None
            at = (float(back[k, 0]), float(back[k, 1]), pose[2])
            err = self.heading_error(at, path)
            if err is None or abs(err) <= self.angular_dist_threshold:
                return float(d[k])
            if bool((footprint_costs(grid, resolution, self._turn(at, err), outline) >= 0).all()):
                return float(d[k])
        return None

    def command(
        self,
        pose: tuple[float, float, float],
        velocity: tuple[float, float],
        path: np.ndarray,
        dt: float,
        grid: np.ndarray,
        resolution: float,
        outline: np.ndarray | None,
        *,
        backing: bool = False,
    ) -> tuple[float, float] | None:
        """The command (m/s, rad/s) that turns the robot in place toward ``path`` (grid-local, (P, 2+)), or backs
        it straight out first where the turn is blocked (``backup_dist``), or None when the shim leaves the robot
        to MPPI: moving faster than ``max_speed`` (unless ``backing``: the shim's own back-out), already within the
        threshold, no path point far enough, or the turn blocked within ``simulate_ahead_time`` and no way back
        out. ``dt``: the control period (s)."""
        v0, w0 = velocity
        if abs(v0) > self.max_speed and not backing:
            return None
        err = self.heading_error(pose, path)
        if err is None or abs(err) <= self.angular_dist_threshold:
            return None
        dv = self.backup_accel * dt
        if bool((footprint_costs(grid, resolution, self._turn(pose, err), outline) >= 0).all()):
            if abs(v0) > self.max_speed:  # backed out far enough: stop, then turn
                return min(v0 + dv, 0.0), 0.0
            # as fast as allowed, and slow enough to stop at the heading with max_angular_accel
            w = math.copysign(
                min(self.rotate_to_heading_angular_vel, math.sqrt(2.0 * self.max_angular_accel * abs(err))), err
            )
            return 0.0, min(max(w, w0 - self.max_angular_accel * dt), w0 + self.max_angular_accel * dt)
        back = self._backup_needed(pose, path, grid, resolution, outline)
        if back is None:
            return None
        # back out, slow enough to stop where the turn is free
        v = -min(self.backup_speed, math.sqrt(2.0 * self.backup_accel * back))
        return min(max(v, v0 - dv), v0 + dv), 0.0
