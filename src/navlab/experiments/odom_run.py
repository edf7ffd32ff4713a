"""Odometry drift: how far a robot's ``odom`` strays from the truth per metre driven and per radian turned.

The robot follows a scripted route steering on ground truth (``RouteFollower`` on ``/ground_truth/odom``), so
every robot drives the same line whatever its odometry says; ``odom`` is what the robot's own files make it:
the wheel odometry on ``/odom``, or with the EKF robot_localization's ``/odometry/filtered``. Routes: the
paper's room loop (``localize_run.DEFAULT_ROUTE`` in ``room``) and a generated clutter course (the
reference path through a BARN-style world, planned for a 0.2 m disc, so larger robots brush the clutter).

Figures per run: ``distance_m`` and ``turned_rad`` (true path length and summed |yaw change|), the odometry's
``final_error_m`` and ``max_error_m`` (position, in the odom frame = the start pose), ``final_yaw_error_rad``,
``error_per_m`` (final error / distance) and ``yaw_error_per_rad`` (final yaw error / turned; None below 0.1 rad).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node
from navlab.experiments.session import rounded, start_run
from navlab.geometry import wrap_angle

ROBOTS = ("mybot", "jackal", "jackal_skid")
ROUTES = ("room", "clutter")
# a winding BARN course (reference path for a 0.3 m disc 1.07 x the 10 m, 20 % of the field filled; BARN's densest
# fill 0.30), so a Jackal-sized robot (half-width 0.215 m) following it brushes past the clutter without getting stuck
CLUTTER = {"seed": 6, "fill": 0.3, "smooth": 3, "robot_radius": 0.3}
SPEED = 0.5  # m/s: the benchmark's max_vel_x


class DriftMonitor(Node):
    """Samples the true pose (``/ground_truth/odom``) and the odometry (``topic``) every ``1/rate`` s."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "drift_monitor",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        topic = self.declare_parameter("topic", "/odom")
        rate = self.declare_parameter("rate", 10.0)
        self.truth: tuple[float, float, float] | None = None
        self.odom: tuple[float, float, float] | None = None
        self.samples: list[tuple[float, ...]] = []
        self.create_subscription(msgs.Odometry, "/ground_truth/odom", self._on_truth, 10)
        self.create_subscription(msgs.Odometry, topic, self._on_odom, 10)
        self.create_timer(1.0 / rate, self._sample)

    def _on_truth(self, msg: Any) -> None:
        self.truth = msgs.pose2d(msg.pose.pose)

    def _on_odom(self, msg: Any) -> None:
        self.odom = msgs.pose2d(msg.pose.pose)

    def _sample(self) -> None:
        if self.truth is not None and self.odom is not None:
            self.samples.append((*self.truth, *self.odom))


def drift_figures(truth: np.ndarray, odom: np.ndarray) -> dict[str, float | None]:
    """Figures of one run from the true poses (N, 3; world frame) and odometry poses (N, 3; odom frame, which
    starts at the first true pose)."""
    x0, y0, yaw0 = truth[0]
    c, s = math.cos(yaw0), math.sin(yaw0)
    dx, dy = truth[:, 0] - x0, truth[:, 1] - y0
    rel = np.column_stack([c * dx + s * dy, -s * dx + c * dy, wrap_angle(truth[:, 2] - yaw0)])
    err = np.hypot(*(odom[:, :2] - rel[:, :2]).T)
    distance = float(np.hypot(*np.diff(truth[:, :2], axis=0).T).sum())
    turned = float(np.abs(wrap_angle(np.diff(truth[:, 2]))).sum())
    yaw_err = abs(float(wrap_angle(odom[-1, 2] - rel[-1, 2])))
    return {
        "distance_m": distance,
        "turned_rad": turned,
        "final_error_m": float(err[-1]),
        "max_error_m": float(err.max()),
        "final_yaw_error_rad": yaw_err,
        "error_per_m": float(err[-1]) / max(distance, 1e-9),
        "yaw_error_per_rad": yaw_err / turned if turned > 0.1 else None,
    }


def route_of(name: str) -> tuple[str, tuple[float, float, float], list[list[float]], Any]:
    """(world, start pose, waypoints, a ClutterWorld or None) of a route name (``room`` or ``clutter``)."""
    if name == "room":
        from navlab.experiments.localize_run import DEFAULT_ROUTE

        return "room", (0.0, 0.0, 0.0), [list(p) for p in (*DEFAULT_ROUTE, DEFAULT_ROUTE[0])], None
    if name == "clutter":
        from navlab.world import generate_clutter

        world = generate_clutter(
            int(CLUTTER["seed"]),
            fill=CLUTTER["fill"],
            smooth=int(CLUTTER["smooth"]),
            robot_radius=CLUTTER["robot_radius"],
        )
        path = world.reference_path[1:]
        return "", world.start, [list(map(float, p)) for p in path], world
    raise ValueError(f"unknown route {name!r} (routes: {', '.join(ROUTES)})")


def run_drift(robot: str, route: str, *, ekf: bool, seed: int = 0, timeout: float | None = None) -> dict[str, Any]:
    """Drive ``robot`` along ``route`` with or without the EKF; its drift figures (see the module)."""
    import tempfile
    from pathlib import Path

    world, pose, waypoints, clutter = route_of(route)
    with tempfile.TemporaryDirectory(prefix="navlab-odom-") as tmp:
        if clutter is not None:
            world = str(clutter.write_world(Path(tmp) / f"{clutter.name}.world"))
        run = start_run("sim", world=world, robot=robot, pose=pose, seed=seed, ekf="true" if ekf else "false")
        follower = run.add(
            _route_follower(),
            parameters={
                "waypoints": waypoints,
                "pose_topic": "/ground_truth/odom",
                "max_vel_x": SPEED,
                "waypoint_tolerance": 0.15,
            },
        )
        monitor = run.add(DriftMonitor, parameters={"topic": "/odometry/filtered" if ekf else "/odom"})
        length = float(sum(math.dist(a, b) for a, b in zip([pose[:2], *waypoints[:-1]], waypoints, strict=True)))
        limit = timeout if timeout is not None else 3.0 * length / SPEED + 10.0
        t = 0.0
        while not follower.done and t < limit:
            run.executor.run(1.0)
            t += 1.0
    data = np.array(monitor.samples)
    if len(data) < 2:
        raise RuntimeError(f"odom drift run {robot}/{route}: no odometry on {'/odometry/filtered' if ekf else '/odom'}")
    figures = drift_figures(data[:, :3], data[:, 3:])
    return rounded(
        {"robot": robot, "route": route, "ekf": ekf, "completed": bool(follower.done), "time_s": t, **figures}
    )


def _route_follower() -> type[Node]:
    from navlab.drivers import RouteFollower

    return RouteFollower
