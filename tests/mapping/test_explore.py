"""Exploration algorithms on synthetic grids: frontiers, planning around walls, the path follower."""

import math

import numpy as np

from navlab.grid import GridMap
from navlab.mapping.explore import find_frontiers, plan_to_frontier, traversable
from navlab.mapping.follow import follow_path


def _half_known_room() -> GridMap:
    """A 4 × 3 m room (5 cm cells) with walls; the left half is mapped free, the right half unknown."""
    data = np.full((60, 80), -1, dtype=np.int8)
    data[:, :40] = 0
    data[0, :] = data[-1, :] = 100
    data[:, 0] = data[:, -1] = 100
    data[20:, 20] = 100  # an interior wall from y = 1.0 m up, open below
    data[:, 40:] = -1
    return GridMap(data, 0.05, (0.0, 0.0, 0.0))


def test_frontier_is_the_known_unknown_border():
    fr = find_frontiers(_half_known_room())
    assert len(fr) == 1
    assert np.all(fr[0].cells[:, 0] == 39)
    assert abs(fr[0].centroid[0] - 1.975) < 1e-9


def test_plan_goes_around_the_wall_and_keeps_clearance():
    grid = _half_known_room()
    path = plan_to_frontier(grid, (0.5, 2.5), robot_radius=0.25)
    assert path is not None
    assert np.hypot(*(path[0] - (0.525, 2.525))) < 0.08
    assert path[-1][0] > 1.9  # reaches the frontier column
    assert path[:, 1].min() < 1.0  # had to pass below the interior wall's lower end
    # every path cell keeps the robot radius from occupied cells
    mask = traversable(grid, 0.25)
    cells = grid.world_to_cell(path)
    assert mask[cells[:, 1], cells[:, 0]].all()


def test_no_frontier_left_means_none():
    grid = _half_known_room()
    grid.data[grid.data < 0] = 0
    grid.data[:, -1] = 100
    assert plan_to_frontier(grid, (0.5, 2.5)) is None


def test_follower_turns_then_drives_and_stops_for_obstacles():
    path = np.array([[0.0, 0.0], [0.0, 1.0], [0.0, 2.0]])
    v, w, _ = follow_path((0.0, 0.0, 0.0), path)  # facing +x, path goes +y: turn left in place
    assert v == 0.0 and w > 0
    v, w, _ = follow_path((0.0, 0.0, math.pi / 2), path)
    assert v > 0.2 and abs(w) < 1e-6
    v, w, _ = follow_path((0.0, 0.0, math.pi / 2), path, min_front_range=0.2)
    assert v == 0.0
