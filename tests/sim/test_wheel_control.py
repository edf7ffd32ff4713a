"""The speed controller (diff_drive_controller + wheel PID on effort), its PID, and the disturbances."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_helpers import make_mybot, make_room

from navlab import msgs
from navlab.core import Context, Executor, Node, load_params
from navlab.resources import root as resources_root
from navlab.sim import SimError, launch_sim
from navlab.sim.disturbances import parse_disturbances
from navlab.sim.pid import Pid, PidGains
from navlab.sim.wheel_control import SpeedLimiter, WheelOdometry


def _step_response(gains: PidGains, limit: float, target: float, t_end: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """A wheel (inertia 0.05 kg m², viscous 0.02 N m s) under the PID at 100 Hz, physics at 1 kHz."""
    pid, w, ws, cmds = Pid(gains, output_limit=limit), 0.0, [], []
    for _ in range(round(t_end / 0.01)):
        tau = pid.compute(target - w, 0.01)
        cmds.append(tau)
        for _ in range(10):
            w += (tau - 0.02 * w) / 0.05 * 0.001
        ws.append(w)
    return np.array(ws), np.array(cmds)


def test_pid_step_response_settles_within_its_limits() -> None:
    gains = PidGains(p=1.0, i=5.0, i_clamp_max=2.0, i_clamp_min=-2.0, antiwindup=True)
    w, tau = _step_response(gains, limit=3.0, target=10.0)
    assert np.abs(tau).max() <= 3.0 + 1e-12  # the motor's torque limit
    assert w.max() <= 10.0 * 1.05  # overshoot under 5 %
    settled = np.flatnonzero(np.abs(w - 10.0) > 0.2)  # 2 % band
    assert settled[-1] * 0.01 < 1.0  # settled within a second and stays there
    assert w[-1] == pytest.approx(10.0, abs=0.02)  # the integral removes the viscous loss
    # the integral term never leaves its clamp
    pid = Pid(gains, output_limit=3.0)
    for _ in range(500):
        pid.compute(100.0, 0.01)
    assert abs(pid.i_term) <= 2.0


def test_pid_proportional_only_leaves_an_offset() -> None:
    w, _ = _step_response(PidGains(p=1.0), limit=0.0, target=10.0)
    assert w[-1] == pytest.approx(10.0 / (1 + 0.02), rel=1e-3)  # p / (p + viscous)


@pytest.mark.parametrize(
    "params, message",
    [
        ({"p": -1.0}, "left_wheel_hinge parameter p: expected >= 0"),
        ({"p": 1.0, "i": -0.5}, "parameter i: expected >= 0"),
        ({"p": 1.0, "i_clamp": -1.0}, "parameter i_clamp: expected >= 0"),
        ({"p": 1.0, "i_clamp_min": 0.5}, "parameter i_clamp_min: expected <= 0"),
        ({"p": 1.0, "kp": 2.0}, "did you mean 'p'"),
        ({"p": 1.0, "gain": 2.0}, "unknown pid_gains.left_wheel_hinge parameter 'gain'"),
        ({"d": "fast"}, "parameter d: expected a number"),
        ({"antiwindup": "yes"}, "parameter antiwindup: expected true or false"),
    ],
)
def test_pid_bad_gains_are_refused(params: dict, message: str) -> None:
    with pytest.raises(SimError, match=message):
        PidGains.from_params(params, where="pid_gains.left_wheel_hinge")


def test_pid_gains_built_in_code_get_the_same_checks() -> None:
    with pytest.raises(SimError, match="pid parameter p: expected >= 0"):
        PidGains(p="fast")  # type: ignore[arg-type]
    with pytest.raises(SimError, match="pid parameter i_clamp_min: expected <= 0"):
        PidGains(i_clamp_max=1.0, i_clamp_min=0.5)


def test_speed_limiter_acceleration_velocity_and_jerk() -> None:
    lim = SpeedLimiter(
        {"has_velocity_limits": True, "max_velocity": 0.5, "has_acceleration_limits": True, "max_acceleration": 1.0}
    )
    v = v0 = v1 = 0.0
    out = []
    for _ in range(100):
        v, v1 = lim.limit(2.0, v, v1, 0.01), v
        out.append(v)
    assert np.diff([0.0, *out]).max() == pytest.approx(0.01)  # 1 m/s² at 100 Hz
    assert out[-1] == pytest.approx(0.5)  # the velocity limit
    assert lim.limit(-3.0, 0.5, 0.5, 0.01) == pytest.approx(0.49)  # min_acceleration mirrors max
    jerk = SpeedLimiter({"has_jerk_limits": True, "max_jerk": 10.0})
    assert jerk.limit(1.0, 0.0, 0.0, 0.01) == pytest.approx(10.0 * 2 * 0.01 * 0.01)
    with pytest.raises(SimError, match="min_velocity"):
        SpeedLimiter({"has_velocity_limits": True, "max_velocity": 0.5, "min_velocity": 1.0})
    del v0


def test_wheel_odometry_arc_and_rolling_mean() -> None:
    odo = WheelOdometry(0.4, 0.08, 0.08, window=5)
    odo.update(0.0, 0.0, 0.0)
    # a quarter circle of radius 1 m: left wheel 0.8 m, right 1.2 m of arc (rad = m / 0.08)
    for k in range(1, 101):
        s = k / 100
        odo.update(0.8 * math.pi / 2 * s / 0.08, 1.2 * math.pi / 2 * s / 0.08, 0.01)
    assert (odo.x, odo.y, odo.yaw) == pytest.approx((1.0, 1.0, math.pi / 2), abs=1e-9)
    assert odo.linear == pytest.approx(math.pi / 2, rel=1e-9) and odo.angular == pytest.approx(math.pi / 2, rel=1e-9)


def _controller_params(**extra: object) -> dict:
    params = load_params(resources_root() / "params" / "mybot" / "diff_drive_controller.yaml")
    params["mobile_base_controller"].update(extra)
    return params


def _drive(
    params: dict, v: float, w: float, seconds: float, *, robot: object = None, stop_at: float = math.inf
) -> tuple[Executor, object, dict]:
    ex = Executor(seed=0)
    gazebo = launch_sim(ex, world=make_room(), robot=robot or make_mybot(), **params)  # type: ignore[arg-type]
    probe = Node("probe", context=Context(ex))
    got: dict = {"odom": [], "truth": []}
    probe.create_subscription(msgs.Odometry, "odom", got["odom"].append)
    probe.create_subscription(msgs.Odometry, "/ground_truth/odom", got["truth"].append)
    cmd = probe.create_publisher(msgs.Twist, "cmd_vel")
    probe.create_timer(0.05, lambda: ex.now_ns / 1e9 < stop_at and cmd.publish(msgs.twist(v, w)))
    ex.run(seconds)
    return ex, gazebo, got


def test_controller_ramps_to_the_command_within_its_limits_and_publishes_odometry() -> None:
    params = _controller_params(
        linear={
            "x": {
                "has_acceleration_limits": True,
                "max_acceleration": 0.5,
                "has_velocity_limits": True,
                "max_velocity": 0.4,
            }
        }
    )
    ex, gazebo, got = _drive(params, 0.6, 0.0, 2.0)
    controller = gazebo.plugins[0]
    assert type(controller).__name__ == "DiffDriveController"
    speeds = np.array([m.twist.twist.linear.x for m in got["truth"]])  # 50 Hz, body frame
    t = np.arange(1, len(speeds) + 1) / 50.0
    assert (np.diff(speeds) * 50.0).max() < 0.5 * 1.25  # the PID closes its lag: at most 25 % over the ramp
    assert speeds[t < 0.6].max() < 0.5 * 0.6 + 0.02  # the ramp: 0.5 m/s² for 0.6 s
    assert speeds[-1] == pytest.approx(0.4, abs=0.01)  # max_velocity, not the commanded 0.6
    wheel = gazebo.sim.joint_velocity("left_wheel_hinge")
    assert wheel == pytest.approx(0.4 / 0.08, rel=0.01)  # the PID holds the wheel speed
    odom = got["odom"][-1]
    assert odom.header.frame_id == "odom" and odom.child_frame_id == "chassis"
    assert len(got["odom"]) == pytest.approx(100, abs=1)  # publish_rate 50 Hz
    assert odom.pose.covariance[35] == pytest.approx(1000.0)
    x, _, _ = msgs.pose2d(odom.pose.pose)
    assert x == pytest.approx(msgs.pose2d(got["truth"][-1].pose.pose)[0], abs=0.02)
    assert ex.tf.lookup_pose2d("odom", "chassis")[0] == pytest.approx(x, abs=0.02)


def test_controller_stops_after_cmd_vel_timeout() -> None:
    _, gazebo, got = _drive(_controller_params(cmd_vel_timeout=0.5), 0.4, 0.0, 2.5, stop_at=1.0)
    assert abs(got["truth"][-1].twist.twist.linear.x) < 0.01
    assert gazebo.sim.base_pose2d()[0] < 0.4 * 1.5 + 0.15  # stopped about 0.5 s after the last command


@pytest.mark.parametrize(
    "params, message",
    [
        (
            {
                "mobile_base_controller": {"type": "diff_drive_controller/DiffDriveController"},
                "gazebo_ros_control": {"pid_gains": {"left_wheel_hinge": {"p": -1.0}}},
            },
            "pid_gains.left_wheel_hinge parameter p: expected >= 0",
        ),
        (
            {
                "mobile_base_controller": {
                    "type": "diff_drive_controller/DiffDriveController",
                    "pose_covariance_diagonal": [0.1, 0.1],
                }
            },
            "expected 6 numbers",
        ),
        ({"mobile_base_controller": {"type": "effort_controllers/JointGroupEffortController"}}, "navlab simulates"),
        (
            {"mobile_base_controller": {"type": "diff_drive_controller/DiffDriveController", "publish_rat": 5.0}},
            "did you mean 'publish_rate'",
        ),
        ({"disturbances": {"payload": 3.0}}, "did you mean 'payload_mass'"),
        ({"disturbances": {"slip_patches": [{"x": 0, "y": 0, "mu": 0.1}]}}, "either radius"),
    ],
)
def test_bad_controller_and_disturbance_parameters(params: dict, message: str) -> None:
    with pytest.raises(Exception, match=message):
        launch_sim(Executor(seed=0), world=make_room(), robot=make_mybot(), **params)


def test_wheel_radius_error_turns_the_robot_while_odometry_believes_straight() -> None:
    params = {**_controller_params(), "disturbances": {"wheel_radius_error": [0.05, 0.0]}}
    _, _, got = _drive(params, 0.5, 0.0, 3.0)
    _, _, true_yaw = msgs.pose2d(got["truth"][-1].pose.pose)
    _, _, odom_yaw = msgs.pose2d(got["odom"][-1].pose.pose)
    assert abs(odom_yaw) < 0.01  # the encoders turn equally
    assert true_yaw < -0.1  # the larger left wheel goes further: the robot veers right


def test_slip_patch_and_payload() -> None:
    patch = {"x": 0.0, "y": 0.0, "size_x": 1.0, "size_y": 2.0, "mu": 0.02}
    params = {**_controller_params(), "disturbances": {"slip_patches": [patch], "payload_mass": 4.0}}
    ex, gazebo, got = _drive(params, 0.0, 2.0, 1.5)
    slip = next(p for p in gazebo.plugins if type(p).__name__ == "SlipPatchPlugin")
    assert slip.wheel_friction == (0.02, 0.02)
    true_yaw = msgs.pose2d(got["truth"][-1].pose.pose)[2]
    odom_yaw = msgs.pose2d(got["odom"][-1].pose.pose)[2]
    assert odom_yaw - true_yaw > 0.2  # the wheels spun more than the robot turned
    assert parse_disturbances({"wheel_radius_error": 0.01}).wheel_radius_error == (0.01, 0.01)
    del ex
