"""Four-wheel skid-steer robots: the gazebo_ros_control + diff_drive_controller shape (a control YAML with
``left_wheel: [front, rear]``), libgazebo_ros_skid_steer_drive.so, and how fast they really turn.

The yaw-rate figure by construction: four wheels at (+-a, +-b/2) carrying equal load, driven at the rim speeds
``+-u`` with isotropic Coulomb friction, turn in place at the rate where the wheels' friction moments balance:
every wheel slides along ``(w b/2 - u, w a)``, and its moment about the centre vanishes when
``w (a^2 + (b/2)^2) = u b/2``, so ``w / w_cmd = m (b/2)^2 / (a^2 + (b/2)^2)`` for a controller whose
``wheel_separation_multiplier`` is ``m`` (it commands ``u = w_cmd m b/2``). The friction coefficient cancels.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from navlab import msgs
from navlab.core import Context, Executor, Node
from navlab.core.node import flatten_params
from navlab.description import load_robot
from navlab.sim import launch_sim

FIXTURE = Path(__file__).parents[1] / "fixtures" / "skidbot_description"
XACRO = FIXTURE / "urdf" / "skidbot.urdf.xacro"
A, HALF_B = 0.10, 0.15  # skidbot's half wheelbase and half track (m)


def coulomb_ratio(multiplier: float, a: float = A, half_b: float = HALF_B) -> float:
    """Achieved / commanded in-place yaw rate of a four-wheel skid-steer robot (see the module docstring)."""
    return multiplier * half_b**2 / (a**2 + half_b**2)


def _yaw(sim: object) -> float:
    q = sim.link_pose("base_link").quaternion  # type: ignore[attr-defined]
    return math.atan2(2 * (q[3] * q[2] + q[0] * q[1]), 1 - 2 * (q[1] ** 2 + q[2] ** 2))


def drive(
    v: float,
    w: float,
    *,
    drive_kind: str = "ros_control",
    multiplier: float = 1.0,
    mu: float = 0.3,
    settle: float = 1.0,
    duration: float = 2.0,
) -> dict[str, float]:
    """Command (v, w) on skidbot; the true speed and yaw rate over ``duration`` s after ``settle`` s, and the
    odometry's."""
    ex = Executor(seed=0)
    robot = load_robot(XACRO, args={"drive": drive_kind, "mu": str(mu)})
    params: dict = {}
    if drive_kind == "ros_control":
        params = flatten_params(yaml.safe_load((FIXTURE / "config" / "control.yaml").read_text()))
        params["skidbot_velocity_controller.wheel_separation_multiplier"] = multiplier
    gz = launch_sim(ex, world="room", robot=robot, ground_truth_rate=0.0, **params)
    node = Node("driver", context=Context(ex))
    pub = node.create_publisher(msgs.Twist, "cmd_vel")
    odom: list = []
    node.create_subscription(msgs.Odometry, "odom", odom.append, 10)
    node.create_timer(0.05, lambda: pub.publish(msgs.twist(v, w)))
    ex.run(settle)
    y0, p0, turned = _yaw(gz.sim), gz.sim.link_pose("base_link").position.copy(), 0.0
    for _ in range(int(duration / 0.05)):
        last = _yaw(gz.sim)
        ex.run(0.05)
        turned += (_yaw(gz.sim) - last + math.pi) % (2 * math.pi) - math.pi
    p1 = gz.sim.link_pose("base_link").position
    o = odom[-1]
    return {
        "w": turned / duration,
        "v": float(np.linalg.norm(p1[:2] - p0[:2])) / duration,
        "odom_w": o.twist.twist.angular.z,
        "odom_v": o.twist.twist.linear.x,
        "z": float(p1[2]),
        "odom_x": o.pose.pose.position.x,
        "true_x": float(p1[0]),
        "y0": y0,
    }


