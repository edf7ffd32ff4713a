"""Regulated Pure Pursuit (Nav2's RPP): carrot, regulation, rotate-to-heading, collision ahead, a closed loop.

Hand-made costmaps (uint8 costmap_2d costs); the closed loop integrates the commanded (v, w) every 50 ms.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.grid import COST_LETHAL, Grid
from navlab.navigation.controllers import synthetic as syn
from navlab.navigation.controllers.regulated_pure_pursuit import RegulatedPurePursuitController, carrot_on
from navlab.navigation.errors import NavigationError
from navlab.plugins import load_plugin

RES, DT = 0.05, 0.05
BOX = [[-0.25, -0.2], [-0.25, 0.2], [0.25, 0.2], [0.25, -0.2]]


def free(size: float = 10.0) -> Grid:
    n = round(size / RES)
    return Grid(np.zeros((n, n), dtype=np.uint8), RES, (-size / 2, -size / 2, 0.0), "odom")


def line(x0: float, x1: float, y: float = 0.0) -> np.ndarray:
    n = round((x1 - x0) / RES) + 1
    return np.column_stack([np.linspace(x0, x1, n), np.full(n, y), np.zeros(n)])


def rpp(**params: object) -> RegulatedPurePursuitController:
    return RegulatedPurePursuitController({"controller_frequency": 20.0, **params}, footprint=BOX)


def test_registered_by_its_nav2_name() -> None:
    cls = load_plugin("controller", "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController")
    assert cls is RegulatedPurePursuitController


def test_carrot_is_where_the_lookahead_circle_leaves_the_path() -> None:
    path = line(0.0, 3.0, y=0.3)[:, :2]
    c = carrot_on(path, 0.5)
    assert math.hypot(*c) == pytest.approx(0.5, abs=1e-6)
    assert c[1] == pytest.approx(0.3) and c[0] == pytest.approx(0.4, abs=1e-6)
    assert np.allclose(carrot_on(path[:3], 5.0), path[2])  # shorter than the lookahead: the path's end


def test_straight_line_at_desired_speed_and_slower_on_approach() -> None:
    c = rpp(desired_linear_vel=1.2)
    c.set_plan(line(0.0, 4.0))
    v, w = c.compute_velocity((0.0, 0.0, 0.0), (1.2, 0.0), free())
    assert v == pytest.approx(1.2) and w == pytest.approx(0.0, abs=1e-9)
    v_end, _ = c.compute_velocity((3.6, 0.0, 0.0), (1.2, 0.0), free())
    assert v_end == pytest.approx(1.2 * 0.4 / 0.6)  # approach_velocity_scaling_dist: slows over the last 0.6 m


def test_sharp_curvature_and_obstacle_proximity_regulate_speed() -> None:
    c = rpp(desired_linear_vel=1.0, use_cost_regulated_linear_velocity_scaling=False)
    c.set_plan(line(0.0, 4.0, y=0.3))  # the carrot is off to the left: a tight arc
    v_curve, w = c.compute_velocity((0.0, 0.0, 0.0), (0.0, 0.0), free())
    assert w > 0 and 0.25 <= v_curve < 1.0
    near = free()
    near.data[:, :] = 200  # inflated cost everywhere: about one inscribed radius from an obstacle
    c2 = rpp(desired_linear_vel=1.0, use_regulated_linear_velocity_scaling=False)
    c2.set_plan(line(0.0, 4.0))
    v_cost, _ = c2.compute_velocity((0.0, 0.0, 0.0), (0.0, 0.0), near)
    assert 0.25 <= v_cost < 0.6


def test_rotates_to_heading_first_then_to_the_goal_heading() -> None:
    c = rpp()
    c.set_plan(line(0.0, 3.0))
    v, w = c.compute_velocity((0.0, 0.0, math.pi / 2), (0.0, 0.0), free())
    assert v == 0.0 and w < 0  # turn right toward the path, limited by max_angular_accel
    assert w == pytest.approx(-3.2 * DT)
    plan = line(0.0, 1.0)
    plan[-1, 2] = math.pi / 2
    c.set_plan(plan)
    v, w = c.compute_velocity((1.0, 0.0, 0.0), (0.0, 1.0), free())
    assert v == 0.0 and w > 0  # within the xy tolerance: turn to the goal's yaw
    assert not c.is_goal_reached((1.0, 0.0, 0.0), (0.0, 0.0))
    assert c.is_goal_reached((1.0, 0.0, math.pi / 2), (0.0, 0.0))


def test_collision_ahead_stops_and_marks_the_cycle_invalid() -> None:
    g = free()
    ij = g.world_to_cell(np.array([[0.6, 0.0]]))[0]
    g.data[:, ij[0]] = COST_LETHAL  # a wall across the path 0.6 m ahead
    c = rpp(desired_linear_vel=1.0)
    c.set_plan(line(0.0, 3.0))
    v, w = c.compute_velocity((0.0, 0.0, 0.0), (1.0, 0.0), g)
    assert (v, w) == (0.0, 0.0) and not c.valid and "collision" in c.last_failure
    c2 = rpp(desired_linear_vel=1.0, use_collision_detection=False)
    c2.set_plan(line(0.0, 3.0))
    assert c2.compute_velocity((0.0, 0.0, 0.0), (1.0, 0.0), g).v > 0 and c2.valid


def test_closed_loop_follows_a_bent_path_to_the_goal() -> None:
    plan = np.vstack([line(0.0, 1.5), np.column_stack([np.full(31, 1.5), np.linspace(0.0, 1.5, 31), np.zeros(31)])])
    g = free()
    c = rpp(desired_linear_vel=0.8)
    c.set_plan(plan)
    pose, vel = (0.0, 0.0, 0.0), (0.0, 0.0)
    worst = 0.0
    for _ in range(400):
        if c.is_goal_reached(pose, vel):
            break
        vel = tuple(c.compute_velocity(pose, vel, g))
        x, y, th = pose
        pose = (x + vel[0] * math.cos(th) * DT, y + vel[0] * math.sin(th) * DT, th + vel[1] * DT)
        d = np.hypot(plan[:, 0] - pose[0], plan[:, 1] - pose[1]).min()
        worst = max(worst, float(d))
    assert math.hypot(pose[0] - 1.5, pose[1] - 1.5) <= 0.25
    assert worst < 0.35  # pure pursuit cuts the corner by less than its lookahead


def test_bad_parameters_are_refused_with_the_key() -> None:
    with pytest.raises(NavigationError, match="min_lookahead_dist"):
        rpp(min_lookahead_dist=2.0, max_lookahead_dist=1.0)
    with pytest.raises(NavigationError, match="desired_linear_vel"):
        rpp(desired_linear_vel=-1.0)
    assert syn is not None
