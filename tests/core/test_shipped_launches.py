"""The shipped mapping and localization launches start, run a few simulated seconds and do their job."""

from __future__ import annotations

import math
from dataclasses import fields

import numpy as np
import pytest
from scipy import ndimage

from navlab import msgs
from navlab.cli import main
from navlab.core import Context, LaunchError, Node, load_params
from navlab.core.launch import resources_dir, start
from navlab.drivers import RouteFollower
from navlab.mapping import GridMap, save_map
from navlab.mapping.gmapping import GMappingParams
from navlab.world import load_world, true_map


class _Recorder(Node):
    """Keeps the latest map, every amcl_pose and the latest true pose."""

    def __init__(self, executor) -> None:
        super().__init__("test_recorder", context=Context(executor))
        self.maps: list = []
        self.amcl: list = []
        self.truth: tuple[float, float, float] | None = None
        self.create_subscription(msgs.OccupancyGrid, "/map", self.maps.append, 1)
        self.create_subscription(msgs.PoseWithCovarianceStamped, "/amcl_pose", self.amcl.append, 10)
        self.create_subscription(msgs.Odometry, "/ground_truth/odom", self._truth, 1)

    def _truth(self, msg) -> None:
        self.truth = msgs.pose2d(msg.pose.pose)


def test_gmapping_params_file_is_slam_gmapping_defaults_plus_small_room_tuning():
    shipped = load_params(resources_dir() / "params" / "gmapping.yaml")
    defaults = {f.name: f.default for f in fields(GMappingParams)}
    assert set(defaults) <= set(shipped)
    changed = {k for k, v in shipped.items() if k in defaults and v != defaults[k]}
    assert changed == {"lskip", "linearUpdate", "angularUpdate", "temporalUpdate"}


def test_mapping_launch_builds_a_map_while_exploring():
    s = start("mapping")
    rec = _Recorder(s.executor)
    s.run(8.0)
    assert {"/gazebo", "/slam_gmapping", "/explore"} <= set(s.nodes)
    slam = s.node("slam_gmapping")
    assert slam.base_frame == "chassis" and slam.params.lskip == 4  # launch param + params/gmapping.yaml
    assert rec.maps, "no /map published"
    grid = GridMap.from_msg(rec.maps[-1])
    assert rec.maps[-1].header.frame_id == "map"
    occupied = grid.data >= 65  # map_server's occupied_thresh
    assert occupied.sum() > 100 and ((grid.data >= 0) & (grid.data < 25)).sum() > 1000
    # the walls it saw are where the world's walls are (within 2 cells)
    truth = true_map(load_world("room"), (0.0, 0.0))
    dist = ndimage.distance_transform_edt(truth.data != 100) * truth.resolution
    rows, cols = np.nonzero(occupied)
    wx = grid.origin[0] + (cols + 0.5) * grid.resolution
    wy = grid.origin[1] + (rows + 0.5) * grid.resolution
    ti = np.clip(((wx - truth.origin[0]) / truth.resolution).astype(int), 0, truth.data.shape[1] - 1)
    tj = np.clip(((wy - truth.origin[1]) / truth.resolution).astype(int), 0, truth.data.shape[0] - 1)
    assert np.mean(dist[tj, ti] <= 0.1) > 0.9
    # exploration drove the robot (cmd_vel → diff_drive), and SLAM tracks it in the map frame
    assert rec.truth is not None and math.hypot(rec.truth[0], rec.truth[1]) > 0.2
    x, y, _ = s.executor.tf.lookup_pose2d("map", "chassis")
    assert math.hypot(x - rec.truth[0], y - rec.truth[1]) < 0.2


def test_mapping_launch_without_exploration_stands_still():
    s = start("mapping", explore="false")
    rec = _Recorder(s.executor)
    s.run(3.0)
    assert "/explore" not in s.nodes and rec.maps
    assert rec.truth is not None and math.hypot(rec.truth[0], rec.truth[1]) < 0.01


@pytest.fixture
def room_map(tmp_path):
    path = tmp_path / "room.yaml"
    save_map(true_map(load_world("room"), (0.0, 0.0)), path)
    return path


def test_localization_launch_tracks_the_robot(room_map):
    s = start("localization", map=str(room_map), x=0.5, y=-0.3, yaw=0.2)
    rec = _Recorder(s.executor)
    amcl = s.node("amcl")
    assert amcl.base_frame == "chassis" and amcl.params.laser_max_beams == 30
    assert amcl.initial_pose == pytest.approx((0.5, -0.3, 0.2))
    RouteFollower(s.executor, parameters={"segments": [{"linear": 0.25, "angular": 0.3, "duration": 6.0}]})
    s.run(7.0)
    assert len(rec.amcl) >= 3 and rec.amcl[-1].header.frame_id == "map"
    est = msgs.pose2d(rec.amcl[-1].pose.pose)
    x, y, yaw = s.executor.tf.lookup_pose2d("map", "chassis")
    assert rec.truth is not None and math.hypot(rec.truth[0] - 0.5, rec.truth[1] + 0.3) > 1.0  # it drove
    assert math.hypot(x - rec.truth[0], y - rec.truth[1]) < 0.15
    assert abs(math.remainder(yaw - rec.truth[2], 2 * math.pi)) < 0.1
    assert math.hypot(est[0] - rec.truth[0], est[1] - rec.truth[1]) < 0.3  # last update, not "now"
    np.testing.assert_array_equal(GridMap.from_msg(rec.maps[-1]).data, GridMap.from_msg(s.node("map_server").msg).data)


def test_localization_launch_needs_a_map():
    with pytest.raises(LaunchError, match="map:=VALUE"):
        start("localization")


def test_cli_launch_and_graph_of_shipped_launches(room_map, tmp_path, capsys):
    assert main(["launch", "mapping", "--duration", "2", "--quiet", "--json"]) == 0
    assert '"/map"' in capsys.readouterr().out
    assert (
        main(["graph", "--launch", "localization", f"map:={room_map}", "--duration", "1", "--out", str(tmp_path / "g")])
        == 0
    )
    dot = (tmp_path / "g" / "graph.dot").read_text()
    assert '"n:/map_server" -> "t:/map"' in dot and '"t:/map" -> "n:/amcl"' in dot
    assert '"n:/amcl" -> "t:/amcl_pose"' in dot
