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


def _full_search_goal(grid: GridMap, robot_xy: tuple[float, float]) -> tuple[float, float] | None:
    """The frontier goal by a Dijkstra over the whole map (the reference for the bounded search)."""
    from navlab.mapping.explore import GridDijkstraPlanner, clearance_costmap

    grid = grid.crop_to_known()
    found = GridDijkstraPlanner().distances(clearance_costmap(grid, 0.3), robot_xy)
    assert found is not None
    dist = found[0]
    best, best_cost = None, math.inf
    for f in find_frontiers(grid, min_cells=5):
        d = dist[f.cells[:, 1], f.cells[:, 0]]
        if not np.isfinite(d).any():
            continue
        k = int(np.argmin(d))
        cost = d[k] * grid.resolution - 0.02 * f.size * grid.resolution
        if cost < best_cost:
            best, best_cost = f.cells[k], cost
    return None if best is None else tuple(grid.cell_to_world(best[None])[0])


def test_bounded_search_picks_the_goal_of_a_full_search():
    rng = np.random.default_rng(3)
    for _ in range(12):
        data = np.full((80, 100), -1, dtype=np.int8)
        data[5:75, int(rng.integers(15, 35)) : int(rng.integers(65, 90))] = 0  # known band, unknown both sides
        data[5, :] = data[74, :] = 100
        for _ in range(8):  # wall pieces, none on the robot
            j, i = int(rng.integers(5, 75)), int(rng.integers(5, 95))
            if abs(i - 50) > 8 or abs(j - 40) > 8:
                data[j : j + int(rng.integers(1, 20)), i : i + 2] = 100
        grid = GridMap(data, 0.05, (0.0, 0.0, 0.0))
        start = (2.525, 2.025)
        path = plan_to_frontier(grid, start)
        goal = _full_search_goal(grid, start)
        assert path is not None and goal is not None
        assert np.allclose(path[-1], goal)


def test_clearance_is_scipys_euclidean_distance_transform():
    from scipy import ndimage

    from navlab.mapping.explore import clearance

    rng = np.random.default_rng(5)
    for _ in range(300):
        h, w = (int(v) for v in rng.integers(1, 50, 2))
        data = np.where(rng.random((h, w)) < rng.random() ** 3, 100, 0).astype(np.int8)
        data[rng.integers(h), rng.integers(w)] = 100
        grid = GridMap(data, 0.05, (0.0, 0.0, 0.0))
        assert np.array_equal(clearance(grid), ndimage.distance_transform_edt(data < 65) * 0.05)
    assert np.isinf(clearance(GridMap(np.zeros((4, 5), dtype=np.int8), 0.05, (0.0, 0.0, 0.0)))).all()


def test_clearance_costmap_follows_its_formula():
    from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN
    from navlab.mapping.explore import clearance, clearance_costmap

    rng = np.random.default_rng(7)
    for _ in range(200):
        h, w = (int(v) for v in rng.integers(1, 40, 2))
        data = rng.choice(np.array([-1, 0, 30, 64, 65, 100], dtype=np.int8), size=(h, w))
        grid = GridMap(data, 0.05, (0.0, 0.0, 0.0))
        radius, comfort = float(rng.uniform(0.05, 0.5)), float(rng.uniform(0.05, 0.8))
        dist = clearance(grid)
        expect = np.rint(252.0 * np.clip((radius + comfort - dist) / comfort, 0.0, 1.0) ** 2).astype(np.uint8)
        expect[dist <= radius] = COST_INSCRIBED
        expect[data < 0] = COST_UNKNOWN
        expect[data >= 65] = COST_LETHAL
        assert np.array_equal(clearance_costmap(grid, radius, comfort=comfort).data, expect)
