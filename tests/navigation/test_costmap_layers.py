"""costmap_2d layers: static costs from maps, obstacle marking and ray clearing, inflation against the formula."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, Grid, GridMap
from navlab.navigation import NavigationError
from navlab.navigation.costmap import (
    InflationLayer,
    ObstacleLayer,
    StaticLayer,
    make_footprint,
    parse_polygon,
)

RES = 0.05


def _master(width: int = 100, height: int = 100, origin: tuple[float, float] = (-2.5, -2.5), fill: int = 0) -> Grid:
    return Grid(np.full((height, width), fill, np.uint8), RES, (origin[0], origin[1], 0.0), "map")


def _one_row_map() -> GridMap:
    return GridMap(np.array([[-1, 0, 20, 50, 65, 99, 100]], np.int8), RES)


# --- static layer -------------------------------------------------------------------------------


def test_static_trinary_without_tracking_unknown_maps_unknown_to_free() -> None:
    layer = StaticLayer()
    assert layer.interpret(_one_row_map().data).tolist() == [[0, 0, 0, 0, 0, 0, 254]]


def test_static_trinary_with_tracking_unknown_and_lower_threshold() -> None:
    layer = StaticLayer({"track_unknown_space": True, "lethal_cost_threshold": 65})
    assert layer.interpret(_one_row_map().data).tolist() == [[255, 0, 0, 0, 254, 254, 254]]


def test_static_percentages_scale_to_lethal() -> None:
    layer = StaticLayer({"trinary_costmap": False, "track_unknown_space": True})
    # value / 100 * 254, truncated, as costmap_2d's interpretValue
    assert layer.interpret(_one_row_map().data).tolist() == [[255, 0, 50, 127, 165, 251, 254]]


def test_static_layer_writes_the_map_into_a_master_in_world_coordinates() -> None:
    grid = GridMap.empty(20, 10, RES, (1.0, 2.0, 0.0), fill=0)
    grid.data[5, 7] = 100
    grid.data[0, 0] = -1
    layer = StaticLayer({"track_unknown_space": True})
    layer.set_map(grid)
    master = _master(100, 100, (0.0, 0.0))
    layer.update_costs(master)
    wall = grid.cell_to_world(np.array([[7, 5]]))
    assert master.value_at(wall, outside=COST_UNKNOWN)[0] == COST_LETHAL
    assert master.value_at(grid.cell_to_world(np.array([[0, 0]])), outside=COST_UNKNOWN)[0] == COST_UNKNOWN
    assert (master.data == COST_LETHAL).sum() == 1
    assert master.value_at(np.array([[0.5, 0.5]]), outside=COST_UNKNOWN)[0] == 0  # outside the map: untouched


# --- obstacle layer -----------------------------------------------------------------------------


def _obstacle_layer(**params: object) -> tuple[ObstacleLayer, Grid]:
    master = _master()
    layer = ObstacleLayer(dict(params), footprint=make_footprint(robot_radius=0.1, footprint_padding=0.0))
    layer.match_size(master)
    return layer, master


def _cost(layer: ObstacleLayer, x: float, y: float) -> int:
    assert layer.grid is not None
    return int(layer.grid.value_at(np.array([[x, y]]), outside=COST_UNKNOWN)[0])


def test_obstacle_marks_only_within_obstacle_range() -> None:
    layer, _ = _obstacle_layer()
    layer.add_scan((0.0, 0.0), np.array([[1.0, 0.0], [0.0, 2.4], [1.9, 1.8], [0.0, -2.45]]))
    assert _cost(layer, 1.0, 0.0) == COST_LETHAL
    assert _cost(layer, 0.0, 2.4) == COST_LETHAL
    assert _cost(layer, 1.9, 1.8) == 0  # 2.62 m: beyond the default obstacle_range 2.5 m
    assert _cost(layer, 0.0, -2.45) == COST_LETHAL


def test_obstacle_range_limits_marking() -> None:
    layer, _ = _obstacle_layer(obstacle_range=1.5)
    layer.add_scan((0.0, 0.0), np.array([[1.2, 0.0], [0.0, 1.8]]))
    assert _cost(layer, 1.2, 0.0) == COST_LETHAL
    assert _cost(layer, 0.0, 1.8) == 0


def test_a_moved_obstacle_is_cleared_by_the_rays_that_pass_through_it() -> None:
    layer, _ = _obstacle_layer(track_unknown_space=True)
    ang = np.linspace(-0.3, 0.3, 61)
    layer.add_scan((0.0, 0.0), np.stack([1.0 * np.cos(ang), 1.0 * np.sin(ang)], axis=1))
    assert _cost(layer, 1.0, 0.0) == COST_LETHAL
    assert _cost(layer, 0.5, 0.0) == 0  # cleared along the ray
    assert _cost(layer, -0.5, 0.0) == COST_UNKNOWN  # never seen
    # the obstacle moves back to 2 m: the old cells lie on the new rays and disappear
    layer.add_scan((0.0, 0.0), np.stack([2.0 * np.cos(ang), 2.0 * np.sin(ang)], axis=1))
    assert _cost(layer, 1.0, 0.0) == 0
    assert _cost(layer, 2.0, 0.0) == COST_LETHAL


def test_max_range_rays_clear_without_marking_and_clearing_stops_at_raytrace_range() -> None:
    layer, _ = _obstacle_layer(raytrace_range=1.0)
    layer.add_scan((0.0, 0.0), np.array([[0.6, 0.0], [1.5, 0.0]]))
    assert _cost(layer, 0.6, 0.0) == COST_LETHAL and _cost(layer, 1.5, 0.0) == COST_LETHAL
    # a no-return ray along +x, projected to 2.4 m: clears up to raytrace_range (1 m), marks nothing
    layer.add_scan((0.0, 0.0), np.array([[2.4, 0.0]]), valid=np.array([False]))
    assert _cost(layer, 0.6, 0.0) == 0
    assert _cost(layer, 1.5, 0.0) == COST_LETHAL
    assert _cost(layer, 2.4, 0.0) == 0


def test_observation_source_settings_apply() -> None:
    from navlab.navigation.costmap import ObservationSource

    master = _master()
    layer = ObstacleLayer(sources={"mark_only": ObservationSource(marking=True, clearing=False, obstacle_range=3.0)})
    layer.match_size(master)
    layer.add_scan((0.0, 0.0), np.array([[1.0, 0.0]]))
    layer.add_scan((0.0, 0.0), np.array([[2.0, 0.0]]), source="mark_only")
    assert _cost(layer, 1.0, 0.0) == COST_LETHAL  # not cleared by a marking-only source
    with pytest.raises(NavigationError, match="unknown observation source 'lidar'"):
        layer.add_scan((0.0, 0.0), np.array([[1.0, 0.0]]), source="lidar")


def test_footprint_is_cleared_under_the_robot_and_max_combines_into_the_master() -> None:
    layer, master = _obstacle_layer()
    layer.add_scan((-1.0, 0.0), np.array([[0.0, 0.0], [0.05, 0.0], [0.5, 0.5]]))
    layer.update_bounds((0.0, 0.0, 0.0))
    i, j = master.world_to_cell(np.array([[1.0, 1.0]]))[0]
    master.data[j, i] = 100
    layer.update_costs(master)
    assert master.value_at(np.array([[0.0, 0.0], [0.05, 0.0]]), outside=COST_UNKNOWN).tolist() == [0, 0]
    assert master.value_at(np.array([[0.5, 0.5]]), outside=COST_UNKNOWN)[0] == COST_LETHAL
    # a free layer cell does not lower the master
    assert master.value_at(np.array([[1.0, 1.0]]), outside=COST_UNKNOWN)[0] == 100


# --- inflation ----------------------------------------------------------------------------------


def test_inflation_costs_follow_the_costmap_2d_formula() -> None:
    inscribed, radius, factor = 0.2, 0.6, 3.0
    layer = InflationLayer(
        {"inflation_radius": radius, "cost_scaling_factor": factor},
        footprint=make_footprint(robot_radius=inscribed, footprint_padding=0.0),
    )
    master = _master(81, 81, (0.0, 0.0))
    master.data[40, 40] = COST_LETHAL
    layer.update_costs(master)

    def expected(d: float) -> int:
        if d == 0:
            return COST_LETHAL
        if d <= inscribed:
            return COST_INSCRIBED
        if d > radius + 1e-9:  # a cell at exactly inflation_radius is inflated
            return 0
        return math.floor(252 * math.exp(-factor * (d - inscribed)))

    for di, dj in [(0, 0), (1, 0), (4, 0), (3, 4), (5, 0), (6, 0), (7, 7), (10, 0), (12, 0), (13, 0), (9, 9)]:
        d = math.hypot(di, dj) * RES
        assert master.data[40 + dj, 40 + di] == expected(d), (di, dj, d)
    assert master.data[40, 45] == 216  # 0.25 m: floor(252 * exp(-3 * 0.05))


def test_inflation_leaves_unknown_cells_unless_inscribed() -> None:
    layer = InflationLayer({"inflation_radius": 0.5}, footprint=make_footprint(robot_radius=0.1, footprint_padding=0))
    master = _master(30, 1, (0.0, 0.0), fill=COST_UNKNOWN)
    master.data[0, 0] = COST_LETHAL
    layer.update_costs(master)
    assert master.data[0, :4].tolist() == [COST_LETHAL, COST_INSCRIBED, COST_INSCRIBED, COST_UNKNOWN]
    layer = InflationLayer(
        {"inflation_radius": 0.5, "inflate_unknown": True},
        footprint=make_footprint(robot_radius=0.1, footprint_padding=0),
    )
    master = _master(30, 1, (0.0, 0.0), fill=COST_UNKNOWN)
    master.data[0, 0] = COST_LETHAL
    layer.update_costs(master)
    assert 0 < master.data[0, 3] < COST_INSCRIBED
    assert master.data[0, 20] == COST_UNKNOWN


def test_inflation_keeps_the_higher_cost() -> None:
    layer = InflationLayer({"inflation_radius": 0.3}, footprint=make_footprint(robot_radius=0.1, footprint_padding=0))
    master = _master(20, 1, (0.0, 0.0))
    master.data[0, 0] = COST_LETHAL
    master.data[0, 4] = 250
    layer.update_costs(master)
    assert master.data[0, 4] == 250
    assert master.data[0, 10] == 0


# --- footprints ---------------------------------------------------------------------------------


def test_square_footprint_radii_and_padding() -> None:
    square = [[0.2, 0.2], [0.2, -0.2], [-0.2, -0.2], [-0.2, 0.2]]
    fp = make_footprint(footprint=square, footprint_padding=0.0)
    assert fp.inscribed_radius == pytest.approx(0.2)
    assert fp.circumscribed_radius == pytest.approx(0.2 * math.sqrt(2))
    padded = make_footprint(footprint=square)  # ROS default padding 0.01
    assert padded.inscribed_radius == pytest.approx(0.21)
    rect = make_footprint(footprint=[[0.3, 0.1], [0.3, -0.1], [-0.1, -0.1], [-0.1, 0.1]], footprint_padding=0.0)
    assert rect.inscribed_radius == pytest.approx(0.1)
    assert rect.circumscribed_radius == pytest.approx(math.hypot(0.3, 0.1))


def test_footprint_string_form_and_circle() -> None:
    text = "[[0.2, 0.2], [0.2, -0.2], [-0.2, -0.2], [-0.2, 0.2]]"
    assert parse_polygon(text).tolist() == [[0.2, 0.2], [0.2, -0.2], [-0.2, -0.2], [-0.2, 0.2]]  # type: ignore[union-attr]
    assert parse_polygon("[]") is None
    circle = make_footprint(robot_radius=0.2, footprint="[]")
    assert circle.inscribed_radius == pytest.approx(0.21) and circle.circumscribed_radius == pytest.approx(0.21)


@pytest.mark.parametrize(
    ("value", "match"),
    [
        ("[[0.2, 0.2], [0.2, -0.2]]", "at least 3 points"),
        ("[[0.2, 0.2], [0.2, -0.2], [oops]]", "list of \\[x, y\\] points"),
        ([[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]], "centre \\(0, 0\\) must lie inside"),
    ],
)
def test_bad_footprints_are_refused(value: object, match: str) -> None:
    with pytest.raises(NavigationError, match=match):
        make_footprint(footprint=value)


def test_footprint_cells_cover_the_polygon_at_a_pose() -> None:
    fp = make_footprint(footprint=[[0.3, 0.1], [0.3, -0.1], [-0.1, -0.1], [-0.1, 0.1]], footprint_padding=0.0)
    grid = _master(60, 60, (-1.5, -1.5))
    cells = fp.cells(grid, (0.0, 0.0, math.pi / 2))  # long side now along +y
    xy = grid.cell_to_world(cells)
    assert xy[:, 1].max() > 0.2 and xy[:, 0].max() < 0.11
    assert len(cells) == pytest.approx(0.4 * 0.2 / RES**2, rel=0.3)
