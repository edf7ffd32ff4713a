"""Prices for never-observed cells likely to be closed (costmap.hidden_cells and the obstacle layer's opt-in)."""

from __future__ import annotations

import numpy as np
import pytest

from navlab.grid import COST_FREE, COST_LETHAL, COST_UNKNOWN, Grid
from navlab.navigation import NavigationError
from navlab.navigation.costmap import ObstacleLayer, make_footprint
from navlab.navigation.costmap.hidden_cells import hidden_costs, mark_shadows, near_obstacle_costs, write_hidden

RES = 0.05


def _master(fill: int = COST_FREE) -> Grid:
    return Grid(np.full((100, 100), fill, np.uint8), RES, (-2.5, -2.5, 0.0), "odom")


def _layer(**params: object) -> tuple[ObstacleLayer, Grid]:
    master = _master()
    layer = ObstacleLayer(dict(params), footprint=make_footprint(robot_radius=0.1, footprint_padding=0.0))
    layer.match_size(master)
    return layer, master


def _at(grid: Grid, x: float, y: float) -> int:
    return int(grid.value_at(np.array([[x, y]]), outside=COST_UNKNOWN)[0])


def _wall_scan(x: float = 1.0, half: float = 0.3) -> np.ndarray:
    """Returns of a wall across +x at ``x`` m from y = -half to +half, seen from the origin (m)."""
    ys = np.linspace(-half, half, 61)
    return np.stack([np.full_like(ys, x), ys], axis=1)


# --- the pure kernels --------------------------------------------------------------------------


def test_a_return_shadows_the_cells_behind_it_out_to_reach_and_depth() -> None:
    shadow = np.zeros((10, 20), np.uint8)
    ends = np.array([[5.5, 2.5]])  # from (0.5, 2.5) along +x: the return in cell (5, 2)
    n = mark_shadows(shadow, 0.5, 2.5, ends, np.array([True]), 12.0, 0.0)
    row = shadow[2].tolist()
    assert row[:6] == [0] * 6  # before the return and the return's own cell
    assert row[6:13] == [1] * 7 and row[13:] == [0] * 7  # behind it up to 12 cells from the sensor
    assert n == 7 and shadow.sum() == 7  # only along the ray
    shadow[:] = 0
    mark_shadows(shadow, 0.5, 2.5, ends, np.array([True]), 12.0, 2.0)  # at most 2 cells behind the return
    assert shadow[2].tolist()[6:9] == [1, 1, 0]


def test_no_shadow_from_invalid_returns_returns_beyond_reach_or_off_the_grid() -> None:
    shadow = np.zeros((10, 20), np.uint8)
    mark_shadows(shadow, 0.5, 2.5, np.array([[5.5, 2.5]]), np.array([False]), 12.0, 0.0)
    mark_shadows(shadow, 0.5, 2.5, np.array([[15.5, 2.5]]), np.array([True]), 12.0, 0.0)
    assert shadow.sum() == 0
    mark_shadows(shadow, 0.5, 2.5, np.array([[17.5, 2.5]]), np.array([True]), 40.0, 0.0)
    assert shadow[2].tolist()[18:] == [1, 1]  # stops at the grid's edge


def test_hidden_costs_price_only_never_observed_cells() -> None:
    data = np.full((3, 6), COST_UNKNOWN, np.uint8)
    data[:, 0] = COST_FREE  # observed free
    data[1, 3] = COST_LETHAL
    shadow = np.zeros_like(data)
    shadow[:, 0] = 1  # a shadow over an observed cell is no price
    shadow[0, 5] = 1
    costs = hidden_costs(data, shadow, occluded_cost=40)
    assert costs[0, 5] == 40 and costs.sum() == 40
    near = hidden_costs(data, None, near_cost=90, near_cells=3.0)
    assert near[1, 3] == 0  # the obstacle itself is no unknown cell
    assert near[1, 2] == 90 and near[1, 4] == 90  # next to it
    assert near[1, 5] == 60  # 2 cells: 1 - (2 - 1) / 3
    assert near[1, 0] == 0  # observed
    both = hidden_costs(data, shadow, occluded_cost=70, near_cost=90, near_cells=3.0)
    assert both[0, 5] == max(70, near[0, 5])


def test_near_obstacle_costs_fall_to_zero_at_the_distance() -> None:
    data = np.full((1, 8), COST_UNKNOWN, np.uint8)
    data[0, 0] = COST_LETHAL
    assert near_obstacle_costs(data, 100, 4.0).tolist() == [[100, 100, 75, 50, 25, 0, 0, 0]]
    assert near_obstacle_costs(np.full((2, 2), COST_UNKNOWN, np.uint8), 100, 4.0).sum() == 0


def test_write_hidden_raises_lower_and_unknown_master_cells_only() -> None:
    master = np.array([[0, 100, COST_UNKNOWN, COST_LETHAL, 10]], np.uint8)
    write_hidden(master, np.array([[50, 50, 50, 50, 0]], np.uint8))
    assert master.tolist() == [[50, 100, 50, COST_LETHAL, 10]]


# --- the obstacle layer ---------------------------------------------------------------------------


