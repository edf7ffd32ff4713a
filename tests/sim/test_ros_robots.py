"""Issue 13: a ROS 1 tutorial robot behaves in navlab as in Gazebo classic (tests/fixtures/tutorial_bot_description).

Its wheel joints are named the other way round (its plugin may set ``legacyMode``, which ROS Noetic's
plugin no longer reads: issue 23), it sends its scans to /tutorial_bot/laser/scan and paints its chassis Gazebo/Orange.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from sim_helpers import make_room

from navlab import msgs
from navlab.core import Context, Executor, Node
from navlab.description import load_robot
from navlab.sim import launch_sim

PKG = Path(__file__).parents[1] / "fixtures" / "tutorial_bot_description"
XACRO = PKG / "urdf" / "tutorial_bot.urdf.xacro"


def _drive(
    robot: object, twists: list[tuple[float, float, float]], duration: float, **params: object
) -> tuple[Executor, object]:
    """Run the robot in the test room; publish each (t, v, w) once at time t."""
    ex = Executor(seed=0)
    gazebo = launch_sim(ex, world=make_room(), robot=robot, **params)  # type: ignore[arg-type]
    node = Node("rostopic_pub", context=Context(ex))
    pub = node.create_publisher(msgs.Twist, "cmd_vel", 10)
    for t, v, w in twists:
        holder: dict[str, object] = {}

        def fire(v: float = v, w: float = w, holder: dict[str, object] = holder) -> None:
            holder["timer"].cancel()  # type: ignore[attr-defined]
            pub.publish(msgs.twist(v, w))

        holder["timer"] = node.create_timer(t, fire)
    ex.run(duration)
    return ex, gazebo


@pytest.mark.parametrize("legacy", ["unset", "true", "false"])
def test_swapped_wheel_names_turn_as_noetic_turns_them(legacy: str) -> None:
    """Noetic's plugin drives <leftJoint> as the left wheel whatever <legacyMode> says (the tag was removed in
    Melodic): a robot whose <leftJoint> is on the right turns clockwise when asked for +angular.z."""
    robot = load_robot(XACRO, args={"legacy": legacy})
    assert robot.diff_drive is not None and robot.diff_drive.legacy_mode is False
    assert any("removed from gazebo_ros_diff_drive in Melodic" in w for w in robot.warnings) is (legacy == "true")
    _, gazebo = _drive(robot, [(0.05, 0.0, 1.0)], 1.0)
    yaw = gazebo.sim.base_pose2d("base_link")[2]  # type: ignore[attr-defined]
    assert yaw < -0.5


def test_swapped_wheel_names_encoder_odometry_turns_the_other_way() -> None:
    """Noetic's encoder odometry integrates the named joints as left/right: with the names swapped it turns
    counter-clockwise while the robot turns clockwise, as in Gazebo."""
    robot = load_robot(XACRO, args={"odometry_source": "encoder"})
    ex, gazebo = _drive(robot, [(0.05, 0.1, 0.8)], 1.5)
    odom_yaw = ex.tf.lookup_pose2d("odom", "base_link")[2]
    true_yaw = gazebo.sim.base_pose2d("base_link")[2]  # type: ignore[attr-defined]
    assert true_yaw < -0.8 and odom_yaw == pytest.approx(-true_yaw, abs=0.1)


def test_one_cmd_vel_keeps_a_ros1_robot_going() -> None:
    """``rostopic pub -1 cmd_vel ...``: ROS 1's plugin applies the last command until a new one."""
    robot = load_robot(XACRO, args={"legacy": "true"})
    _, gazebo = _drive(robot, [(0.1, 0.4, 0.0)], 3.0)
    x = gazebo.sim.base_pose2d("base_link")[0]  # type: ignore[attr-defined]
    assert x == pytest.approx(0.4 * 2.9, abs=0.15)


