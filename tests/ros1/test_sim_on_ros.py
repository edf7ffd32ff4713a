"""The simulation alone on a real ROS 1 graph: driven by `rostopic pub /cmd_vel`, recorded by `rosbag record`,
robust to garbage peers; and navlab's own master serving real ROS tools."""

from __future__ import annotations

import math
import socket
import struct
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
from ros1_helpers import free_port, ros, rospy, run_with_ros

from navlab.ros1.live import LiveRun


@pytest.fixture(scope="module")
def sim(ros_env: dict[str, str]) -> Iterator[LiveRun]:
    run = run_with_ros(ros_env, "sim", world="room")
    try:
        yield run
    finally:
        run.close()


def _truth(run: LiveRun) -> tuple[float, float]:
    pose = run.call(lambda: run.session.node("gazebo").sim.base_pose2d())
    return float(pose[0]), float(pose[1])


def test_rostopic_pub_cmd_vel_drives_the_robot_the_commanded_distance(sim: LiveRun, ros_env: dict[str, str]) -> None:
    got: list[tuple[int, float]] = []
    sim.call(lambda: sim.ex.add_listener(lambda t, m, ns: got.append((ns, m.linear.x)) if t == "/cmd_vel" else None))
    x0, y0 = _truth(sim)
    ros(
        ros_env,
        "timeout",
        "-s",
        "INT",
        "4",
        "rostopic",
        "pub",
        "-r",
        "20",
        "/cmd_vel",
        "geometry_msgs/Twist",
        "{linear: {x: 0.2}}",
        ok=(124,),
    )
    ros(ros_env, "rostopic", "pub", "-1", "/cmd_vel", "geometry_msgs/Twist", "{}")
    stop = [ns for ns, v in got if v == 0.0]
    moving = [ns for ns, v in got if v > 0]
    assert moving and stop, got[:5]
    x1, y1 = _truth(sim)
    commanded = 0.2 * (stop[0] - moving[0]) / 1e9  # m, in simulated time between the first and the stop command
    assert abs(math.hypot(x1 - x0, y1 - y0) - commanded) < 0.15 * commanded


def test_rosbag_records_the_run_with_its_counts_and_types(
    sim: LiveRun, ros_env: dict[str, str], tmp_path: Path
) -> None:
    bag = tmp_path / "run.bag"
    ros(ros_env, "rosbag", "record", "-O", str(bag), "--duration=4", "/odom", "/mybot/laser/scan", "/tf", timeout=60)
    info = yaml.safe_load(ros(ros_env, "rosbag", "info", "--yaml", str(bag)))
    topics = {t["topic"]: t for t in info["topics"]}
    assert topics["/mybot/laser/scan"]["type"] == "sensor_msgs/LaserScan"
    assert topics["/odom"]["type"] == "nav_msgs/Odometry"
    assert topics["/tf"]["type"] == "tf2_msgs/TFMessage"
    assert 100 < topics["/mybot/laser/scan"]["messages"] < 200  # 40 Hz for ~4 s of real time


def test_a_peer_sending_garbage_is_dropped_and_the_run_goes_on(
    sim: LiveRun, ros_env: dict[str, str], caplog: pytest.LogCaptureFixture
) -> None:
    port = sim.bridge.tcpros.port
    with socket.create_connection(("127.0.0.1", port)) as s:
        s.sendall(struct.pack("<I", 12) + b"\xff" * 12)
        assert s.recv(100) == b""  # closed on us
    assert "dropped peer" in caplog.text
    assert "average rate" in ros(ros_env, "timeout", "-s", "INT", "3", "rostopic", "hz", "/odom", ok=(124,))


def test_navlab_roscore_serves_real_rospy_nodes_and_rosparam(ros_env: dict[str, str], tmp_path: Path) -> None:
    port = free_port()
    env = {**ros_env, "ROS_MASTER_URI": f"http://127.0.0.1:{port}/"}
    core = subprocess.Popen(
        [str(Path(sys.executable).parent / "navlab"), "roscore", "-p", str(port)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert "ROS master at" in (core.stdout.readline() if core.stdout else "")
        ros(env, "rosparam", "set", "/demo/gain", "2.5")
        assert float(ros(env, "rosparam", "get", "/demo/gain")) == 2.5
        out = rospy(
            env,
            """
import rospy
from std_msgs.msg import String
rospy.init_node('talker_listener')
got = []
rospy.Subscriber('/chatter', String, lambda m: got.append(m.data))
pub = rospy.Publisher('/chatter', String, queue_size=1, latch=True)
pub.publish('hello')
t = rospy.Time.now() + rospy.Duration(5)
while not got and rospy.Time.now() < t:
    rospy.sleep(0.05)
print(got[0], rospy.search_param('gain') or '')
""",
        )
        assert out.split()[0] == "hello"
        assert "/chatter" in ros(env, "rostopic", "list")
    finally:
        core.terminate()
        core.wait(5)


def test_navlab_sim_ros_starts_its_own_master_when_none_answers(ros_env: dict[str, str]) -> None:
    env = {**ros_env, "ROS_MASTER_URI": f"http://127.0.0.1:{free_port()}/"}  # nothing listens there
    env.pop("ROS_IP")  # and nothing says where to listen: loopback
    proc = subprocess.Popen(
        [str(Path(sys.executable).parent / "navlab"), "sim", "--ros", "--duration", "60", "--quiet"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 30
        listed = ""
        while "/odom" not in listed and time.monotonic() < deadline:
            time.sleep(0.5)
            done = subprocess.run(["/usr/bin/rostopic", "list"], env=env, capture_output=True, text=True, timeout=10)
            listed = done.stdout
        assert "/odom" in listed and "/mybot/laser/scan" in listed
    finally:
        proc.terminate()
        _, err = proc.communicate(timeout=15)
    assert "started navlab's own" in err and "loopback only" in err


def test_a_subscriber_that_never_reads_does_not_slow_the_run(sim: LiveRun) -> None:
    """A TCPROS subscriber that stops reading: its queue drops the oldest scans, the run keeps real time."""
    from navlab.ros1.tcpros import encode_header, recv_header

    pub = sim.bridge.tcpros.publications["/mybot/laser/scan"]
    with socket.socket() as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # before connecting: a small receive window
        s.connect(("127.0.0.1", sim.bridge.tcpros.port))
        s.sendall(
            encode_header(
                {"callerid": "/stuck", "topic": "/mybot/laser/scan", "md5sum": "*", "type": "sensor_msgs/LaserScan"}
            )
        )
        assert recv_header(s)["type"] == "sensor_msgs/LaserScan"
        sim0, wall0 = sim.ex.now_ns, time.monotonic()
        time.sleep(5.0)  # 200 scans of ~6 kB: far more than the small window and the queue (100) hold
        ratio = (sim.ex.now_ns - sim0) / 1e9 / (time.monotonic() - wall0)
        stuck = next(c for c in pub.connections if c.peer.startswith("/stuck"))
        assert stuck.dropped > 0
    assert 0.9 < ratio < 1.1