def test_off_by_default_the_layer_and_master_are_as_before() -> None:
    plain, m1 = _layer()
    off, m2 = _layer(occluded_unknown_cost=0, unknown_near_obstacle_cost=0)
    for layer, master in ((plain, m1), (off, m2)):
        layer.add_scan((0.0, 0.0), _wall_scan())
        layer.update_bounds((0.0, 0.0, 0.0))
        layer.update_costs(master)
    assert off.shadow is None and not off.prices_hidden and off.default_value == COST_FREE
    assert plain.grid is not None and off.grid is not None
    assert np.array_equal(plain.grid.data, off.grid.data) and np.array_equal(m1.data, m2.data)


def test_occluded_cells_are_priced_until_a_scan_observes_them() -> None:
    layer, master = _layer(occluded_unknown_cost=80, raytrace_range=2.0)
    layer.add_scan((0.0, 0.0), _wall_scan())
    layer.update_bounds((0.0, 0.0, 0.0))
    layer.update_costs(master)
    assert _at(master, 1.0, 0.0) == COST_LETHAL
    assert _at(master, 0.5, 0.0) == COST_FREE  # seen free in front of the wall
    assert _at(master, 1.5, 0.0) == 80  # behind it, within 2 m of the sensor
    assert _at(master, 2.3, 0.0) == COST_FREE  # never in range: as the master holds it
    assert _at(master, 0.0, 1.5) == COST_FREE  # outside every ray
    assert layer.grid is not None and _at(layer.grid, 1.5, 0.0) == COST_UNKNOWN
    # seen from the side: the cell is observed free and its price goes
    layer.add_scan((1.5, 1.0), np.array([[1.5, -0.8]]), valid=np.array([False]))
    master.data[:] = COST_FREE
    layer.update_costs(master)
    assert _at(master, 1.5, 0.0) == COST_FREE
    assert _at(master, 1.6, 0.0) == 80


def test_add_ranges_casts_the_shadows_add_scan_casts() -> None:
    angles = np.linspace(-0.25, 0.25, 41)
    ranges = np.full(41, 1.2)
    ranges[:5] = np.inf  # no return: clears only, no shadow
    by_scan, _ = _layer(occluded_unknown_cost=50, raytrace_range=2.5, obstacle_range=2.0)
    by_ranges, _ = _layer(occluded_unknown_cost=50, raytrace_range=2.5, obstacle_range=2.0)
    pose = (0.3, -0.2, 0.4)
    dist = np.where(np.isfinite(ranges), ranges, 2.5)
    world = pose[2] + angles
    ends = np.stack([pose[0] + dist * np.cos(world), pose[1] + dist * np.sin(world)], axis=1)
    by_scan.add_scan(pose[:2], ends, valid=np.isfinite(ranges))
    by_ranges.add_ranges(pose, ranges, (np.cos(angles), np.sin(angles)), (0.1, 30.0, 2.5))
    assert by_scan.shadow is not None and by_ranges.shadow is not None and by_scan.shadow.sum() > 0
    assert by_scan.grid is not None and by_ranges.grid is not None
    assert np.array_equal(by_scan.grid.data, by_ranges.grid.data)
    # the same cells to within the rounding of the two endpoint computations
    assert np.abs(by_scan.shadow.astype(int) - by_ranges.shadow.astype(int)).sum() <= 0.02 * by_scan.shadow.sum()


def test_the_shadow_follows_a_rolling_window_and_is_forgotten_on_reset() -> None:
    layer, master = _layer(occluded_unknown_cost=80, raytrace_range=2.0)
    layer.add_scan((0.0, 0.0), _wall_scan())
    assert layer.shadow is not None
    before = layer.shadow.sum()
    moved = Grid(master.data, RES, (-2.5 + 10 * RES, -2.5, 0.0), "odom")  # the window moves 10 cells along +x
    layer.update_origin(moved)
    assert layer.shadow.sum() == before
    layer.update_bounds((0.0, 0.0, 0.0))
    moved.data[:] = COST_FREE
    layer.update_costs(moved)
    assert _at(moved, 1.5, 0.0) == 80
    layer.reset()
    assert layer.shadow.sum() == 0


def test_near_obstacle_price_in_the_layer() -> None:
    layer, master = _layer(unknown_near_obstacle_cost=100, unknown_near_obstacle_distance=0.5)
    layer.add_scan((0.0, 0.025), np.array([[1.025, 0.025]]))  # cell centres: the return in cell (70, 50)
    layer.update_bounds((-1.0, 0.0, 0.0))
    layer.update_costs(master)
    assert _at(master, 1.025, 0.025) == COST_LETHAL
    assert _at(master, 1.075, 0.025) == 100  # the unknown side next to it
    assert _at(master, 1.175, 0.025) == 80  # 3 cells away: 1 - (3 - 1) / 10
    assert _at(master, 1.025, 0.575) == COST_FREE  # 11 cells away
    assert _at(master, 0.975, 0.025) == COST_FREE  # observed on the ray


@pytest.mark.parametrize("key", ["occluded_unknown_cost", "unknown_near_obstacle_cost"])
def test_prices_above_252_are_refused(key: str) -> None:
    with pytest.raises(NavigationError, match=key):
        ObstacleLayer({key: 253})


@pytest.mark.parametrize("key", ["occluded_unknown_cost", "unknown_near_obstacle_cost"])
def test_the_voxel_layer_refuses_hidden_cell_prices_by_name(key: str) -> None:
    from navlab.navigation.costmap.voxel_layer import VoxelLayer

    with pytest.raises(NavigationError, match=f"voxel_layer: {key} is an obstacle_layer parameter"):
        VoxelLayer({key: 20})
    VoxelLayer({key: 0})  # off: accepted as before
