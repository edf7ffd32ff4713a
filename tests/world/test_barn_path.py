"""BARN's generator path (the path_N.npy the challenge's run.py turns into T_opt) on hand-made grids: A* with
turns of at most 45 degrees, no squeeze between diagonal blocks, the wall penalty, run.py's length, and the
path on a field in navlab's row order."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from navlab.world.barn_grid import (
    CELLS,
    RUNNER_OFFSET,
    barn_astar,
    barn_path,
    barn_path_length,
    configuration_space,
    field_centres,
    wall_distance,
)
from navlab.world.clutter import generate_clutter


def _steps(path: list[tuple[int, int]]) -> list[tuple[int, int]]:
    return [(b[0] - a[0], b[1] - a[1]) for a, b in itertools.pairwise(path)]


def _turn_deg(a: tuple[int, int], b: tuple[int, int]) -> float:
    return abs(math.degrees(math.remainder(math.atan2(b[0], b[1]) - math.atan2(a[0], a[1]), math.tau)))


def test_wall_distance_is_the_euclidean_distance_to_the_nearest_blocked_cell() -> None:
    blocked = np.zeros((7, 9), dtype=bool)
    blocked[0, 0] = blocked[6, 8] = True
    d = wall_distance(blocked)
    for r, c in itertools.product(range(7), range(9)):
        assert d[r, c] == pytest.approx(min(math.hypot(r, c), math.hypot(r - 6, c - 8)))


def test_a_straight_corridor_gives_the_straight_path() -> None:
    blocked = np.ones((5, 10), dtype=bool)
    blocked[2] = False
    path = barn_astar(blocked, (2, 0), (2, 9), wall_distance(blocked))
    assert path == [(2, c) for c in range(10)]


def test_turns_are_at_most_45_degrees_and_a_u_turn_takes_the_long_way() -> None:
    """From the start any of 8 moves; after that straight on or 45 degrees. Going right then having to come back
    left means two 45 degree turns, each a step of its own."""
    blocked = np.zeros((8, 8), dtype=bool)
    blocked[3, 1:] = True  # a wall the path must go round at its open left end
    start, end = (1, 6), (5, 6)
    path = barn_astar(blocked, start, end, wall_distance(blocked))
    assert path is not None and path[0] == start and path[-1] == end
    steps = _steps(path)
    assert all(max(abs(dr), abs(dc)) == 1 for dr, dc in steps)
    assert all(_turn_deg(a, b) <= 45.0 + 1e-9 for a, b in itertools.pairwise(steps))
    assert not any(blocked[r, c] for r, c in path)
    assert (3, 0) in path  # round the wall's open end


def test_no_squeeze_between_two_diagonal_blocks_and_none_without_a_way() -> None:
    blocked = np.ones((4, 4), dtype=bool)
    blocked[1, 1] = blocked[2, 2] = False  # joined only corner to corner
    assert barn_astar(blocked, (1, 1), (2, 2), wall_distance(blocked)) is None
    blocked[1, 2] = False  # now a side step joins them: the diagonal is allowed
    assert barn_astar(blocked, (1, 1), (2, 2), wall_distance(blocked)) == [(1, 1), (2, 2)]


def test_cells_within_two_cells_of_a_wall_cost_more(monkeypatch: pytest.MonkeyPatch) -> None:
    """Round a 3 x 3 block in the open: without the penalty the path hugs the block (cells 1 from it); with
    BARN's 5 / d on cells d <= 2 from it, it keeps more than 2 cells off (as many steps: 10)."""
    import navlab.world.barn_grid as barn_grid

    blocked = np.zeros((11, 11), dtype=bool)
    blocked[4:7, 4:7] = True
    dist = wall_distance(blocked)
    path = barn_astar(blocked, (5, 0), (5, 10), dist)
    assert path is not None and len(path) == 11 and min(dist[p] for p in path) > 2.0
    monkeypatch.setattr(barn_grid, "PENALTY_FACTOR", 0.0)
    hugging = barn_astar(blocked, (5, 0), (5, 10), dist)
    assert hugging is not None and len(hugging) == 11 and min(dist[p] for p in hugging) == 1.0


def test_run_py_length_of_a_straight_path() -> None:
    """A path along one field row, from the first column to the last: run.py's legs are start -> the first cell
    (where run.py puts it, 0.1 m back and one row aside), 29 cells of 0.15 m, the last cell -> goal."""
    row = 12
    path = np.array([(row, 0), (row, 0), *[(row, c) for c in range(1, CELLS)]])
    start, goal = np.array([-2.1, -0.25]), np.array([7.9, -0.25])
    xc, yc = field_centres()
    first = np.array([xc[0] + RUNNER_OFFSET[0], yc[row] + RUNNER_OFFSET[1]])
    last = np.array([xc[-1] + RUNNER_OFFSET[0], yc[row] + RUNNER_OFFSET[1]])
    expected = np.linalg.norm(first - start) + 29 * 0.15 + np.linalg.norm(goal - last)
    assert barn_path_length(path, start, goal) == pytest.approx(expected)
    assert yc[row] + RUNNER_OFFSET[1] == pytest.approx(-0.25 - 2.175 + 0.15 * (row + 1) + 0.25)


def test_the_path_runs_through_the_only_free_band_in_navlabs_rows() -> None:
    """A field open only in navlab's rows 3..9 (low y): the path stays there (BARN's rows are navlab's upside
    down, and the path comes back in navlab's), from the first column to the last, the start given twice."""
    cells = np.zeros((CELLS, CELLS), dtype=bool)
    cells[[0, -1]] = True
    cells[12] = True  # a full row of cylinders: the c-space is free only in rows 3..9 and 15..26
    cells[15:] = True  # everything above it filled
    free = configuration_space(cells)
    path = barn_path(cells, np.random.default_rng(0))
    assert path is not None
    assert tuple(path[0]) == tuple(path[1]) and path[0][1] == 0 and path[-1][1] == CELLS - 1
    assert all(free[r, c] for r, c in path) and set(path[:, 0]) <= set(range(3, 10))
    assert barn_path(cells, np.random.default_rng(0)).tolist() == path.tolist()  # same stream, same path


def test_a_generated_world_carries_barns_path_and_t_opt() -> None:
    w = generate_clutter(3, fill=0.3, smooth=2)
    free = configuration_space(w.cells)
    assert w.barn_path is not None and all(free[r, c] for r, c in w.barn_path)
    assert w.barn_path_m == pytest.approx(barn_path_length(w.barn_path, np.array(w.start[:2]), np.array(w.goal[:2])))
    assert w.barn_t_opt() == pytest.approx(w.barn_path_m / 2.0) and w.barn_path_m > 10.0
    assert w.summary()["barn_t_opt_s"] == pytest.approx(w.barn_t_opt(), abs=1e-4)