def test_cmd_timeout_watchdog_is_a_navlab_parameter() -> None:
    robot = load_robot(XACRO, args={"legacy": "true"})
    _, gazebo = _drive(robot, [(0.1, 0.4, 0.0)], 3.0, cmd_timeout=0.5)
    x = gazebo.sim.base_pose2d("base_link")[0]  # type: ignore[attr-defined]
    assert 0.1 < x < 0.4  # moved for 0.5 s (and coasted), then stopped


def test_gazebo_material_colours_the_rendered_chassis() -> None:
    from navlab.sim import SimError, Simulation
    from navlab.sim.render import render_image

    robot = load_robot(XACRO)
    sim = Simulation(robot, make_room(), visuals=True)
    try:
        image = render_image(sim, width=160, height=120, elevation=-89.0, distance=1.2, lookat=(0.0, 0.0, 0.0)).astype(
            int
        )
    except SimError as exc:
        pytest.skip(f"no offscreen OpenGL here: {exc}")
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    orange = (r > 200) & (g <= r) & (r - b > 100)  # lit orange: red full, blue low
    blue = (b > r + 60) & (b > g + 60)
    assert orange.mean() > 0.05  # Gazebo/Orange from <gazebo reference="base_link"><material>
    assert blue.mean() < 0.005  # not the URDF's own blue material
    assert math.isfinite(float(np.mean(image)))


def test_mapping_launch_takes_base_frame_and_scan_topic_from_the_robot() -> None:
    """The shipped mapping launch with another robot: base_link and /tutorial_bot/laser/scan, not mybot's."""
    import navlab

    session = navlab.launch("mapping", robot=str(XACRO), explore="false")
    assert session.args["base_frame"] == "base_link"
    assert session.args["scan_topic"] == "/tutorial_bot/laser/scan"
    node = Node("drv", context=Context(session.executor))
    pub = node.create_publisher(msgs.Twist, "cmd_vel", 10)
    node.create_timer(0.1, lambda: pub.publish(msgs.twist(0.0, 0.6)))
    session.run(4.0)
    slam = session.node("slam_gmapping")
    grid = slam.current_map()  # type: ignore[attr-defined]
    assert slam.scans_processed >= 5 and grid is not None  # type: ignore[attr-defined]
    assert int((grid.data >= 65).sum()) > 100  # the room's walls are in the map


def test_a_torque_tag_drives_as_noetic_drives_it_with_wheel_torque_5(tmp_path: Path) -> None:
    """Noetic's plugin reads <wheelTorque> (default 5 N m), not <torque>: a robot whose file says <torque>0.001</torque>
    drives exactly as one with <wheelTorque>5</wheelTorque>, while <wheelTorque>0.001</wheelTorque> barely moves it."""
    import shutil

    src = Path(__file__).parents[1] / "fixtures" / "ros_ws" / "my_description"
    x_after: dict[str, float] = {}
    for label, tag in (
        ("torque", "<torque>0.001</torque>"),
        ("default", "<wheelTorque>5</wheelTorque>"),
        ("weak", "<wheelTorque>0.001</wheelTorque>"),
    ):
        pkg = tmp_path / label / "my_description"
        shutil.copytree(src, pkg)
        gz = pkg / "urdf" / "my_robot.gazebo.xacro"
        gz.write_text(gz.read_text().replace("<wheelTorque>10</wheelTorque>", tag))
        _, gazebo = _drive(load_robot(pkg / "urdf" / "my_robot.urdf.xacro"), [(0.05, 0.2, 0.0)], 2.0)
        x_after[label] = gazebo.sim.base_pose2d()[0]  # type: ignore[attr-defined]
    assert x_after["torque"] == x_after["default"] and x_after["default"] > 0.3
    assert x_after["weak"] < 0.5 * x_after["default"]