def test_shipped_jackal_skid_has_the_public_shape() -> None:
    robot = load_robot("jackal_skid")
    assert robot.ros_control is not None and robot.diff_drive is None  # the drive comes from control.yaml
    wheel = robot.links["front_left_wheel_link"]
    assert wheel.mu1 == wheel.mu2 == 0.8 and wheel.contact is not None and wheel.contact.kp == 1e6
    skid = load_robot("jackal_skid", args={"drive": "skid_steer"}).diff_drive
    assert skid is not None and skid.drive == "gazebo_ros_skid_steer_drive"
    assert skid.wheel_joints() == (("front_left_wheel", "rear_left_wheel"), ("front_right_wheel", "rear_right_wheel"))
    assert skid.odometry_source == "world" and skid.publish_tf  # the plugin's odometry is the true pose


def test_ros_control_drives_straight_with_odometry_from_the_wheels() -> None:
    r = drive(0.5, 0.0)
    assert r["v"] == pytest.approx(0.5, rel=0.03)  # rolling straight, the tyres hardly slip
    assert r["odom_v"] == pytest.approx(0.5, rel=0.02) and abs(r["w"]) < 0.01
    assert abs(r["z"]) < 0.01  # on its wheels, not hopping


@pytest.mark.parametrize("multiplier", [1.0, 1.5])
def test_in_place_yaw_rate_is_the_coulomb_figure(multiplier: float) -> None:
    r = drive(0.0, 1.0, multiplier=multiplier)
    assert r["w"] == pytest.approx(coulomb_ratio(multiplier), rel=0.12)
    # diff_drive_controller's odometry reads the wheels: it reports the command, not the slower turn
    assert r["odom_w"] == pytest.approx(1.0, rel=0.05)


def test_skid_steer_plugin_drives_an_arc_and_reports_the_true_pose() -> None:
    r = drive(0.4, 0.5, drive_kind="skid_steer")
    assert 0.3 < r["w"] / 0.5 < 1.0  # the tyres scrub: slower than the wheels ask
    assert r["odom_w"] == pytest.approx(r["w"], abs=0.05)  # gazebo_ros_skid_steer_drive's odometry: the model's pose
    assert r["odom_x"] == pytest.approx(r["true_x"], abs=1e-3)


@pytest.mark.parametrize("mu", [0.05, 0.3])
def test_friction_tags_set_the_slip_when_starting(mu: float) -> None:
    """Coulomb friction lets four driven wheels push the robot at most ``mu g``: the wheels spin up at the
    controller's 5 m/s² while the robot follows at ``min(mu g, 5)``, so by the time both run at v the wheel
    odometry has counted ``v²/2 (1/(mu g) - 1/5)`` m the robot never drove."""
    r = drive(1.0, 0.0, mu=mu, settle=0.0, duration=2.5)
    expected = 0.5 * (1.0 / min(mu * 9.81, 5.0) - 1.0 / 5.0)
    assert r["odom_x"] - r["true_x"] == pytest.approx(expected, rel=0.25, abs=0.02)


def test_robot_files_turn_on_the_controller_and_the_ekf_by_default() -> None:
    """jackal_skid ships config/control.yaml and a robot_localization YAML beside it: the shipped sim launch starts
    its diff_drive_controller and robot_localization's EKF without being asked; the EKF alone sends odom -> base."""
    from navlab.core.launch import start
    from navlab.description.loader import robot_launch_values

    values = robot_launch_values("jackal_skid")
    assert (values["wheel_controller"], values["ekf"]) == ("true", "true")
    assert values["controller_params"].endswith("jackal_skid/config/control.yaml")
    assert robot_launch_values("mybot")["ekf"] == "false"  # mybot asks for neither
    s = start("sim", launch_args={"robot": "jackal_skid"})
    senders: set[str] = set()
    filtered: list = []
    watch = Node("watch", context=Context(s.executor))
    watch.create_subscription(
        msgs.TFMessage,
        "/tf",
        lambda m: senders.update(t.header.frame_id + ">" + t.child_frame_id for t in m.transforms),
        100,
    )
    watch.create_subscription(msgs.Odometry, "/odometry/filtered", filtered.append, 100)
    cmd = watch.create_publisher(msgs.Twist, "/cmd_vel", 1)
    watch.create_timer(0.1, lambda: cmd.publish(msgs.twist(0.3, 0.5)))
    s.run(1.5)
    assert "jackal_velocity_controller" in {p.name for p in s.nodes["/gazebo"].plugins} and "/ekf_se" in s.nodes
    assert "odom>base_link" in senders and len(filtered) >= 60  # 50 Hz
    assert filtered[-1].twist.twist.angular.z > 0.2  # turning left, as the IMU says


