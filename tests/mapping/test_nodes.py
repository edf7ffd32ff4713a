"""map_server and slam_gmapping nodes, driven by synthetic scans and tf odometry (no simulator needed)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab import msgs
from navlab.core import Context, Executor, Node
from navlab.geometry import compose2, inverse2
from navlab.mapping import GridMap, MappingError, save_map
from navlab.mapping.map_server import MapServer
from navlab.mapping.slam_node import SlamGMapping


class _Listener(Node):
    def __init__(self, executor: Executor) -> None:
        super().__init__("listener", context=Context(executor))
        self.maps: list = []
        self.paths: list = []
        self.create_subscription(msgs.OccupancyGrid, "/map", self.maps.append, 1)
        self.create_subscription(msgs.Path, "/trajectory", self.paths.append, 1)


class _FakeRobot(Node):
    """Replays a route at 10 Hz: tf odom→base_link from drifting odometry, base_link→laser static, scans."""

    LASER = (0.1, 0.0, 0.0)  # laser 10 cm ahead of base_link

    def __init__(self, executor: Executor, world, gt: np.ndarray, odo: np.ndarray, rng) -> None:
        super().__init__("fake_robot", context=Context(executor))
        self.world, self.gt, self.odo, self.rng = world, gt, odo, rng
        self.k = 0
        self.scan_pub = self.create_publisher(msgs.LaserScan, "/mybot/laser/scan", 10)
        self.send_static_transform(msgs.transform_stamped(0, "base_link", "laser", *self.LASER))
        self.create_timer(0.1, self.step)

    def step(self) -> None:
        if self.k >= len(self.gt):
            return
        t = self.get_clock().now_ns()
        # gt/odo are laser poses; base = laser ∘ LASER^-1
        base_odo = compose2(self.odo[self.k], inverse2(self.LASER))
        self.send_transform(msgs.transform_stamped(t, "odom", "base_link", *base_odo))
        ranges = self.world.scan(self.gt[self.k], self.rng)
        ranges = np.where(ranges > 29.0, np.inf, ranges).astype(np.float32)
        self.scan_pub.publish(
            msgs.LaserScan(
                header=msgs.header(t, "laser"),
                angle_min=self.world.angle_min,
                angle_max=self.world.angle_min + self.world.angle_increment * (self.world.n - 1),
                angle_increment=self.world.angle_increment,
                time_increment=0.0,
                scan_time=0.1,
                range_min=0.1,
                range_max=30.0,
                ranges=ranges,
                intensities=np.zeros(0, np.float32),
            )
        )
        self.k += 1


def test_map_server_publishes_latched_map(tmp_path):
    data = np.full((20, 30), -1, np.int8)
    data[5:15, 5:25] = 0
    data[5, 5:25] = 100
    save_map(GridMap(data, 0.1, (-1.0, -2.0, 0.0)), tmp_path / "room.yaml")
    ex = Executor(seed=0)
    MapServer(ex, parameters={"yaml_filename": str(tmp_path / "room.yaml")})
    ex.run(0.5)
    late = _Listener(ex)  # subscribes after the map was published: latched delivery
    ex.run(0.5)
    assert len(late.maps) == 1
    got = GridMap.from_msg(late.maps[0])
    np.testing.assert_array_equal(got.data, data)
    assert got.origin == pytest.approx((-1.0, -2.0, 0.0)) and late.maps[0].header.frame_id == "map"
    assert ex.call_service("/static_map").info.width == 30


def test_map_server_errors_name_the_problem(tmp_path):
    ex = Executor(seed=0)
    with pytest.raises(MappingError, match="yaml_filename"):
        MapServer(ex)
    with pytest.raises(MappingError, match=r"nope\.yaml"):
        MapServer(ex, name="m2", parameters={"yaml_filename": str(tmp_path / "nope.yaml")})


@pytest.mark.parametrize("mode", ["gmapping", "graph"])
def test_slam_node_maps_the_room_and_corrects_odometry(synth_world, odometry_noise, mode):
    rng = np.random.default_rng(5)
    gt = synth_world.route()[:200]
    odo = odometry_noise(gt, rng)
    ex = Executor(seed=1)
    params = {
        "scan_topic": "/mybot/laser/scan",
        "map_update_interval": 2.0,
        "linearUpdate": 0.3,
        "angularUpdate": 0.2,
        "mode": mode,
        "particles": 15,
    }
    if mode == "graph":
        params.update({"linearUpdate": 0.1, "angularUpdate": 0.1})
    slam = SlamGMapping(ex, parameters=params)
    robot = _FakeRobot(ex, synth_world, gt, odo, rng)
    listener = _Listener(ex)
    ex.run(len(gt) * 0.1 + 0.05)
    assert robot.k == len(gt) and slam.scans_processed > 10
    assert listener.maps and listener.paths
    # tf map→odom corrects the odometry: map_T_laser close to the truth at the end
    t, odo_last = ex.now_ns, odo[-1]
    m_T_o = ex.tf.lookup_pose2d("map", "odom")
    est = compose2(m_T_o, odo_last)
    assert math.hypot(est[0] - gt[-1][0], est[1] - gt[-1][1]) < 0.1 < math.hypot(*(odo_last - gt[-1])[:2])
    assert t > 0
    # the map's occupied cells lie on the true walls (within two cells), in the map frame = start frame
    slam.publish_map()
    grid = GridMap.from_msg(listener.maps[-1])
    occ = grid.cell_to_world(np.argwhere(grid.occupied_mask())[:, ::-1])
    assert len(occ) > 300
    d = _dist_to_walls(synth_world, occ)
    assert np.mean(d < 2 * grid.resolution) > 0.9
    assert len(listener.paths[-1].poses) == slam.scans_processed


def _dist_to_walls(world, pts: np.ndarray) -> np.ndarray:
    a, b = world.a[None], world.b[None]
    ab = b - a
    t = np.clip(np.einsum("nmk,nmk->nm", pts[:, None] - a, ab) / np.einsum("nmk,nmk->nm", ab, ab), 0, 1)
    proj = a + t[..., None] * ab
    return np.linalg.norm(pts[:, None] - proj, axis=2).min(axis=1)
