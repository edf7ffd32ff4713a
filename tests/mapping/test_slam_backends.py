"""slam_gmapping's ``mode`` as plugins: registry lookup with "did you mean", the protocol, a new mode in one line."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from navlab import msgs, plugins
from navlab.core import Context, Executor, Node
from navlab.geometry import compose2
from navlab.grid import GridMap
from navlab.mapping import MappingError
from navlab.mapping.backends import GraphBackend
from navlab.mapping.slam import make_slam
from navlab.mapping.slam_node import SlamGMapping
from navlab.plugins import SlamBackend


def _room_scan(n: int = 180) -> tuple[np.ndarray, float, float]:
    """Ranges (m) from the centre of a 4 m × 4 m square room, beams over 360°."""
    inc = 2 * math.pi / n
    a = -math.pi + inc * np.arange(n)
    r = np.minimum(2.0 / np.maximum(np.abs(np.cos(a)), 1e-9), 2.0 / np.maximum(np.abs(np.sin(a)), 1e-9))
    return r, -math.pi, inc


@pytest.mark.parametrize("mode", plugins.plugin_names("slam_backend"))
def test_every_registered_mode_is_a_slam_backend_and_maps_a_room(mode: str) -> None:
    slam = make_slam(mode, seed=0)
    assert isinstance(slam, SlamBackend)
    r, a0, inc = _room_scan()
    for k in range(3):
        slam.add_scan(r, a0, inc, np.array([0.0, 0.0, 0.0]), range_max=10.0, stamp_ns=k * 100_000_000)
    grid = slam.current_map(frame_id="map")
    assert isinstance(grid, GridMap) and grid.frame_id == "map"
    occ = grid.cell_to_world(np.argwhere(grid.occupied_mask())[:, ::-1])
    assert len(occ) > 100
    # occupied cells lie on the walls at |x| = 2 or |y| = 2 m
    assert np.mean(np.abs(np.max(np.abs(occ), axis=1) - 2.0) < 0.1) > 0.9
    assert slam.finish().shape == (3, 3)
    assert all(isinstance(v, int) for v in slam.stats().values())


def test_unknown_mode_says_did_you_mean() -> None:
    with pytest.raises(MappingError, match=r"SLAM mode 'grahp' \(did you mean 'graph'\?"):
        make_slam("grahp")
    with pytest.raises(MappingError, match=r"node /slam_gmapping: unknown mode 'gmaping' \(did you mean 'gmapping'\?"):
        SlamGMapping(Executor(), parameters={"mode": "gmaping"})


def test_graph_mode_takes_its_own_parameters_under_graph() -> None:
    nested = make_slam("graph", {"graph": {"loop_every": 2}, "linearUpdate": 0.4})
    assert isinstance(nested, GraphBackend)
    assert nested.params.loop_every == 2 and nested.gm.linearUpdate == 0.4
    assert make_slam("graph", {"graph.voxel": 0.1}).params.voxel == 0.1
    with pytest.raises(MappingError, match=r"'loop_every' belongs under 'graph' \(graph.loop_every\)"):
        make_slam("graph", {"loop_every": 2})
    node = SlamGMapping(Executor(), parameters={"mode": "graph", "graph": {"loop_every": 3}, "particles": 5})
    assert node.params.loop_every == 3


def test_graph_mode_gates_scans_by_slam_gmappings_update_distances() -> None:
    g = make_slam("graph", {"linearUpdate": 0.5, "angularUpdate": 0.3, "temporalUpdate": 2.0})
    r, a0, inc = _room_scan()
    assert g.due(np.zeros(3), 0)
    g.add_scan(r, a0, inc, np.zeros(3), stamp_ns=0)
    assert not g.due(np.array([0.4, 0.0, 0.0]), 1_000_000_000)
    assert g.due(np.array([0.5, 0.0, 0.0]), 1_000_000_000)
    assert g.due(np.array([0.0, 0.0, 0.31]), 1_000_000_000)
    assert g.due(np.zeros(3), 2_100_000_000)


class _DeadReckoning:
    """A toy mode: trusts odometry, maps nothing but the first scan's origin cell."""

    def __init__(self, params: dict[str, Any] | None = None) -> None:
        self.params = dict(params or {})
        self.poses: list[np.ndarray] = []

    @classmethod
    def from_params(cls, params: dict[str, Any] | None, *, context: plugins.PluginContext) -> _DeadReckoning:
        return cls(params)

    @classmethod
    def parameters(cls) -> dict[str, Any]:
        return {"delta": 0.1}

    def due(self, odom_laser: np.ndarray, stamp_ns: int) -> bool:
        return True

    def add_scan(self, ranges, angle_min, angle_increment, odom_laser, *, range_max=None, stamp_ns=None):
        self.poses.append(np.asarray(odom_laser, dtype=float))
        return self.poses[-1].copy()

    def trajectory(self) -> np.ndarray:
        return np.array(self.poses).reshape(-1, 3)

    def current_map(self, *, frame_id: str = "map") -> GridMap | None:
        return GridMap(np.zeros((4, 4), np.int8), self.params["delta"], (0.0, 0.0, 0.0), frame_id=frame_id)

    def finish(self) -> np.ndarray:
        return self.trajectory()

    def stats(self) -> dict[str, int]:
        return {"scans": len(self.poses)}


def test_a_new_mode_is_one_class_and_one_entry_point(install_plugin_package) -> None:
    install_plugin_package(
        "navlab-test-dead-reckoning", {"navlab.slam_backends": {"dead_reckoning": f"{__name__}:_DeadReckoning"}}
    )
    ex = Executor(seed=0)
    slam = SlamGMapping(ex, parameters={"mode": "dead_reckoning", "delta": 0.2, "map_update_interval": 0.0})
    assert slam.params == {"delta": 0.2}
    robot = Node("robot", context=Context(ex))
    scans = robot.create_publisher(msgs.LaserScan, "scan")
    robot.send_static_transform(msgs.transform_stamped(0, "base_link", "laser", 0.1, 0.0, 0.0))
    maps: list = []
    robot.create_subscription(msgs.OccupancyGrid, "map", maps.append)
    r, a0, inc = _room_scan()
    for k in range(3):
        t = k * 100_000_000
        robot.send_transform(msgs.transform_stamped(t, "odom", "base_link", 0.2 * k, 0.0, 0.0))
        scans.publish(
            msgs.LaserScan(
                header=msgs.header(t, "laser"),
                angle_min=a0,
                angle_max=a0 + inc * (len(r) - 1),
                angle_increment=inc,
                time_increment=0.0,
                scan_time=0.1,
                range_min=0.1,
                range_max=10.0,
                ranges=r.astype(np.float32),
                intensities=np.zeros(0, np.float32),
            )
        )
        ex.run(0.1)
    assert slam.scans_processed == 3 and maps and maps[-1].info.resolution == pytest.approx(0.2)
    np.testing.assert_allclose(slam.slam.trajectory()[-1], compose2((0.4, 0.0, 0.0), (0.1, 0.0, 0.0)))
    np.testing.assert_allclose(ex.tf.lookup_pose2d("map", "odom"), (0.0, 0.0, 0.0), atol=1e-12)
