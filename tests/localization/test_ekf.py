"""robot_localization's EKF: the pure filter, its inputs' modes, the node, and slip against ground truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab import msgs
from navlab.core import Context, Executor, Node, load_params
from navlab.geometry import wrap_angle
from navlab.localization import ekf
from navlab.localization.ekf_node import EkfNode
from navlab.resources import root as resources_root
from navlab.world import WorldModel

PARAMS = resources_root() / "params"


def _mask(*names: str) -> np.ndarray:
    return np.array([s in names for s in ekf.STATE])


def test_prediction_follows_body_velocities() -> None:
    f = ekf.Ekf(two_d_mode=True)
    f.correct(*ekf.twist_measurement((1.0, 0.0, 0.0, 0.0, 0.0, 0.5), np.eye(6) * 1e-3), _mask("vx", "vyaw"))
    for _ in range(100):
        f.predict(0.01)
    # an arc of radius 2 m through 0.5 rad after 1 s at 1 m/s and 0.5 rad/s (first-order steps, as robot_localization)
    assert f.state[[0, 1, 5]] == pytest.approx([2 * math.sin(0.5), 2 * (1 - math.cos(0.5)), 0.5], abs=5e-3)
    assert f.covariance[0, 0] > 0.04  # process noise grows with time
    assert f.state[2] == 0.0 and f.covariance[2, 2] == 0.0  # two_d_mode pins z


def test_compiled_prediction_matches_the_vectorised_model() -> None:
    f = ekf.Ekf()
    f.state = np.random.default_rng(0).normal(size=15) * 0.3
    f.covariance = np.eye(15) * 0.1
    s0, p0 = f.state.copy(), f.covariance.copy()
    f.predict(0.05)
    j = ekf.jacobian(s0, 0.05)
    assert f.state == pytest.approx(ekf.transition(s0, 0.05), abs=1e-12)
    assert f.covariance == pytest.approx(j @ p0 @ j.T + f.process_noise * 0.05, abs=1e-8)


def test_correction_weighs_by_covariance_and_rejects_outliers() -> None:
    f = ekf.Ekf(initial_covariance=[1.0] * 15)
    f.initialized = True
    z, r = ekf.pose_measurement((1.0, 0.0, 0.0, 0.0, 0.0, 0.0), np.eye(6))
    assert f.correct(z, r, _mask("x"))
    assert f.state[0] == pytest.approx(0.5)  # equal variances: half way
    assert f.covariance[0, 0] == pytest.approx(0.5)
    z, r = ekf.pose_measurement((50.0, 0.0, 0.0, 0.0, 0.0, 0.0), np.eye(6) * 0.01)
    assert not f.correct(z, r, _mask("x"), threshold=3.0) and f.last_rejected
    assert f.state[0] == pytest.approx(0.5)
    z, r = ekf.pose_measurement((0.0, 0.0, 0.0, 0.0, 0.0, 3.1), np.eye(6))
    f.state[5] = -3.1
    f.correct(z, r, _mask("yaw"))
    assert abs(wrap_angle(f.state[5] - math.pi)) < 0.05  # the innovation wraps: no trip round the circle


def test_differential_and_relative_inputs() -> None:
    diff = ekf.PoseInput(differential=True)
    pose_mask = _mask("x", "y", "yaw")
    assert diff.convert((1.0, 1.0, 0.0, 0.0, 0.0, math.pi / 2), np.eye(6) * 0.01, 0.0, pose_mask) is None
    z, r, m = diff.convert((1.0, 1.5, 0.0, 0.0, 0.0, math.pi / 2 + 0.1), np.eye(6) * 0.01, 0.5, pose_mask)
    assert list(np.flatnonzero(m)) == [6, 7, 11]  # fused as vx vy vyaw
    assert z[[6, 7, 11]] == pytest.approx([1.0, 0.0, 0.2])  # 0.5 m forward in the robot's frame in 0.5 s
    assert r[6, 6] == pytest.approx(0.02 / 0.25)
    rel = ekf.PoseInput(relative=True)
    rel.convert((5.0, 5.0, 0.0, 0.0, 0.0, 1.0), np.eye(6), 0.0, pose_mask)
    z, _, _ = rel.convert((5.0, 6.0, 0.0, 0.0, 0.0, 1.0), np.eye(6), 1.0, pose_mask)
    assert z[[0, 1, 5]] == pytest.approx([math.sin(1.0), math.cos(1.0), 0.0])


def test_imu_measurement_rotates_into_the_base_and_removes_gravity() -> None:
    upside = np.diag([1.0, -1.0, -1.0])  # an IMU mounted upside down (roll pi)
    z, r = ekf.imu_measurement(
        upside,
        orientation_rpy=(math.pi, 0.0, 0.3),
        orientation_cov=np.eye(3) * 0.01,
        angular_velocity=(0.0, 0.0, -0.5),
        angular_velocity_cov=np.eye(3) * 1e-4,
        linear_acceleration=(0.2, 0.0, -9.80665),
        linear_acceleration_cov=np.eye(3) * 0.01,
        remove_gravity=True,
    )
    assert z[[3, 4, 5]] == pytest.approx([0.0, 0.0, 0.3], abs=1e-9)
    assert z[11] == pytest.approx(0.5) and r[11, 11] == pytest.approx(1e-4)
    assert z[[12, 13, 14]] == pytest.approx([0.2, 0.0, 0.0], abs=1e-9)


@pytest.mark.parametrize(
    "params, message",
    [
        ({"odom0": "odom", "odom0_config": [True] * 12}, "odom0_config: expected 15 booleans .* got 12 values"),
        ({"imu0": "imu", "imu0_config": "all"}, "imu0_config'?: expected"),
        ({"process_noise_covariance": [0.1] * 20}, "process_noise_covariance: expected 225"),
        ({"initial_estimate_covariance": [-1.0] + [1.0] * 14}, "diagonal entries must be >= 0, negative for x"),
        ({"odom0": "odom", "odom0_twist_rejection_threshold": -2.0}, "expected a distance > 0"),
        ({"frequency": 0.0}, "frequency"),
        ({"world_frame": "earth"}, "world_frame 'earth'"),
        ({"odom0": "odom", "odom0_confg": [True] * 15}, "did you mean 'odom0_config'"),
    ],
)
def test_bad_parameters_get_clear_errors(params: dict, message: str) -> None:
    with pytest.raises(Exception, match=message):
        EkfNode(Executor(seed=0), parameters=params)


def test_imu_without_a_frame_is_reported_and_ignored() -> None:
    ex = Executor(seed=0)
    node = EkfNode(ex, parameters={"imu0": "imu", "imu0_config": list(_mask("vyaw")), "base_link_frame": "chassis"})
    pub = Node("probe", context=Context(ex)).create_publisher(msgs.Imu, "imu")
    for frame in ("", "imu_link"):
        node.last_error = None
        pub.publish(
            msgs.Imu(
                header=msgs.header(ex.now_ns, frame),
                orientation=msgs.quaternion_from_yaw(0.0),
                orientation_covariance=np.zeros(9),
                angular_velocity=msgs.Vector3(x=0.0, y=0.0, z=0.3),
                angular_velocity_covariance=np.eye(3).ravel() * 1e-4,
                linear_acceleration=msgs.Vector3(x=0.0, y=0.0, z=0.0),
                linear_acceleration_covariance=np.zeros(9),
            )
        )
        ex.run(0.1)
        assert node.last_error is not None
        assert ("no frame_id" in node.last_error) if not frame else ("'imu_link'" in node.last_error)
        assert node.estimate is None  # nothing fused


def test_slip_patch_heading_drift_smaller_with_imu_fusion_than_wheel_odometry() -> None:
    """mybot turns in place on ice, starting and stopping: the wheels spin more than the robot turns, so
    wheel odometry overestimates the heading change; the EKF fusing the gyro's yaw rate does not."""
    from navlab.sim import launch_sim

    ctrl = load_params(PARAMS / "mybot" / "diff_drive_controller.yaml")
    ctrl["mobile_base_controller"]["enable_odom_tf"] = False
    ex = Executor(seed=0)
    launch_sim(
        ex,
        world=WorldModel("empty"),
        robot="mybot",
        seed=1,
        **ctrl,
        disturbances={"slip_patches": [{"x": 0.0, "y": 0.0, "radius": 1.0, "mu": 0.03}]},
    )
    node = EkfNode(ex, parameters=load_params(PARAMS / "ekf.yaml"))
    probe = Node("probe", context=Context(ex))
    got: dict = {"odom": [], "odometry/filtered": [], "/ground_truth/odom": []}
    for topic, store in got.items():
        probe.create_subscription(msgs.Odometry, topic, store.append)
    cmd = probe.create_publisher(msgs.Twist, "cmd_vel")
    probe.create_timer(0.05, lambda: cmd.publish(msgs.twist(0.0, 2.0 if ex.now_ns / 1e9 % 3.0 < 1.5 else 0.0)))
    ex.run(6.0)
    truth = msgs.pose2d(got["/ground_truth/odom"][-1].pose.pose)[2]
    wheel_err = abs(wrap_angle(msgs.pose2d(got["odom"][-1].pose.pose)[2] - truth))
    ekf_err = abs(wrap_angle(msgs.pose2d(got["odometry/filtered"][-1].pose.pose)[2] - truth))
    assert wheel_err > 0.15  # the slip is real
    assert ekf_err < 0.2 * wheel_err
    assert got["odometry/filtered"][-1].header.frame_id == "odom"
    assert ex.tf.lookup_pose2d("odom", "chassis")[2] == pytest.approx(node.estimate[2], abs=0.05)  # type: ignore[index]
