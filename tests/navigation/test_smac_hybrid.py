"""Smac Hybrid-A* (``nav2_smac_planner/SmacPlannerHybrid``) and its Dubins curves on hand-made grids."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import ndimage

from navlab.grid import COST_LETHAL, Grid
from navlab.navigation.errors import NavigationError
from navlab.navigation.planners import dubins
from navlab.navigation.planners.navfn import NavfnPlanner
from navlab.navigation.planners.smac_hybrid import SmacPlannerHybrid
from navlab.plugins import load_plugin

RES = 0.05
LONG = [[-0.3, -0.15], [-0.3, 0.15], [0.3, 0.15], [0.3, -0.15]]  # 0.6 m x 0.3 m: outer circle 0.335 m


def wall_with_gap(gap: float = 0.5) -> Grid:
    """A 6 m x 6 m map with a wall along x = 0 (0.5 m thick) and one gap of ``gap`` m around y = 0: a passage."""
    n = round(6.0 / RES)
    data = np.zeros((n, n), np.uint8)
    y = -3.0 + (np.arange(n) + 0.5) * RES
    data[np.abs(y) > gap / 2, n // 2 - 5 : n // 2 + 5] = COST_LETHAL
    return Grid(data, RES, (-3.0, -3.0, 0.0), "odom")


def footprint_free(grid: Grid, path: np.ndarray, footprint: list[list[float]]) -> bool:
    """Every pose of ``path`` keeps the footprint's filled polygon off lethal cells."""
    poly = np.asarray(footprint)
    xs, ys = np.meshgrid(
        np.linspace(poly[:, 0].min(), poly[:, 0].max(), 13), np.linspace(poly[:, 1].min(), poly[:, 1].max(), 7)
    )
    body = np.column_stack([xs.ravel(), ys.ravel()])
    for x, y, th in path:
        c, s = math.cos(th), math.sin(th)
        pts = np.column_stack([x + c * body[:, 0] - s * body[:, 1], y + s * body[:, 0] + c * body[:, 1]])
        ij = grid.world_to_cell(pts)
        if np.any(grid.data[ij[:, 1], ij[:, 0]] == COST_LETHAL):
            return False
    return True


def max_curvature(path: np.ndarray) -> float:
    d = np.hypot(*np.diff(path[:, :2], axis=0).T)
    dth = np.abs(np.angle(np.exp(1j * np.diff(path[:, 2]))))
    return float((dth / np.maximum(d, 1e-9))[d > 1e-6].max())


def test_registered_by_its_nav2_name() -> None:
    assert load_plugin("global_planner", "nav2_smac_planner/SmacPlannerHybrid") is SmacPlannerHybrid


def test_dubins_paths_end_at_the_goal_pose() -> None:
    rng = np.random.default_rng(3)
    for _ in range(200):
        a = (*rng.uniform(-3, 3, 2), rng.uniform(-math.pi, math.pi))
        b = (*rng.uniform(-3, 3, 2), rng.uniform(-math.pi, math.pi))
        word, lengths = dubins.shortest(a, b, 0.5)
        end = dubins.sample(a, word, lengths, 0.5, 0.05)[-1]
        assert math.hypot(end[0] - b[0], end[1] - b[1]) < 1e-6
        assert abs(math.remainder(end[2] - b[2], 2 * math.pi)) < 1e-6
        assert sum(lengths) >= math.dist(a[:2], b[:2]) - 1e-9
    assert dubins.shortest((0, 0, 0), (3, 0, 0), 0.5) == ("LSL", (0.0, 3.0, 0.0))


def test_through_a_gap_narrower_than_the_robots_outer_circle() -> None:
    """The 0.5 m gap is narrower than the footprint's outer circle (0.67 m) but wider than the robot (0.3 m):
    a planner for a round robot of that circle finds no way; Hybrid-A* with the footprint drives through, and
    the straight line from start to goal would scrape the wall."""
    grid = wall_with_gap(0.5)
    start, goal = (-1.5, 1.0, 0.0), (1.5, -1.0, 0.0)
    line = np.column_stack(
        [
            np.linspace(start[0], goal[0], 60),
            np.linspace(start[1], goal[1], 60),
            np.full(60, math.atan2(goal[1] - start[1], goal[0] - start[0])),
        ]
    )
    assert not footprint_free(grid, line, LONG)
    outer = ndimage.binary_dilation(grid.data == COST_LETHAL, iterations=round(0.335 / RES))
    round_robot = Grid(np.where(outer, COST_LETHAL, 0).astype(np.uint8), RES, grid.origin, grid.frame_id)
    assert NavfnPlanner({"default_tolerance": 0.0}).make_plan(round_robot, start, goal) is None
    planner = SmacPlannerHybrid({"minimum_turning_radius": 0.4}, footprint=LONG)
    path = planner.make_plan(grid, start, goal)
    assert path is not None, planner.last_failure
    assert np.allclose(path[0], start) and np.allclose(path[-1], goal)
    assert footprint_free(grid, path, LONG)
    crossing = path[np.argmin(np.abs(path[:, 0]))]
    assert abs(crossing[1]) < 0.25 and abs(math.remainder(crossing[2], math.pi)) < 0.3  # lengthwise through
    assert max_curvature(path) <= 1.01 / 0.4  # chords of arcs of radius 0.4 m


def test_turns_are_kinematically_feasible() -> None:
    """A goal behind the robot: no turn on the spot, every turn no sharper than the minimum radius, and the
    path leaves along the start heading."""
    n = round(6.0 / RES)
    grid = Grid(np.zeros((n, n), np.uint8), RES, (-3.0, -3.0, 0.0), "odom")
    for r in (0.4, 0.8):
        path = SmacPlannerHybrid({"minimum_turning_radius": r}).make_plan(grid, (0.0, 0.0, 0.0), (-1.0, 0.5, math.pi))
        assert path is not None
        assert max_curvature(path) <= 1.01 / r
        first = path[1, :2] - path[0, :2]
        assert math.atan2(first[1], first[0]) == pytest.approx(0.0, abs=0.2)
        assert np.hypot(*np.diff(path[:, :2], axis=0).T).sum() > math.pi * r  # a U-turn at least


def test_an_enclosed_goal_is_refused_with_a_reason() -> None:
    grid = wall_with_gap(0.0)
    planner = SmacPlannerHybrid({"allow_unknown": False}, footprint=LONG)
    assert planner.make_plan(grid, (-1.5, 0.0, 0.0), (1.5, 0.0, 0.0)) is None
    assert "cut off" in planner.last_failure
    with pytest.raises(NavigationError, match="outside"):
        planner.make_plan(grid, (-1.5, 0.0, 0.0), (9.0, 0.0, 0.0))
    with pytest.raises(NavigationError, match="motion_model_for_search"):
        SmacPlannerHybrid({"motion_model_for_search": "TANK"})
