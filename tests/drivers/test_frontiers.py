"""Exploration algorithms on synthetic grids: frontiers, the costs from navigation's layers, planning around
walls, the bounded search against a full one (scipy's Dijkstra), the path follower."""

import math

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import dijkstra

from navlab.drivers.frontiers import (
    exploration_costmap,
    find_frontiers,
    plan_to_frontier,
    prepare_frontier_search,
    traversable,
)
from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, GridMap
from navlab.navigation.controllers.pure_pursuit import follow_path


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
    known = grid.crop_to_known()
    mask = traversable(exploration_costmap(known, 0.25))
    cells = known.world_to_cell(path)
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
    search = prepare_frontier_search(grid)
    found = search.distances(robot_xy)
    assert found is not None
    dist = found[0]
    grid = search.grid
    best, best_cost = None, math.inf
    for f in search.frontiers:
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


def test_full_search_is_scipys_dijkstra_over_the_step_costs():
    rng = np.random.default_rng(2)
    for _ in range(20):
        h, w = (int(v) for v in rng.integers(3, 30, 2))
        data = np.where(rng.random((h, w)) < 0.1, 100, 0).astype(np.int8)
        data[h // 2, w // 2] = 0
        grid = GridMap(data, 0.05, (0.0, 0.0, 0.0))
        search = prepare_frontier_search(grid, robot_radius=0.05)
        start_xy = tuple(grid.cell_to_world(np.array([[w // 2, h // 2]]))[0])
        start = search.start_cell(start_xy)
        assert start is not None
        found = search.distances(start_xy)
        assert found is not None
        mask = search.mask.copy()
        mask[start[1], start[0]] = True
        rows, cols, vals = [], [], []
        for j, i in zip(*np.nonzero(mask), strict=True):
            for dj, di, length in ((0, 1, 1.0), (1, 0, 1.0), (1, 1, np.sqrt(2.0)), (1, -1, np.sqrt(2.0))):
                j2, i2 = j + dj, i + di
                if 0 <= j2 < h and 0 <= i2 < w and mask[j2, i2]:
                    a, b = j * w + i, j2 * w + i2
                    c = length * 0.5 * (search.cell_cost[a] + search.cell_cost[b])
                    rows += [a, b]
                    cols += [b, a]
                    vals += [c, c]
        graph = sparse.csr_matrix((vals, (rows, cols)), shape=(h * w, h * w))
        want = dijkstra(graph, indices=start[1] * w + start[0]).reshape(h, w)
        np.testing.assert_allclose(found[0], want, rtol=1e-12)


def test_exploration_costs_are_navigations_static_and_inflation_layers():
    data = np.zeros((40, 40), dtype=np.int8)
    data[:, 30:] = -1  # unknown beyond x = 1.5 m
    data[20, 10] = 100  # one obstacle at (0.525, 1.025)
    data[5, 5] = 64  # under the occupied threshold: free
    costs = exploration_costmap(GridMap(data, 0.05, (0.0, 0.0, 0.0)), 0.2, comfort=0.4).data
    assert costs[20, 10] == COST_LETHAL
    assert costs[20, 14] == COST_INSCRIBED  # 0.20 m away: within the radius
    assert (costs[:, 30:] == COST_UNKNOWN).all()
    profile = costs[20, 15:20].astype(int)  # 0.25 .. 0.45 m: falling with the distance
    assert (np.diff(profile) < 0).all() and 0 < profile[-1] < profile[0] < COST_INSCRIBED
    assert costs[20, 23] == 0 and costs[5, 5] == 0  # beyond radius + comfort (0.65 m); 64 % is free
