"""Nav2's collision monitor and velocity smoother: the polygons' actions on hand-placed laser points, the
smoother's limits, and the monitor node stopping a robot driven at a wall in the simulator."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.navigation.collision_monitor import CollisionMonitor, Polygon, grow, in_polygon, parse_polygons
from navlab.navigation.errors import NavigationError
from navlab.navigation.velocity_smoother import VelocitySmoother

FOOTPRINT = np.array([[-0.25, -0.2], [-0.25, 0.2], [0.25, 0.2], [0.25, -0.2]])


def cloud(x: float, y: float, n: int = 6, spread: float = 0.02) -> np.ndarray:
    """``n`` laser points around (x, y) (base frame, m), as a small obstacle's returns."""
    return np.column_stack([np.full(n, x), y + np.linspace(-spread, spread, n)])


def default_monitor() -> CollisionMonitor:
    return CollisionMonitor(parse_polygons({}, FOOTPRINT))


def test_default_polygons_grow_the_footprint() -> None:
    polys = {p.name: p for p in parse_polygons({}, FOOTPRINT)}
    assert set(polys) == {"PolygonStop", "PolygonSlow", "FootprintApproach"}
    stop = polys["PolygonStop"].points
    assert stop is not None and np.allclose(np.abs(stop).max(axis=0), [0.30, 0.25])
    assert in_polygon(np.array([[0.28, 0.0], [0.32, 0.0]]), stop).tolist() == [True, False]
    assert np.allclose(np.abs(grow(FOOTPRINT, 0.3)).max(axis=0), [0.55, 0.5])


def test_stop_slowdown_and_free_space() -> None:
    mon = default_monitor()
    assert (mon.check(1.0, 0.2, np.zeros((0, 2))).v, mon.check(1.0, 0.2, cloud(3.0, 0.0)).v) == (1.0, 1.0)
    near = mon.check(0.5, 0.0, cloud(0.28, 0.0))
    assert (near.v, near.w, near.action, near.polygon) == (0.0, 0.0, "stop", "PolygonStop")
    side = mon.check(0.5, 0.0, cloud(0.0, 0.4))  # beside the robot: in the slowdown zone, not on the arc
    assert side.action == "slowdown" and side.v == pytest.approx(0.15)
    assert mon.check(0.5, 0.0, cloud(0.0, 0.4, n=3)).action == "none"  # fewer than min_points: noise


def test_approach_keeps_the_contact_time_before_collision_away() -> None:
    mon = CollisionMonitor(
        [Polygon("FootprintApproach", "approach", FOOTPRINT, min_points=4, time_before_collision=1.2)]
    )
    far = mon.check(0.5, 0.0, cloud(1.5, 0.0))  # 1.25 m of gap at 0.5 m/s: 2.5 s away
    assert far.v == 0.5
    close = mon.check(1.0, 0.0, cloud(1.0, 0.0))  # 0.75 m at 1 m/s: 0.75 s away -> slowed
    assert close.action == "approach" and 0.0 < close.v < 0.75
    assert close.extra["collision_in_s"] == pytest.approx(0.8, abs=0.11)
    turning = mon.check(0.5, 1.0, cloud(0.0, 1.2))  # an arc to the left toward a point on the left
    assert turning.v <= 0.5
    assert mon.check(-0.5, 0.0, cloud(1.0, 0.0)).v == -0.5  # reversing away from it: no change


def test_configured_polygons_and_bad_ones() -> None:
    square = [0.3, 0.3, 0.3, -0.3, -0.3, -0.3, -0.3, 0.3]
    params = {
        "polygons": ["Stop", "Ring"],
        "Stop": {"type": "polygon", "action_type": "stop", "points": square},
        "Ring": {"type": "circle", "action_type": "limit", "radius": 1.0, "linear_limit": 0.2, "max_points": 2},
    }
    mon = CollisionMonitor(parse_polygons(params, None))
    limited = mon.check(1.0, 2.0, cloud(0.8, 0.0, n=3))  # Humble's max_points 2: three points act
    assert (limited.v, limited.action) == (0.2, "limit") and limited.w == pytest.approx(0.5)
    with pytest.raises(NavigationError, match="action_type"):
        parse_polygons({"polygons": ["X"], "X": {"type": "circle", "radius": 1.0, "action_type": "explode"}}, None)
    with pytest.raises(NavigationError, match="points"):
        parse_polygons({"polygons": ["X"], "X": {"type": "polygon", "action_type": "stop", "points": [1, 2]}}, None)


def test_velocity_smoother_limits_acceleration_and_keeps_curvature() -> None:
    sm = VelocitySmoother({"max_velocity": [2.0, 0.0, 2.5], "min_velocity": [-0.5, 0.0, -2.5]})
    v, w = sm.step((2.0, 0.0), 0.05)
    assert v == pytest.approx(2.5 * 0.05)  # max_accel 2.5 m/s²
    for _ in range(40):
        v, w = sm.step((3.0, 0.0), 0.05)
    assert v == pytest.approx(2.0)  # clamped to max_velocity
    v, _ = sm.step((0.0, 0.0), 0.05)
    assert v == pytest.approx(2.0 - 2.5 * 0.05)  # max_decel
    scaled = VelocitySmoother({"scale_velocities": True})
    v, w = scaled.step((0.5, 2.0), 0.05)
    assert w / v == pytest.approx(2.0 / 0.5)  # the same arc, both axes slowed by the most limited one
    with pytest.raises(NavigationError, match="feedback"):
        VelocitySmoother({"feedback": "MAGIC"})
    assert math.isfinite(v)


def test_the_monitor_node_stops_a_robot_driven_at_a_wall() -> None:
    """The mapless launch with collision_monitor:=true: a command of 1 m/s straight at the room's wall, sent
    where move_base's would go (cmd_vel_nav), is smoothed and then stopped by the polygons before any contact."""
    from navlab import msgs
    from navlab.core import Node
    from navlab.experiments.session import start_run

    run = start_run("navigation_mapless", world="room", pose=(2.0, 0.0, 0.0), collision_monitor="true")
    mon = run.node("collision_monitor")
    driver = run.add(Node, name="driver")
    pub = driver.create_publisher(msgs.Twist, "cmd_vel_nav", 1)
    hits: list[float] = []
    driver.create_subscription(msgs.String, "/collisions", lambda _m: hits.append(1.0), 10)
    driver.create_timer(0.05, lambda: pub.publish(msgs.twist(1.0, 0.0)))
    run.run(8.0)
    assert not hits and run.sim.clearance() > 0.0
    assert mon.actions.get("PolygonStop", 0) + mon.actions.get("FootprintApproach", 0) > 0
    x, _, _ = run.sim.base_pose2d()
    assert x > 2.5  # it did drive, and stopped short of the wall
