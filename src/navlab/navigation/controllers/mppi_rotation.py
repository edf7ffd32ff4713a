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
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from navlab.geometry import wrap_angle
from navlab.navigation.controllers.rollout import footprint_costs

CHECK_STEP = 0.05  # rad between the footprint poses checked along a turn


@dataclass(frozen=True)
class RotationShim:
    """The shim's settings (Nav2's names and defaults; ``max_speed`` is ``rotation_shim_max_speed``)."""

    angular_dist_threshold: float = 0.785  # rad
    forward_sampling_distance: float = 0.5  # m
    rotate_to_heading_angular_vel: float = 1.8  # rad/s
    max_angular_accel: float = 3.2  # rad/s²
    simulate_ahead_time: float = 1.0  # s
    max_speed: float = 0.1  # m/s

    @classmethod
    def of(cls, params: Any) -> RotationShim | None:
        """The shim MPPI's ``params`` (``MppiParams``) ask for; None with ``use_rotation_shim`` off."""
        if not params.use_rotation_shim:
            return None
        keys = ("angular_dist_threshold", "forward_sampling_distance", "rotate_to_heading_angular_vel")
        more = ("max_angular_accel", "simulate_ahead_time", "rotation_shim_max_speed")
        return cls(*(float(getattr(params, k)) for k in (*keys, *more)))

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

    def command(
        self,
        pose: tuple[float, float, float],
        velocity: tuple[float, float],
        path: np.ndarray,
        dt: float,
        grid: np.ndarray,
        resolution: float,
        outline: np.ndarray | None,
    ) -> float | None:
        """The turn rate (rad/s) that rotates the robot in place toward ``path`` (grid-local, (P, 2+)), or None when
        the shim leaves the robot to MPPI: moving faster than ``max_speed``, already within the threshold, no path
        point far enough, or the turn blocked within ``simulate_ahead_time``. ``dt``: the control period (s)."""
        if abs(velocity[0]) > self.max_speed:
            return None
        err = self.heading_error(pose, path)
        if err is None or abs(err) <= self.angular_dist_threshold:
            return None
        sign = 1.0 if err > 0 else -1.0
        # as fast as allowed, and slow enough to stop at the heading with max_angular_accel
        w = sign * min(self.rotate_to_heading_angular_vel, math.sqrt(2.0 * self.max_angular_accel * abs(err)))
        w = min(max(w, velocity[1] - self.max_angular_accel * dt), velocity[1] + self.max_angular_accel * dt)
        sweep = min(abs(err), self.rotate_to_heading_angular_vel * self.simulate_ahead_time)
        n = max(1, math.ceil(sweep / CHECK_STEP))
        poses = np.empty((n, 3))
        poses[:, 0], poses[:, 1] = pose[0], pose[1]
        poses[:, 2] = pose[2] + sign * sweep * np.arange(1, n + 1) / n
        if bool((footprint_costs(grid, resolution, poses, outline) < 0).any()):
            return None
        return float(w)
