"""navlab's navigation stack on a real ROS 1 graph: real rostopic, rosparam, rosservice, tf2 and actionlib
peers (Debian's Noetic tools) read it and drive it through a real rosmaster. One run serves every test."""

from __future__ import annotations

import re
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from ros1_helpers import Screen, require, ros, rospy, run_with_ros, send_move_base_goal

from navlab.core.launch import resources_dir
from navlab.ros1.live import LiveRun


@pytest.fixture(scope="module")
def nav(ros_env: dict[str, str], room_map: Path) -> Iterator[LiveRun]:
    run = run_with_ros(ros_env, "navigation", world="room", map=str(room_map))
    try:
        yield run
    finally:
        run.close()


def test_rostopic_lists_the_runs_topics_with_ros1_types_and_hz_holds_the_scan_rate(
    nav: LiveRun, ros_env: dict[str, str]
) -> None:
    listed = ros(ros_env, "rostopic", "list").split()
    for topic in (
        "/mybot/laser/scan",
        "/odom",
        "/tf",
        "/tf_static",
        "/map",
        "/clock",
        "/cmd_vel",
        "/move_base/goal",
        "/move_base/status",
        "/amcl_pose",
    ):
        assert topic in listed
    assert ros(ros_env, "rostopic", "type", "/odom").strip() == "nav_msgs/Odometry"
    assert ros(ros_env, "rostopic", "type", "/tf").strip() == "tf2_msgs/TFMessage"
    out = ros(ros_env, "timeout", "-s", "INT", "5", "rostopic", "hz", "/mybot/laser/scan", ok=(124,))
    rates = [float(r) for r in re.findall(r"average rate: ([0-9.]+)", out)]
    assert rates and 34.0 < rates[-1] < 46.0, out  # 40 Hz in real time


def test_the_map_is_latched_and_echoed_with_its_size(nav: LiveRun, ros_env: dict[str, str]) -> None:
    out = ros(ros_env, "rostopic", "echo", "-n", "1", "/map/info")
    grid = nav.call(lambda: nav.session.node("map_server").grid)
    assert f"width: {grid.width}" in out and f"height: {grid.height}" in out


def test_parameters_and_robot_description_are_on_the_parameter_server(nav: LiveRun, ros_env: dict[str, str]) -> None:
    ours = nav.session.node("move_base").get_parameter("controller_frequency")
    assert float(ros(ros_env, "rosparam", "get", "/move_base/controller_frequency")) == ours
    assert float(ros(ros_env, "rosparam", "get", "/move_base/local_costmap/inflation_radius")) > 0
    assert "<robot" in ros(ros_env, "rosparam", "get", "/robot_description")


def test_tf2_looks_up_map_to_chassis_as_navlab_does(nav: LiveRun, ros_env: dict[str, str]) -> None:
    out = rospy(
        ros_env,
        """
import rospy, tf2_ros
rospy.init_node('tf_probe')
buf = tf2_ros.Buffer(); tf2_ros.TransformListener(buf)
t = buf.lookup_transform('map', 'chassis', rospy.Time(0), rospy.Duration(10)).transform.translation
print(t.x, t.y)
""",
    )
    x, y = map(float, out.split())
    nx, ny, _ = nav.call(lambda: nav.ex.tf.lookup_pose2d("map", "chassis", None))
    assert abs(x - nx) < 0.05 and abs(y - ny) < 0.05


def test_services_clear_costmaps_static_map_and_make_plan(nav: LiveRun, ros_env: dict[str, str]) -> None:
    ros(ros_env, "rosservice", "call", "/move_base/clear_costmaps")
    assert ros(ros_env, "rosservice", "type", "/static_map").strip() == "nav_msgs/GetMap"
    out = rospy(
        ros_env,
        """
import rospy
from nav_msgs.srv import GetMap, GetPlan
from geometry_msgs.msg import PoseStamped
rospy.init_node('srv_probe')
rospy.wait_for_service('/static_map', 10)
m = rospy.ServiceProxy('/static_map', GetMap)().map
goal = PoseStamped(); goal.header.frame_id = 'map'; goal.pose.position.x = 2.0; goal.pose.orientation.w = 1.0
plan = rospy.ServiceProxy('/move_base/make_plan', GetPlan)(start=PoseStamped(), goal=goal, tolerance=0.0).plan
print(m.info.width, len(plan.poses), plan.poses[-1].pose.position.x)
""",
    )
    width, n, last_x = out.split()
    assert int(width) > 0 and int(n) > 5 and abs(float(last_x) - 2.0) < 0.1


def test_a_use_sim_time_node_follows_the_clock(nav: LiveRun, ros_env: dict[str, str]) -> None:
    out = rospy(
        ros_env,
        """
import rospy
rospy.set_param('/use_sim_time', True)
rospy.init_node('clock_probe')
rospy.sleep(0.5)  # sleeps on /clock: returns only if the clock runs
print(rospy.get_time())
rospy.delete_param('/use_sim_time')
""",
    )
    now = nav.ex.now_ns / 1e9
    assert 0.5 < float(out) <= now + 0.1 and now - float(out) < 5.0


