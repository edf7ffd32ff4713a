"""The amcl node on the executor: map/scan/initialpose in, tf map→odom and amcl_pose out, services."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from amcl_synth import odometry, room_field, route, scan_at

from navlab import msgs
from navlab.core import Context, Executor, Node, ParameterError
from navlab.grid import GridMap
from navlab.localization import LocalizationError
from navlab.localization.amcl_node import Amcl
from navlab.localization.models import sample_motion_diff_corrected
from navlab.localization.synthetic import room_grid


class FakeRobot(Node):
    """Drives the synthetic route at 10 Hz: publishes tf odom→base_link, base_link→laser and scans."""

    def __init__(self, executor: Executor, *, name: str = "fake_robot", truth: list, odo: list) -> None:
        super().__init__(name, context=Context(executor))
        self.truth, self.odo, self.k = truth, odo, 0
        self.field = room_field()
        self.scan_rng = np.random.default_rng(0)
        self.blank = False
        self.scan_pub = self.create_publisher(msgs.LaserScan, "scan", 10)
        self.send_static_transform(msgs.transform_stamped(0, "base_link", "laser", 0.0, 0.0, 0.0, z=0.2))
        self.create_timer(0.1, self.tick)

    def tick(self) -> None:
        if self.k >= len(self.truth):
            return
        t = self.get_clock().now_ns()
        self.send_transform(msgs.transform_stamped(t, "odom", "base_link", *self.odo[self.k]))
        s = scan_at(self.field, self.truth[self.k], self.scan_rng)
        ranges = np.full(s.ranges.shape, np.inf) if self.blank else s.ranges
        self.scan_pub.publish(
            msgs.LaserScan(
                header=msgs.header(t, "laser"),
                angle_min=s.angle_min,
                angle_max=s.angle_min + s.angle_increment * (len(ranges) - 1),
                angle_increment=s.angle_increment,
                time_increment=0.0,
                scan_time=0.1,
                range_min=s.range_min,
                range_max=s.range_max,
                ranges=ranges.astype(np.float32),
                intensities=np.zeros(0, np.float32),
            )
        )
        self.k += 1


def _map_msg(data: np.ndarray | None = None) -> Any:
    return GridMap(room_grid() if data is None else data, 0.05, (-0.2, -0.2, 0.0)).to_msg(0)


def _setup(params: dict[str, Any], n: int = 300, seed: int = 0) -> tuple[Executor, Amcl, FakeRobot, dict]:
    ex = Executor(seed=seed)
    truth = route(n)
    odo = odometry(truth, np.random.default_rng(1), start=(0.5, -0.3, 0.2))
    got: dict[str, list] = {"pose": [], "tf": []}
    amcl = Amcl(ex, parameters=params)
    robot = FakeRobot(ex, truth=truth, odo=odo)
    probe = Node("probe", context=Context(ex))
    probe.create_subscription(msgs.PoseWithCovarianceStamped, "amcl_pose", got["pose"].append)
    probe.create_subscription(
        msgs.TFMessage, "/tf", lambda m: got["tf"].extend(t for t in m.transforms if t.child_frame_id == "odom")
    )
    probe.create_publisher(msgs.OccupancyGrid, "map", latched=True).publish(_map_msg())
    got["initialpose"] = probe.create_publisher(msgs.PoseWithCovarianceStamped, "initialpose")
    return ex, amcl, robot, got


def _error(robot: FakeRobot, ex: Executor) -> float:
    """Distance (m) between the truth and map_T_odom ⊕ odom at the latest tick."""
    k = robot.k - 1
    mx, my, _ = ex.tf.lookup_pose2d("map", "base_link")
    return math.hypot(mx - robot.truth[k][0], my - robot.truth[k][1])


def test_node_tracks_from_initial_pose_parameters_and_publishes_ros_outputs() -> None:
    truth0 = route(1)[0]
    ex, amcl, robot, got = _setup(
        {"initial_pose_x": truth0[0], "initial_pose_y": truth0[1], "initial_pose_a": truth0[2], "max_particles": 2000}
    )
    ex.run(25.0)
    assert _error(robot, ex) < 0.10
    assert got["pose"], "amcl_pose was never published"
    last = got["pose"][-1]
    assert last.header.frame_id == "map"
    assert math.dist(msgs.pose2d(last.pose.pose)[:2], amcl.filter.estimate[:2]) < 1e-9
    cov = np.asarray(last.pose.covariance).reshape(6, 6)
    assert 0 < cov[0, 0] < 0.05 and 0 < cov[5, 5] < 0.05
    tf = got["tf"][-1]
    assert tf.header.frame_id == "map"
    scan_t = robot.k * 100_000_000  # tick k runs at (k + 1) * 0.1 s
    assert msgs.stamp_ns(tf) == scan_t + 100_000_000  # scan stamp + transform_tolerance 0.1 s


def test_global_localization_service_and_nomotion_update() -> None:
    ex, amcl, robot, _ = _setup({"max_particles": 5000}, n=450)
    ex.run(0.05)
    ex.call_service("/global_localization")
    assert amcl.filter.n_particles == 5000
    spread = amcl.filter.particles[:, :2].std(0)
    assert spread.min() > 1.0  # uniform over the room
    ex.run(44.0)
    assert _error(robot, ex) < 0.10
    n0 = amcl.filter.n_updates
    robot.k -= 1  # robot stands still for one more scan
    robot.truth.append(robot.truth[-1])
    robot.odo.append(robot.odo[-1])
    ex.call_service("/request_nomotion_update")
    ex.run(0.1)
    assert amcl.filter.n_updates == n0 + 1


def test_bad_initial_pose_is_refused_and_all_inf_scans_do_not_update() -> None:
    truth0 = route(1)[0]
    ex, amcl, robot, got = _setup(
        {"initial_pose_x": truth0[0], "initial_pose_y": truth0[1], "initial_pose_a": truth0[2]}
    )
    ex.run(2.0)
    before = amcl.filter.estimate
    for x in (float("nan"), 40.0):
        got["initialpose"].publish(
            msgs.PoseWithCovarianceStamped(
                header=msgs.header(ex.now_ns, "map"),
                pose=msgs.PoseWithCovariance(pose=msgs.pose_from_2d(x, 1.0, 0.0), covariance=msgs.covariance()),
            )
        )
        assert "ignoring initialpose" in amcl.last_error
    assert amcl.filter.estimate == before
    n0 = amcl.filter.n_updates
    robot.blank = True
    ex.run(3.0)  # robot keeps driving 0.9 m but the laser sees nothing
    assert amcl.filter.n_updates == n0
    robot.blank = False
    ex.run(1.0)
    assert amcl.filter.n_updates > n0
    assert _error(robot, ex) < 0.15


def test_map_without_free_cells_is_refused_and_unknown_parameters_are_named() -> None:
    ex = Executor(seed=0)
    amcl = Amcl(ex)
    probe = Node("probe", context=Context(ex))
    probe.create_publisher(msgs.OccupancyGrid, "map", latched=True).publish(
        _map_msg(np.full((50, 50), 100, dtype=np.int8))
    )
    ex.run(0.1)
    assert amcl.filter is None
    assert "no free cells" in amcl.last_error
    with pytest.raises(ParameterError, match="laser_z_hit"):
        Amcl(Executor(), parameters={"laser_z_hitt": 0.5})
    nav2 = Amcl(Executor(), parameters={"z_hit": 0.5, "max_beams": 60, "robot_model_type": "differential"})
    assert nav2.params.laser_z_hit == 0.5 and nav2.params.laser_max_beams == 60
    assert nav2.params.motion_model() is sample_motion_diff_corrected  # Nav2's name for ROS's diff-corrected
    with pytest.raises(LocalizationError, match=r"odom_model_type 'dif' \(did you mean 'diff'\?"):
        Amcl(Executor(), parameters={"odom_model_type": "dif"})
    with pytest.raises(LocalizationError, match=r"laser_model_type 'beams' \(did you mean 'beam'\?"):
        Amcl(Executor(), parameters={"laser_model_type": "beams"})


@pytest.mark.parametrize(
    ("mangle", "words"),
    [
        (lambda m: setattr(m.info, "width", m.info.width + 1), ["cells but info says width"]),
        (lambda m: setattr(m.info, "resolution", 0.0), ["resolution must be a positive number"]),
        (lambda m: setattr(m.info.origin.position, "x", float("nan")), ["origin must be finite"]),
    ],
)
def test_malformed_map_is_refused_in_one_line_naming_the_topic(mangle, words, caplog) -> None:  # type: ignore[no-untyped-def]
    """A malformed /map does not escape the subscriber: amcl logs one line naming the topic and what was wrong,
    keeps waiting for a map, and takes the next good one."""
    ex = Executor(seed=0)
    amcl = Amcl(ex)
    pub = Node("probe", context=Context(ex)).create_publisher(msgs.OccupancyGrid, "map", latched=True)
    bad = _map_msg()
    mangle(bad)
    pub.publish(bad)
    ex.run(0.1)
    assert amcl.filter is None
    assert amcl.last_error.startswith("ignoring map on /map: ") and "\n" not in amcl.last_error
    for word in words:
        assert word in amcl.last_error
    pub.publish(_map_msg())
    ex.run(0.1)
    assert amcl.filter is not None