def test_p3d_plugins_publish_where_noetic_publishes(tmp_path: Path) -> None:
    """A p3d plugin with <bodyName> and <topicName> publishes the true pose there (frame default world); one
    without <topicName> does not load, as in Noetic, and says so."""
    import shutil

    pkg = tmp_path / "my_description"
    shutil.copytree(Path(__file__).parents[1] / "fixtures" / "ros_ws" / "my_description", pkg)
    gz = pkg / "urdf" / "my_robot.gazebo.xacro"
    gz.write_text(
        gz.read_text().replace(
            "</robot>",
            """
  <gazebo><plugin name="truth" filename="libgazebo_ros_p3d.so"><bodyName>base_link</bodyName>
    <topicName>truth/odom</topicName><robotNamespace>my_robot</robotNamespace><updateRate>20</updateRate></plugin></gazebo>
  <gazebo><plugin name="broken" filename="libgazebo_ros_p3d.so"><bodyName>base_link</bodyName></plugin></gazebo>
</robot>""",
        )
    )
    robot = load_robot(pkg / "urdf" / "my_robot.urdf.xacro")
    assert [(p.link, p.topic, p.frame_id, p.update_rate) for p in robot.ground_truths] == [
        ("base_link", "/my_robot/truth/odom", "world", 20.0)
    ]
    assert any("no <topicName>" in w and "does not load" in w for w in robot.warnings)
    ex, _ = _drive(robot, [(0.05, 0.2, 0.0)], 0.05)
    got: list[object] = []
    Node("listener", context=Context(ex)).create_subscription(msgs.Odometry, "/my_robot/truth/odom", got.append, 10)
    ex.run(1.0)
    assert len(got) == 20 and got[-1].header.frame_id == "world"  # type: ignore[attr-defined]
    assert got[-1].pose.pose.position.x > 0.05  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    ("tag", "odom", "tf"),
    [
        ("<publishTf>false</publishTf>", False, False),
        ("<publishOdomTF>false</publishOdomTF>", True, False),
        ("", True, True),
    ],
)
def test_publish_tf_and_publish_odom_tf_as_noetic(tmp_path: Path, tag: str, odom: bool, tf: bool) -> None:
    """Noetic: <publishTf>false publishes no odometry at all; <publishOdomTF>false keeps the topic, drops the tf."""
    import shutil

    pkg = tmp_path / "my_description"
    shutil.copytree(Path(__file__).parents[1] / "fixtures" / "ros_ws" / "my_description", pkg)
    gz = pkg / "urdf" / "my_robot.gazebo.xacro"
    gz.write_text(gz.read_text().replace("<publishOdomTF>true</publishOdomTF>", tag))
    ex = Executor(seed=0)
    launch_sim(ex, world=make_room(), robot=load_robot(pkg / "urdf" / "my_robot.urdf.xacro"))
    got: list[object] = []
    Node("listener", context=Context(ex)).create_subscription(msgs.Odometry, "/odom", got.append, 10)
    ex.run(0.5)
    assert bool(got) is odom
    assert ex.tf.can_transform("odom", "base_footprint") is tf


def test_wheel_acceleration_follows_noetics_rule() -> None:
    """gazebo_ros_diff_drive (Noetic): each wheel's instructed speed moves by its measured error, at most
    wheelAcceleration x dt; when either wheel is within 0.01 m/s of its target, both get their targets at once."""
    from navlab.sim.diffdrive import noetic_wheel_commands

    cmd, instr = noetic_wheel_commands((1.0, 1.0), (0.0, 0.0), (0.0, 0.0), 2.0, 0.1, near=0.01)
    assert cmd == instr == pytest.approx((0.2, 0.2))
    cmd, _ = noetic_wheel_commands((1.0, -1.0), (0.995, 0.0), (0.4, 0.0), 2.0, 0.1, near=0.01)
    assert cmd == (1.0, -1.0)  # the left wheel is near its target: the right one jumps too, as in Gazebo
    assert noetic_wheel_commands((1.0, 1.0), (0.0, 0.0), (0.0, 0.0), 0.0, 0.1, near=0.01)[0] == (1.0, 1.0)
