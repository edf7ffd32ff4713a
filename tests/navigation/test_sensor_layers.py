"""costmap_2d's VoxelLayer, range_sensor_layer's RangeSensorLayer and pointcloud_to_laserscan."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.core import Context
from navlab.grid import COST_FREE, COST_LETHAL, COST_UNKNOWN, Grid
from navlab.navigation.costmap.layered import LayeredCostmap
from navlab.navigation.costmap.params import ObservationSource
from navlab.navigation.costmap.range_sensor_layer import RangeSensorLayer
from navlab.navigation.costmap.voxel_layer import VoxelLayer
from navlab.navigation.errors import NavigationError
from navlab.navigation.pointcloud_to_laserscan import flatten


def _master(size: int = 60, value: int = COST_FREE) -> Grid:
    return Grid(np.full((size, size), value, np.uint8), 0.1, (-3.0, -3.0, 0.0), "odom")


def _cell(g: Grid, x: float, y: float) -> int:
    i, j = g.world_to_cell(np.array([[x, y]]))[0]
    return int(g.data[j, i])


def _voxel(**src: float) -> VoxelLayer:
    source = ObservationSource(data_type="PointCloud2", marking=True, clearing=True, **src)
    layer = VoxelLayer(
        {"z_resolution": 0.1, "z_voxels": 10, "track_unknown_space": True},
        name="obstacle_layer",
        sources={"cloud": source},
    )
    layer.match_size(_master())
    return layer


def test_voxel_layer_marks_in_3d_and_keeps_a_low_box_under_a_clearing_ray() -> None:
    layer = _voxel(min_obstacle_height=0.05, max_obstacle_height=0.5)
    # a low box top at (1, 0, 0.1), a point above the robot (table top) at (1.5, 0.5, 0.8), floor at (2.05, -1.05, 0)
    layer.add_cloud((0.0, 0.0, 0.3), np.array([[1.0, 0.0, 0.1], [1.5, 0.5, 0.8], [2.05, -1.05, 0.0]]), source="cloud")
    g = layer.grid
    assert _cell(g, 1.0, 0.0) == COST_LETHAL
    assert _cell(g, 1.5, 0.5) == COST_FREE  # above max_obstacle_height: not marked, its ray cleared
    assert _cell(g, 2.05, -1.05) == COST_FREE and _cell(g, 1.05, -0.54) == COST_FREE  # the floor ray cleared
    assert _cell(g, -2.0, 2.0) == COST_UNKNOWN  # never seen
    # a laser plane at 0.3 m passes over the box: it clears its voxels at 0.3 m, the box's column stays marked
    layer.add_cloud((0.0, 0.0, 0.3), np.array([[2.5, 0.0, 0.3]]), source="cloud")
    assert _cell(layer.grid, 1.0, 0.0) == COST_LETHAL and _cell(layer.grid, 2.0, 0.0) == COST_FREE
    # the box goes: a ray to the floor behind it clears its voxel, then the column is free
    layer.add_cloud((0.0, 0.0, 0.3), np.array([[1.5, 0.0, 0.0]]), source="cloud")
    assert _cell(layer.grid, 1.0, 0.0) == COST_FREE
    assert len(layer.marked_voxels()) == 0


def test_voxel_layer_from_costmap_params_and_into_the_master() -> None:
    params = {
        "global_frame": "odom",
        "robot_base_frame": "base",
        "static_map": False,
        "rolling_window": True,
        "width": 6.0,
        "height": 6.0,
        "resolution": 0.1,
        "robot_radius": 0.2,
        "plugins": [
            {"name": "obstacle_layer", "type": "costmap_2d::VoxelLayer"},
            {"name": "inflation_layer", "type": "costmap_2d::InflationLayer"},
        ],
        "obstacle_layer": {
            "observation_sources": "cam",
            "z_voxels": 16,
            "origin_z": 0.0,
            "z_resolution": 0.05,
            "cam": {"data_type": "PointCloud2", "topic": "points", "clearing": True},
        },
    }
    layered = LayeredCostmap(params)
    voxel = layered.layer("obstacle_layer")
    assert isinstance(voxel, VoxelLayer) and voxel.params.z_voxels == 16 and voxel.z_top == pytest.approx(0.8)
    voxel.add_cloud((0.0, 0.0, 0.2), np.array([[1.0, 1.0, 0.1]]), source="cam")
    grid = layered.update_map((0.0, 0.0, 0.0))
    assert _cell(grid, 1.0, 1.0) == COST_LETHAL and 0 < _cell(grid, 1.25, 1.0) < COST_LETHAL  # inflated around it
    with pytest.raises(NavigationError, match=r"z_voxels: expected <= 16, got 20"):
        LayeredCostmap({**params, "obstacle_layer": {**params["obstacle_layer"], "z_voxels": 20}})


def test_voxel_layer_keeps_its_voxels_in_place_when_the_window_rolls_and_takes_no_2d_scans() -> None:
    params = {
        "global_frame": "odom",
        "static_map": False,
        "rolling_window": True,
        "width": 4.0,
        "height": 4.0,
        "resolution": 0.1,
        "robot_radius": 0.2,
        "plugins": [
            {"name": "obstacle_layer", "type": "costmap_2d::ObstacleLayer"},
            {"name": "voxel_layer", "type": "costmap_2d::VoxelLayer"},
        ],
        "voxel_layer": {"z_voxels": 10, "z_resolution": 0.1, "cam": {"data_type": "PointCloud2", "clearing": True}},
        "voxel_layer.observation_sources": "cam",
    }
    layered = LayeredCostmap(params)
    voxel = layered.layer("voxel_layer")
    assert isinstance(voxel, VoxelLayer) and [x.name for x in layered.scan_layers] == ["obstacle_layer"]
    layered.update_map((0.0, 0.0, 0.0))
    voxel.add_cloud((0.0, 0.0, 0.3), np.array([[1.05, 0.55, 0.25]]), source="cam")
    layered.add_scan((0.0, 0.0), np.array([[-1.05, -0.55]]))  # 2-D scans: the obstacle layer only
    grid = layered.update_map((0.0, 0.0, 0.0))
    assert _cell(grid, 1.05, 0.55) == COST_LETHAL and _cell(grid, -1.05, -0.55) == COST_LETHAL
    assert _cell(voxel.grid, -1.05, -0.55) != COST_LETHAL
    grid = layered.update_map((0.73, 0.41, 0.0))  # the window moves by whole cells; what it still covers stays
    assert grid.origin[:2] == pytest.approx((-1.3, -1.6))
    assert _cell(grid, 1.05, 0.55) == COST_LETHAL and _cell(grid, -1.05, -0.55) == COST_LETHAL
    marked = voxel.marked_voxels()
    assert marked.shape == (1, 3) and marked[0] == pytest.approx((1.05, 0.55, 0.25))


def test_range_sensor_layer_marks_the_reading_and_clears_short_of_it() -> None:
    layer = RangeSensorLayer({"topics": ["/sonar_front"], "clear_on_max_reading": True}, name="sonar")
    assert layer.topics == ["/sonar_front"] and layer.params.phi == 1.2 and layer.params.mark_threshold == 0.8
    master = _master(value=COST_UNKNOWN)
    layer.match_size(master)
    for _ in range(5):  # repeated readings of a wall 1.5 m ahead in a 0.3 rad cone
        layer.add_range((0.0, 0.0, 0.0), 1.5, field_of_view=0.3, min_range=0.02, max_range=4.0)
    layer.update_costs(master)
    assert _cell(master, 1.5, 0.0) == COST_LETHAL
    assert _cell(master, 0.8, 0.0) == COST_FREE  # short of the reading, on the axis
    assert _cell(master, 0.8, 0.6) == COST_UNKNOWN  # outside the cone: untouched
    assert _cell(master, -1.0, 0.0) == COST_UNKNOWN  # behind the sensor
    # max readings clear (clear_on_max_reading) the cone, the earlier wall fades
    for _ in range(10):
        layer.add_range((0.0, 0.0, 0.0), 4.0, field_of_view=0.3, min_range=0.02, max_range=4.0)
    master.data[:] = COST_UNKNOWN
    layer.update_costs(master)
    assert _cell(master, 1.5, 0.0) != COST_LETHAL


def test_pointcloud_to_laserscan_keeps_the_nearest_point_per_bin_between_heights() -> None:
    pts = np.array(
        [
            [1.0, 0.0, 0.2],
            [0.5, 0.0, 0.2],
            [0.3, 0.0, 2.0],  # same bin: nearest in band wins
            [0.0, 2.0, 0.1],
            [np.nan, 0.0, 0.1],
            [-1.0, 0.0, -0.5],
        ]
    )
    r = flatten(
        pts,
        angle_min=-math.pi,
        angle_max=math.pi,
        angle_increment=math.pi / 180,
        min_height=0.0,
        max_height=1.0,
        range_min=0.0,
        range_max=10.0,
        fill=math.inf,
    )
    assert len(r) == 360
    assert r[180] == pytest.approx(0.5)  # angle 0
    assert r[270] == pytest.approx(2.0)  # angle pi/2
    assert np.isinf(r[0]) and np.isinf(r[100])  # the point below min_height and empty bins: inf (use_inf)


def test_voxel_grid_message_packs_the_columns() -> None:
    layer = _voxel(min_obstacle_height=0.0, max_obstacle_height=2.0)
    layer.add_cloud((0.0, 0.0, 0.3), np.array([[1.05, 0.05, 0.25]]), source="cloud")
    msg = layer.voxel_grid_msg(0)
    assert (msg.size_x, msg.size_y, msg.size_z) == (60, 60, 10) and msg.resolutions.z == pytest.approx(0.1)
    i, j = layer.grid.world_to_cell(np.array([[1.05, 0.05]]))[0]
    column = int(msg.data[j * 60 + i])
    assert column >> 16 == 1 << 2 and column & (1 << 2)  # voxel 2 (0.2 .. 0.3 m) marked: both of its bits set
    assert column & 0xFFFF == 0xFFFF  # the others unknown (their low bit only), none cleared: no ray crossed them


def test_layers_build_from_params_with_a_context() -> None:
    from types import SimpleNamespace

    from navlab.navigation.costmap.params import costmap_params

    costmap = costmap_params(
        {"static_map": False, "observation_sources": "cam", "cam": {"data_type": "PointCloud2", "topic": "points"}}
    )
    ctx = SimpleNamespace(name="voxels", costmap=costmap, footprint=None)
    voxel = VoxelLayer.from_params({"z_voxels": 4, "origin_z": -0.1}, context=ctx)
    assert (voxel.name, voxel.params.z_voxels, voxel.params.origin_z, list(voxel.sources)) == (
        "voxels",
        4,
        -0.1,
        ["cam"],
    )
    sonar = RangeSensorLayer.from_params(
        {"topics": ["/sonar_left", "/sonar_right"], "phi": 1.0},
        context=SimpleNamespace(name="sonar", costmap=costmap, footprint=None),
    )
    assert sonar.topics == ["/sonar_left", "/sonar_right"] and sonar.params.phi == 1.0
    with pytest.raises(NavigationError, match="clear_threshold"):
        RangeSensorLayer.from_params({"clear_threshold": 0.9}, context=ctx)


def test_pointcloud_to_laserscan_node_publishes_a_scan_in_the_target_frame() -> None:
    from navlab import msgs
    from navlab.core import Executor, Node
    from navlab.io.pointcloud import FLOAT32, pack_cloud
    from navlab.navigation.pointcloud_to_laserscan import PointCloudToLaserScan

    class Probe(Node):
        def __init__(self, ex: Executor) -> None:
            super().__init__("probe", context=Context(ex))
            self.scans: list = []
            self.pub = self.create_publisher(msgs.PointCloud2, "cloud_in", 1)
            self.create_subscription(msgs.LaserScan, "scan", self.scans.append, 1)

    ex = Executor(seed=0)
    # the cloud's frame 'cam' sits 0.5 m ahead of base_link, turned 90 degrees left
    ex.tf.set_transform(
        "base_link", "cam", 0, (0.5, 0.0, 0.0, 0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)), static=True
    )
    PointCloudToLaserScan(
        ex,
        parameters={
            "target_frame": "base_link",
            "min_height": -0.1,
            "max_height": 0.1,
            "use_inf": False,
            "range_max": 10.0,
        },
    )
    probe = Probe(ex)
    pts = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 1.0]], np.float32)  # 1 m ahead of cam: (0.5, 1.0) in base_link
    probe.pub.publish(
        pack_cloud(0, "cam", {"x": (0, FLOAT32, pts[:, 0]), "y": (4, FLOAT32, pts[:, 1]), "z": (8, FLOAT32, pts[:, 2])})
    )
    ex.run(0.01)
    (scan,) = probe.scans
    r = np.asarray(scan.ranges)
    assert scan.header.frame_id == "base_link" and len(r) == 360
    k = int((math.atan2(1.0, 0.5) + math.pi) / (math.pi / 180))
    assert r[k] == pytest.approx(math.hypot(0.5, 1.0), abs=1e-5)
    assert np.sum(r < 10.0) == 1 and r[0] == pytest.approx(11.0)  # empty bins: range_max + inf_epsilon (use_inf false)