def test_a_simple_action_client_drives_move_base_to_its_goal(nav: LiveRun, ros_env: dict[str, str]) -> None:
    assert send_move_base_goal(ros_env, 1.0, 0.0, timeout=60) == 3  # SUCCEEDED
    x, y, _ = nav.call(lambda: nav.ex.tf.lookup_pose2d("map", "chassis", None))
    assert abs(x - 1.0) < 0.3 and abs(y) < 0.3


SCALE = 30.0  # pixels per metre of the saved config's top-down view


def _near(mask: np.ndarray, pts: np.ndarray, radius: int) -> np.ndarray:
    """For each pixel (col, row) of ``pts``: whether ``mask`` is set within ``radius`` pixels."""
    h, w = mask.shape
    out = np.zeros(len(pts), dtype=bool)
    for k, (c, r) in enumerate(pts.astype(int)):
        out[k] = mask[max(r - radius, 0) : min(r + radius + 1, h), max(c - radius, 0) : min(c + radius + 1, w)].any()
    return out


def test_real_rviz_shows_the_map_scan_robot_and_plan_where_navlab_has_them(
    nav: LiveRun, ros_env: dict[str, str], tmp_path: Path
) -> None:
    """Runs last in this module (it freezes the run): rviz with a saved config, compared by pixels with where
    navlab has the map's walls, the last scan, the robot and the global plan (projected with the view's scale)."""
    scans: list[object] = []
    nav.call(lambda: nav.ex.add_listener(lambda t, m, ns: scans.append(m) if t == "/mybot/laser/scan" else None))
    nav.call(lambda: nav.session.node("move_base").send_goal(-2.5, 1.0, 0.0))
    ros(ros_env, "rosparam", "set", "/use_sim_time", "true")  # rviz keeps the run's time (from /clock)
    screen = Screen(tmp_path)
    env = {
        **ros_env,
        "DISPLAY": screen.display,
        "LIBGL_ALWAYS_SOFTWARE": "1",
        "ROS_PACKAGE_PATH": str(resources_dir() / "robots"),
    }  # package://mybot_description meshes
    viewer = subprocess.Popen(
        [require("rviz"), "-d", str(Path(__file__).parent / "data" / "navlab.rviz")],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        red = lambda img: (img[..., 0] > 200) & (img[..., 1] < 60) & (img[..., 2] < 60)  # noqa: E731
        green = lambda img: (img[..., 1] > 200) & (img[..., 0] < 60) & (img[..., 2] < 60)  # noqa: E731
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            time.sleep(1.0)
            img = screen.grab()
            if red(img).sum() > 200 and green(img).sum() > 50:
                break
        nav.call(lambda: nav.ex.stop())  # freeze the run: rviz keeps showing its last messages
        time.sleep(2.0)
        img = screen.grab()
    finally:
        viewer.terminate()
        viewer.wait(10)
        screen.close()
        ros(ros_env, "rosparam", "delete", "/use_sim_time")
    Image.fromarray(img).save(tmp_path / "rviz.png")
    ex = nav.ex
    rx, ry, _ryaw = ex.tf.lookup_pose2d("map", "chassis", None)
    orange = (img[..., 0] > 200) & (img[..., 1] > 60) & (img[..., 1] < 180) & (img[..., 2] < 60)
    rows, cols = np.nonzero(orange)
    assert len(rows) > 30, "no robot model drawn"
    center = np.array([cols.mean(), rows.mean()])  # the robot's chassis: where map point (rx, ry) is drawn

    def to_px(xy: np.ndarray) -> np.ndarray:
        return center + np.column_stack([(xy[:, 0] - rx) * SCALE, -(xy[:, 1] - ry) * SCALE])

    def inside(px: np.ndarray) -> np.ndarray:
        return np.hypot(*(px - center).T) < 170

    scan = scans[-1]
    angles = scan.angle_min + scan.angle_increment * np.arange(len(scan.ranges))
    ranges = np.asarray(scan.ranges)
    ok = np.isfinite(ranges) & (ranges < scan.range_max)
    lx, ly, lyaw = ex.tf.lookup_pose2d("map", scan.header.frame_id, None)
    hits = np.column_stack([lx + ranges[ok] * np.cos(lyaw + angles[ok]), ly + ranges[ok] * np.sin(lyaw + angles[ok])])
    px = to_px(hits)
    px = px[inside(px)]
    assert len(px) > 50 and _near(red(img), px, 4).mean() > 0.8, "the scan is not where navlab measured it"

    grid = nav.session.node("map_server").grid
    px = to_px(grid.cell_to_world(np.argwhere(np.asarray(grid.data) > 50)[:, ::-1]))  # (col, row) cells
    px = px[inside(px)]
    dark = img.max(axis=2) < 80
    assert len(px) > 50 and _near(dark | red(img), px, 3).mean() > 0.8, "the map's walls are not drawn"

    (plan,) = ex.topics["/move_base/NavfnROS/plan"].latched.values()
    px = to_px(np.array([[p.pose.position.x, p.pose.position.y] for p in plan.poses]))
    px = px[inside(px) & (np.hypot(*(px - center).T) > 15)]  # the robot model covers the plan's end
    assert len(px) > 5 and _near(green(img), px, 4).mean() > 0.8, "the global plan is not drawn"
