"""Global planners on hand-made costmaps: navfn (Dijkstra and A*) and Theta*, against known optimal paths."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, Grid
from navlab.navigation import NavigationError
from navlab.navigation.planners import (
    GlobalPlanner,
    NavfnPlanner,
    ThetaStarPlanner,
    make_planner,
    path_length,
)
from navlab.plugins import PluginError

RES = 0.1
PLANNERS = [
    pytest.param(lambda **p: NavfnPlanner(p), id="navfn-dijkstra"),
    pytest.param(lambda **p: NavfnPlanner({"use_dijkstra": False, **p}), id="navfn-astar"),
    pytest.param(lambda **p: ThetaStarPlanner(p), id="theta_star"),
]


def _grid(data: np.ndarray) -> Grid:
    return Grid(data.astype(np.uint8), RES, (0.0, 0.0, 0.0), "map")


def _costs_along(grid: Grid, path: np.ndarray) -> np.ndarray:
    """Costs of the cells under the path, sampled every 1 cm along it."""
    dense = [path[:1]]
    for a, b in itertools.pairwise(path):
        k = max(1, math.ceil(float(np.hypot(*(b - a))) / 0.01))
        dense.append(a + (np.arange(1, k + 1)[:, None] / k) * (b - a))
    return grid.value_at(np.vstack(dense), outside=COST_UNKNOWN)


def _corridor() -> Grid:
    data = np.zeros((10, 60))
    data[0, :] = data[-1, :] = COST_LETHAL
    return _grid(data)


def _l_shape() -> Grid:
    """Free: the bottom arm y < 1 m and the right arm x >= 4 m of a 5 m x 5 m square; the rest is lethal."""
    data = np.full((50, 50), COST_LETHAL)
    data[:10, :] = 0
    data[:, 40:] = 0
    return _grid(data)


@pytest.mark.parametrize("make", PLANNERS)
def test_straight_corridor(make) -> None:  # type: ignore[no-untyped-def]
    grid = _corridor()
    path = make().make_plan(grid, (0.5, 0.45, 0.0), (5.5, 0.45, math.pi))
    assert path is not None and path.shape[1] == 2
    assert path[0].tolist() == [0.5, 0.45] and path[-1].tolist() == [5.5, 0.45]
    assert path_length(path) == pytest.approx(5.0, rel=0.01)
    assert np.abs(path[:, 1] - 0.45).max() < 0.1
    assert np.hypot(*np.diff(path, axis=0).T).max() <= RES * 1.5  # dense enough for a controller


@pytest.mark.parametrize("make", PLANNERS)
def test_l_shaped_detour_is_near_the_optimal_length(make) -> None:  # type: ignore[no-untyped-def]
    grid = _l_shape()
    path = make().make_plan(grid, (0.5, 0.5, 0.0), (4.5, 4.5, 0.0))
    assert path is not None
    optimal = 2 * math.hypot(3.5, 0.5)  # taut string around the inner corner (4.0, 1.0)
    assert optimal * 0.999 <= path_length(path) <= optimal * 1.03
    assert _costs_along(grid, path).max() < COST_INSCRIBED  # never crosses the obstacle


@pytest.mark.parametrize("make", PLANNERS)
def test_walled_off_goal_gives_none_with_a_reason(make) -> None:  # type: ignore[no-untyped-def]
    data = np.zeros((40, 40))
    data[20:31, 20] = data[20:31, 30] = data[20, 20:31] = data[30, 20:31] = COST_LETHAL
    planner = make()
    assert planner.make_plan(_grid(data), (0.5, 0.5, 0.0), (2.5, 2.5, 0.0)) is None
    assert "cut off" in planner.last_failure


@pytest.mark.parametrize("make", PLANNERS)
def test_goal_in_an_obstacle_is_refused(make) -> None:  # type: ignore[no-untyped-def]
    planner = make()
    assert planner.make_plan(_l_shape(), (0.5, 0.5, 0.0), (2.5, 2.5, 0.0)) is None
    assert "in an obstacle (cost 254)" in planner.last_failure


def test_navfn_default_tolerance_plans_to_the_nearest_reachable_cell() -> None:
    grid = _l_shape()
    goal = (3.02, 1.3, 0.0)  # 0.3 m above the bottom arm, inside the obstacle block
    assert NavfnPlanner().make_plan(grid, (0.5, 0.5, 0.0), goal) is None
    planner = NavfnPlanner({"default_tolerance": 0.5})
    path = planner.make_plan(grid, (0.5, 0.5, 0.0), goal)
    assert path is not None and planner.last_failure == ""
    assert path[-1] == pytest.approx((3.05, 0.95))  # the free cell nearest the goal
    assert grid.value_at(path[-1:], outside=COST_UNKNOWN)[0] == 0
    far = NavfnPlanner({"default_tolerance": 0.5})
    assert far.make_plan(grid, (0.5, 0.5, 0.0), (2.0, 3.0, 0.0)) is None
    assert "no reachable cell within default_tolerance 0.5 m" in far.last_failure


def test_theta_star_is_shorter_than_navfn_on_an_open_diagonal() -> None:
    grid = _grid(np.zeros((60, 60)))
    start, goal = (0.33, 0.31, 0.0), (5.71, 5.52, 0.0)
    straight = math.dist(start[:2], goal[:2])
    theta = ThetaStarPlanner().make_plan(grid, start, goal)
    navfn = NavfnPlanner().make_plan(grid, start, goal)
    assert theta is not None and navfn is not None
    assert path_length(theta) == pytest.approx(straight, rel=1e-6)  # one straight segment
    assert path_length(navfn) == pytest.approx(straight, rel=0.02)
    assert path_length(theta) < path_length(navfn)


@pytest.mark.parametrize("make", PLANNERS)
def test_planners_go_around_expensive_cells(make) -> None:  # type: ignore[no-untyped-def]
    data = np.zeros((40, 60))
    data[10:30, 25:35] = 250  # passable but costly (not lethal)
    grid = _grid(data)
    path = make().make_plan(grid, (0.5, 2.0, 0.0), (5.5, 2.0, 0.0))
    assert path is not None
    assert (_costs_along(grid, path) == 250).mean() < 0.05


def test_astar_expands_fewer_cells_than_dijkstra_for_the_same_path() -> None:
    grid = _grid(np.zeros((80, 80)))
    dijkstra, astar = NavfnPlanner(), NavfnPlanner({"use_dijkstra": False})
    a = dijkstra.make_plan(grid, (0.5, 0.5, 0.0), (7.5, 3.5, 0.0))
    b = astar.make_plan(grid, (0.5, 0.5, 0.0), (7.5, 3.5, 0.0))
    assert a is not None and b is not None
    assert path_length(b) == pytest.approx(path_length(a), rel=0.01)
    assert astar.stats["cells"] < 0.6 * dijkstra.stats["cells"]


def test_allow_unknown_decides_whether_unknown_cells_are_passable() -> None:
    data = np.zeros((30, 30))
    data[:, 15] = COST_UNKNOWN  # an unknown band between start and goal
    grid = _grid(data)
    for make in (NavfnPlanner, ThetaStarPlanner):
        assert make().make_plan(grid, (0.5, 1.5, 0.0), (2.5, 1.5, 0.0)) is not None
        closed = make({"allow_unknown": False})
        assert closed.make_plan(grid, (0.5, 1.5, 0.0), (2.5, 1.5, 0.0)) is None
        assert "cut off" in closed.last_failure


def test_unknown_cost_prices_unknown_cells_against_a_seen_detour() -> None:
    """navfn prices an unknown cell at lethal_cost (253, ~5x a free cell): a 1 m unknown band with a seen-free way
    round it (4.4 m) is driven round; with ``unknown_cost`` 100 (2x) the straight 2 m through it is cheaper."""
    data = np.zeros((30, 30))
    data[:25, 10:20] = COST_UNKNOWN  # never observed, but for a free strip along the top
    grid = _grid(data)
    start, goal = (0.5, 1.0, 0.0), (2.5, 1.0, 0.0)
    around = NavfnPlanner().make_plan(grid, start, goal)
    assert around is not None and around[:, 1].max() > 2.4
    through = NavfnPlanner({"unknown_cost": 100.0}).make_plan(grid, start, goal)
    assert through is not None and through[:, 1].max() < 1.2
    assert path_length(through) == pytest.approx(2.0, abs=0.05)
    with pytest.raises(NavigationError, match="unknown_cost: expected -1"):
        NavfnPlanner({"unknown_cost": 0.0})


@pytest.mark.parametrize("make", PLANNERS)
def test_start_errors_explain_why(make) -> None:  # type: ignore[no-untyped-def]
    grid = _l_shape()
    with pytest.raises(NavigationError, match=r"start \(-1.000, 0.500\) is outside the costmap"):
        make().make_plan(grid, (-1.0, 0.5, 0.0), (4.5, 4.5, 0.0))
    with pytest.raises(NavigationError, match=r"start \(2.500, 2.500\) is in an obstacle"):
        make().make_plan(grid, (2.5, 2.5, 0.0), (4.5, 4.5, 0.0))
    with pytest.raises(NavigationError, match=r"goal \(9.000, 4.500\) is outside the costmap"):
        make().make_plan(grid, (0.5, 0.5, 0.0), (9.0, 4.5, 0.0))


@pytest.mark.parametrize("make", PLANNERS)
def test_a_start_in_inscribed_space_is_cleared_as_navfn_does(make) -> None:  # type: ignore[no-untyped-def]
    data = np.zeros((20, 20))
    data[5, 5] = COST_INSCRIBED
    path = make().make_plan(_grid(data), (0.55, 0.55, 0.0), (1.5, 1.5, 0.0))
    assert path is not None and path[0].tolist() == [0.55, 0.55]


def test_plugin_names_and_nav2_spellings() -> None:
    assert isinstance(make_planner("navfn/NavfnROS"), NavfnPlanner)
    nav2 = make_planner("nav2_navfn_planner/NavfnPlanner", {"use_astar": True, "tolerance": 0.25})
    assert nav2.params.use_dijkstra is False and nav2.params.default_tolerance == 0.25
    gp = make_planner("global_planner/GlobalPlanner", {"use_dijkstra": False})
    assert isinstance(gp, GlobalPlanner) and gp.params.cost_factor == 3.0
    assert isinstance(make_planner("nav2_theta_star_planner/ThetaStarPlanner"), ThetaStarPlanner)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: make_planner("navfn/NavfnRos"), "did you mean 'navfn/NavfnROS'"),
        (lambda: NavfnPlanner({"default_tolerance": -1.0}), "default_tolerance: expected >= 0.0, got -1.0"),
        (lambda: NavfnPlanner({"allow_unknwn": False}), "did you mean 'allow_unknown'"),
        (lambda: NavfnPlanner({"allow_unknown": "no"}), "allow_unknown: expected true or false, got 'no'"),
        (lambda: ThetaStarPlanner({"how_many_corners": 6}), "how_many_corners: expected 4 or 8, got 6"),
        (lambda: ThetaStarPlanner({"w_traversal_cost": -2.0}), "w_traversal_cost: expected >= 0"),
        (lambda: GlobalPlanner({"use_grid_path": True}), "use_grid_path: only false"),
    ],
)
def test_bad_parameters_get_one_line_errors(make, match: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises((NavigationError, PluginError), match=match) as info:
        make()
    assert "\n" not in str(info.value)
