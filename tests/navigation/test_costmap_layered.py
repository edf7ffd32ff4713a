"""The layered costmap: layers from ROS parameter files, global costmap from a map, rolling window, bad params."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.grid import COST_INSCRIBED, COST_LETHAL, COST_UNKNOWN, GridMap
from navlab.navigation import NavigationError
from navlab.navigation.costmap import InflationLayer, LayeredCostmap, ObstacleLayer, StaticLayer, costmap_params
from navlab.plugins import PluginError

# what a ROS 1 user of the paper's robot writes (costmap_common_params + global_costmap_params)
COMMON = {
    "obstacle_range": 2.5,
    "raytrace_range": 3.0,
    "robot_radius": 0.2,
    "inflation_radius": 0.55,
    "observation_sources": "laser_scan_sensor",
    "laser_scan_sensor": {
        "sensor_frame": "chassis",
        "data_type": "LaserScan",
        "topic": "/mybot/laser/scan",
        "marking": True,
        "clearing": True,
    },
}


def _room() -> GridMap:
    grid = GridMap.empty(80, 60, 0.05, (-1.0, -1.0, 0.0), fill=0)
    grid.data[0, :] = grid.data[-1, :] = grid.data[:, 0] = grid.data[:, -1] = 100
    grid.data[:10, 60:] = -1
    return grid


def _at(cm: LayeredCostmap, x: float, y: float) -> int:
    return int(cm.costmap.value_at(np.array([[x, y]]), outside=COST_UNKNOWN)[0])


def test_pre_hydro_params_give_static_obstacle_inflation_and_the_map_sizes_the_global_costmap() -> None:
    cm = LayeredCostmap({**COMMON, "global_frame": "map", "robot_base_frame": "chassis", "static_map": True})
    assert [type(x) for x in cm.layers] == [StaticLayer, ObstacleLayer, InflationLayer]
    assert cm.params.sources["laser_scan_sensor"].topic == "/mybot/laser/scan"
    grid = _room()
    cm.set_map(grid)
    costs = cm.update_map((1.0, 1.0, 0.0))
    assert costs.data.shape == grid.data.shape and costs.origin == grid.origin and costs.frame_id == "map"
    assert _at(cm, -0.975, 0.5) == COST_LETHAL  # the wall
    assert _at(cm, -0.975 + 0.2, 0.5) == COST_INSCRIBED  # within robot_radius + padding of it
    assert 0 < _at(cm, -0.975 + 0.4, 0.5) < COST_INSCRIBED
    assert _at(cm, 1.0, 1.0) == 0


def test_static_map_false_and_rolling_window_for_a_local_costmap() -> None:
    cm = LayeredCostmap(
        {
            **COMMON,
            "global_frame": "odom",
            "static_map": False,
            "rolling_window": True,
            "width": 3.0,
            "height": 3.0,
            "resolution": 0.05,
        }
    )
    assert [x.name for x in cm.layers] == ["obstacle_layer", "inflation_layer"]
    assert cm.costmap.data.shape == (60, 60) and cm.costmap.frame_id == "odom"
    with pytest.raises(NavigationError, match="no static layer"):
        cm.set_map(_room())


def test_rolling_window_keeps_world_fixed_cells() -> None:
    cm = LayeredCostmap(
        {
            "global_frame": "odom",
            "static_map": False,
            "rolling_window": True,
            "width": 4.0,
            "height": 4.0,
            "robot_radius": 0.1,
            "inflation_radius": 0.0,
        }
    )
    cm.update_map((0.0, 0.0, 0.0))
    assert cm.costmap.origin[:2] == pytest.approx((-2.0, -2.0))
    cm.add_scan((0.0, 0.0), np.array([[1.0, 0.5], [-1.5, -1.5]]))
    cm.update_map((0.0, 0.0, 0.0))
    assert _at(cm, 1.0, 0.5) == COST_LETHAL and _at(cm, -1.5, -1.5) == COST_LETHAL
    cm.update_map((0.73, 0.31, 0.0))  # the window moves by whole cells and re-centres
    assert cm.costmap.origin[:2] == pytest.approx((0.75 - 2.0, 0.3 - 2.0))
    assert _at(cm, 1.0, 0.5) == COST_LETHAL  # same world cell, new grid index
    assert (cm.costmap.data == COST_LETHAL).sum() == 1  # (-1.5, -1.5) left the window
    cm.update_map((0.0, 0.0, 0.0))  # back: the cell that left is forgotten, the other is kept
    assert _at(cm, -1.5, -1.5) == 0 and _at(cm, 1.0, 0.5) == COST_LETHAL


def test_obstacle_on_the_static_map_clears_when_it_moves_but_walls_stay() -> None:
    cm = LayeredCostmap({**COMMON, "inflation_radius": 0.3})
    cm.set_map(_room())
    ang = np.linspace(-np.pi, np.pi, 720, endpoint=False)
    ranges = np.full(720, 1.2)
    ends = np.stack([1.0 + ranges * np.cos(ang), 1.0 + ranges * np.sin(ang)], axis=1)
    cm.add_scan((1.0, 1.0), ends, source="laser_scan_sensor")
    cm.update_map((1.0, 1.0, 0.0))
    assert _at(cm, 2.2, 1.0) == COST_LETHAL
    far = np.stack([1.0 + 1.8 * np.cos(ang), 1.0 + 1.8 * np.sin(ang)], axis=1)  # the ring moved outwards
    cm.add_scan((1.0, 1.0), far, source="laser_scan_sensor")
    cm.update_map((1.0, 1.0, 0.0))
    assert _at(cm, 2.2, 1.0) == 0
    assert _at(cm, 2.8, 1.0) == COST_LETHAL
    assert _at(cm, -0.975, 0.5) == COST_LETHAL  # the static wall beyond the rays is untouched


def test_plugins_list_ros1_and_nav2_styles() -> None:
    ros1 = LayeredCostmap(
        {
            "robot_radius": 0.2,
            "plugins": [
                {"name": "static", "type": "costmap_2d::StaticLayer"},
                {"name": "inflation", "type": "costmap_2d::InflationLayer"},
            ],
            "inflation": {"inflation_radius": 0.3, "cost_scaling_factor": 4.0},
        }
    )
    assert [x.name for x in ros1.layers] == ["static", "inflation"]
    infl = ros1.layer("inflation")
    assert isinstance(infl, InflationLayer) and infl.params.inflation_radius == 0.3
    nav2 = LayeredCostmap(
        {
            "robot_radius": 0.2,
            "plugins": ["obstacle_layer", "inflation_layer"],
            "obstacle_layer": {
                "plugin": "nav2_costmap_2d::ObstacleLayer",
                "observation_sources": "scan",
                "scan": {"topic": "/scan", "obstacle_max_range": 2.0, "clearing": True},
            },
            "inflation_layer.plugin": "nav2_costmap_2d::InflationLayer",
            "inflation_layer.inflation_radius": 0.4,
            "inflation_layer.inflate_around_unknown": True,
        }
    )
    assert [type(x) for x in nav2.layers] == [ObstacleLayer, InflationLayer]
    assert nav2.params.sources["scan"].obstacle_range == 2.0
    infl = nav2.layer("inflation_layer")
    assert isinstance(infl, InflationLayer) and infl.params.inflation_radius == 0.4 and infl.params.inflate_unknown


def test_the_ros_wiki_tutorial_files_load() -> None:
    common = {
        "obstacle_range": 2.5,
        "raytrace_range": 3.0,
        "footprint": "[[0.2, 0.15], [0.2, -0.15], [-0.2, -0.15], [-0.2, 0.15]]",
        "inflation_radius": 0.55,
        "map_type": "voxel",
        "z_voxels": 2,
        "origin_z": 0.0,
        "observation_sources": "laser_scan_sensor",
        "laser_scan_sensor": {
            "sensor_frame": "laser",
            "data_type": "LaserScan",
            "topic": "scan",
            "marking": True,
            "clearing": True,
        },
    }
    local = LayeredCostmap(
        {
            **common,
            "global_frame": "odom",
            "robot_base_frame": "base_link",
            "update_frequency": 5.0,
            "publish_frequency": 2.0,
            "static_map": False,
            "rolling_window": True,
            "width": 6.0,
            "height": 6.0,
            "resolution": 0.05,
        }
    )
    assert local.costmap.data.shape == (120, 120)
    assert local.inscribed_radius == pytest.approx(0.16)  # padded by footprint_padding 0.01
    assert local.circumscribed_radius == pytest.approx(math.hypot(0.21, 0.16))
    glob = LayeredCostmap({**common, "global_frame": "/map", "robot_base_frame": "base_link", "static_map": True})
    assert glob.costmap.frame_id == "map" and isinstance(glob.layers[0], StaticLayer)


def test_track_unknown_space_fills_unknown() -> None:
    cm = LayeredCostmap({**COMMON, "track_unknown_space": True, "inflation_radius": 0.1})
    cm.set_map(_room())
    cm.update_map((1.0, 1.0, 0.0))
    assert _at(cm, 2.5, -0.7) == COST_UNKNOWN  # the map's unknown corner
    cm2 = LayeredCostmap({**COMMON, "inflation_radius": 0.1})
    cm2.set_map(_room())
    cm2.update_map((1.0, 1.0, 0.0))
    assert _at(cm2, 2.5, -0.7) == 0


@pytest.mark.parametrize(
    ("params", "match"),
    [
        ({"inflation_radius": -0.5}, "inflation_radius: expected >= 0, got -0.5"),
        ({"inflation_layer": {"inflation_radius": -1.0}}, "inflation_layer parameter inflation_radius: expected >= 0"),
        ({"inflation_raduis": 0.5}, "did you mean 'inflation_radius'"),
        ({"inflation_layer": {"cost_scaling_factr": 3.0}}, "did you mean 'cost_scaling_factor'"),
        ({"resolution": 0.0}, "resolution: expected > 0"),
        ({"robot_radius": "big"}, "robot_radius: expected a number, got 'big'"),
        (
            {"plugins": [{"name": "inf", "type": "costmap_2d::InflationLayr"}]},
            "did you mean 'costmap_2d::InflationLayer'",
        ),
        ({"observation_sources": "laser"}, "names 'laser' but there is no"),
        ({"obstacle_layer": {"combination_method": 5}}, "combination_method: expected one of 0, 1"),
        (
            {"obstacle_layr": {"enabled": True}},
            "unknown costmap parameter 'obstacle_layr'; did you mean 'obstacle_layer'",
        ),
    ],
)
def test_bad_parameters_get_one_line_errors(params: dict, match: str) -> None:
    with pytest.raises((NavigationError, PluginError), match=match) as info:
        LayeredCostmap(params)
    assert "\n" not in str(info.value)


def test_keys_ros_ignores_warn_and_are_dropped() -> None:
    """Another plugin's key (TrajectoryPlannerROS's meter_scoring) or section (a layer not in plugins): ROS
    ignores them, navlab warns (the launch names the file) and builds the costmap as without them."""
    from navlab.core.params import ParameterWarning

    extra = {"meter_scoring": True, "voxel_layer": {"z_voxels": 4}, "inflation_layer": {"old_key_of_2014": 1}}
    with pytest.warns(ParameterWarning) as caught:
        cm = LayeredCostmap({**COMMON, **extra})
    assert {w.message.key for w in caught if isinstance(w.message, ParameterWarning)} == {
        "meter_scoring",
        "voxel_layer",
        "old_key_of_2014",
    }
    plain = LayeredCostmap(COMMON)
    assert [layer.params for layer in cm.layers] == [layer.params for layer in plain.layers]


def test_nav2_and_ros1_range_names_are_the_same_parameter() -> None:
    p = costmap_params({"obstacle_layer": {"obstacle_max_range": 1.5}})
    assert p.namespaces["obstacle_layer"]["obstacle_max_range"] == 1.5
    cm = LayeredCostmap({"obstacle_layer": {"obstacle_max_range": 1.5, "raytrace_max_range": 2.0}})
    layer = cm.layer("obstacle_layer")
    assert isinstance(layer, ObstacleLayer)
    assert (layer.params.obstacle_range, layer.params.raytrace_range) == (1.5, 2.0)
    with pytest.raises(NavigationError, match="two spellings"):
        LayeredCostmap({"obstacle_layer": {"obstacle_max_range": 1.5, "obstacle_range": 2.0}})


@pytest.mark.parametrize("rolling", [False, True])
def test_a_deferred_update_writes_the_grid_an_eager_one_writes(rolling: bool) -> None:
    """Updates whose master is written only when read (``defer``, the costmap node's timer) give, at every read, the
    grid of updating at once, through scans that mark, the robot's footprint clearing and a rolling
    window's moves; a layer that is not known to write only the master keeps the updates eager."""
    params = {**COMMON, "global_frame": "map", "robot_base_frame": "chassis", "static_map": not rolling}
    params["laser_scan_sensor"] = {**COMMON["laser_scan_sensor"], "clearing": False}  # only the footprint clears
    if rolling:
        params |= {"rolling_window": True, "width": 2.0, "height": 2.0}
    eager, deferred = LayeredCostmap(params), LayeredCostmap(params)
    for cm in (eager, deferred):
        if not rolling:
            cm.set_map(_room())
    rng = np.random.default_rng(4)
    angles = np.linspace(-math.pi, math.pi, 90, endpoint=False)

    def at(step: int) -> tuple[float, float, float]:
        return (-0.6 + 0.12 * step, 0.8 + 0.3 * math.sin(step / 4), 0.1 * step)

    for step in range(28):
        pose = at(step)
        ends = np.column_stack([np.cos(angles), np.sin(angles)]) * rng.uniform(0.3, 1.2, (90, 1)) + pose[:2]
        ends[::15] = np.array(pose[:2]) + rng.uniform(-0.12, 0.12, (6, 2))  # under the robot: its footprint clears them
        for cm in (eager, deferred):  # to the layers, as the costmap node does just before its update
            for layer in cm.scan_targets("laser_scan_sensor"):
                layer.add_scan(pose[:2], ends, source="laser_scan_sensor")
        eager.update_map(pose)
        deferred.update_map(pose, defer=True)
        assert deferred._deferred
        if step % 4 == 3:  # read now and then
            g, want = deferred.costmap, eager.costmap
            assert g.origin == want.origin
            np.testing.assert_array_equal(g.data, want.data)

    class OwnLayer(InflationLayer):  # a plugin's subclass: not known to write only the master
        pass

    deferred.layers[-1].__class__ = OwnLayer
    deferred.update_map((0.5, 0.5, 0.0), defer=True)
    assert not deferred._deferred