def test_ekf_keeps_drift_within_two_percent_on_a_clutter_course() -> None:
    """jackal_skid with its own files (controller + robot_localization EKF) along a scripted route through a generated
    clutter course: odom strays at most 2 % of the distance driven (the issue's target, <= 0.2 m at 10 m)."""
    from navlab.experiments.odom_run import run_drift

    r = run_drift("jackal_skid", "clutter", ekf=True)
    assert r["completed"] and r["distance_m"] > 10.0 and r["turned_rad"] > 3.0  # a winding course, driven to its end
    assert r["error_per_m"] <= 0.02 and r["max_error_m"] <= 0.2


def test_controllers_are_found_by_type() -> None:
    from navlab.sim.ros_control import find_controllers

    found = find_controllers(
        {
            "base.type": "diff_drive_controller/DiffDriveController",
            "base.left_wheel": ["a", "b"],
            "arm.type": "position_controllers/JointTrajectoryController",
            "arm.joints": ["j1"],
            "joints.type": "joint_state_controller/JointStateController",
            "joints.publish_rate": 20,
        }
    )
    assert (found.diff_drive, found.joint_state_rate) == ("base", 20.0)
    assert set(found.names) == {"base", "arm", "joints"}  # their keys are the YAML's, not unknown parameters
    assert found.ignored == ("arm (position_controllers/JointTrajectoryController)",)
    assert find_controllers({"mobile_base_controller.left_wheel": "w"}).diff_drive == "mobile_base_controller"


def test_turning_in_place_pivots_nearer_the_heavier_front_axle() -> None:
    """jackal_skid's centre of mass sits 12 mm ahead of the chassis centre, as the Jackal's: its front wheels carry
    more load and grip harder sideways, so turning in place it pivots about a point ahead of base_link, which
    circles round it instead of standing still (a centred robot's base_link stays within a few millimetres)."""
    from navlab.core.launch import start

    s = start("sim", launch_args={"robot": "jackal_skid", "ekf": "false"})
    truth: list = []
    watch = Node("watch", context=Context(s.executor))
    watch.create_subscription(msgs.Odometry, "/ground_truth/odom", truth.append, 100)
    cmd = watch.create_publisher(msgs.Twist, "/cmd_vel", 1)
    watch.create_timer(0.05, lambda: cmd.publish(msgs.twist(0.0, 0.314)))  # the benchmark's in-place turn rate
    s.run(12.0)
    xy = np.array([(m.pose.pose.position.x, m.pose.pose.position.y) for m in truth])[len(truth) // 6 :]
    yaw = np.array([2 * math.atan2(m.pose.pose.orientation.z, m.pose.pose.orientation.w) for m in truth])
    yaw = yaw[len(truth) // 6 :]
    # the circle base_link runs on (least squares), and its centre seen from the robot
    a = np.c_[2 * xy, np.ones(len(xy))]
    cx, cy, _ = np.linalg.lstsq(a, (xy**2).sum(axis=1), rcond=None)[0]
    dx, dy = cx - xy[:, 0], cy - xy[:, 1]
    ahead = np.cos(yaw) * dx + np.sin(yaw) * dy
    aside = -np.sin(yaw) * dx + np.cos(yaw) * dy
    assert np.ptp(yaw) > 2.0  # it turned (0.314 rad/s for 10 s)
    assert 0.02 < np.median(ahead) < 0.131 and abs(np.median(aside)) < 0.02, (np.median(ahead), np.median(aside))
    assert np.ptp(ahead) < 0.02, np.ptp(ahead)  # one pivot, fixed in the robot
