"""Hardware in the loop, the paper's point: navlab's map_server + amcl + move_base (``sim:=false``) drive a
robot that lives in another process on the ROS graph (here a second navlab run playing the real robot),
reading its scan, odom and tf and following its /clock; a rospy action client's goal is reached."""

from __future__ import annotations

import math
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import yaml
from ros1_helpers import free_port, require, ros, run_with_ros, send_move_base_goal

from navlab.ros1.live import LiveRun


@pytest.fixture(scope="module")
def robot(ros_env: dict[str, str]) -> Iterator[subprocess.Popen[bytes]]:
    """The "real robot": a navlab simulation alone, on the wire (real time)."""
    proc = subprocess.Popen(
        [
            str(Path(sys.executable).parent / "navlab"),
            "launch",
            "sim",
            "ros:=true",
            "world:=room",
            "--duration",
            "300",
            "--quiet",
        ],
        env=ros_env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    ros(ros_env, "rostopic", "echo", "-n", "1", "/odom/header/stamp", timeout=60)  # it is up
    try:
        yield proc
    finally:
        proc.terminate()
        proc.wait(10)


@pytest.fixture(scope="module")
def hil(ros_env: dict[str, str], room_map: Path, robot: subprocess.Popen[bytes]) -> Iterator[LiveRun]:
    run = run_with_ros(ros_env, "navigation", map=str(room_map), sim="false", follow_clock=True)
    try:
        yield run
    finally:
        run.close()


@pytest.fixture(scope="module")
def recording(ros_env: dict[str, str], tmp_path_factory: pytest.TempPathFactory) -> Iterator[Callable[[], Path]]:
    """What the robot sends while the first test drives it: a ROS 1 bag with /clock, for `rosbag play`
    (call the fixture's value to wait for the bag to be closed)."""
    bag = tmp_path_factory.mktemp("bag") / "robot.bag"
    rec = subprocess.Popen(
        [
            require("rosbag"),
            "record",
            "-O",
            str(bag),
            "--duration=10",
            "/clock",
            "/tf",
            "/tf_static",
            "/odom",
            "/mybot/laser/scan",
            "/ground_truth/odom",
        ],
        env=ros_env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    time.sleep(2.0)  # subscribed before the goal is sent

    def finished() -> Path:
        rec.wait(30)
        return bag

    yield finished
    rec.wait(30)


def test_move_base_drives_the_robot_of_another_process_to_the_goal(
    hil: LiveRun, ros_env: dict[str, str], recording: Callable[[], Path]
) -> None:
    assert "/gazebo" not in hil.ex.nodes  # no simulator in this run
    assert send_move_base_goal(ros_env, 1.5, 0.0, timeout=90) == 3  # SUCCEEDED
    truth = yaml.safe_load(
        ros(ros_env, "rostopic", "echo", "-n", "1", "/ground_truth/odom/pose/pose/position").split("---")[0]
    )
    assert math.hypot(truth["x"] - 1.5, truth["y"]) < 0.3  # where the robot really is, in its own process


def test_amcl_localizes_on_a_rosbag_play_of_the_robot(
    recording: Callable[[], Path], room_map: Path, ros_env: dict[str, str], tmp_path: Path
) -> None:
    """The recording of the drive above (its map -> odom left out), played by `rosbag play` on a fresh master to
    map_server + amcl (``localization sim:=false``): amcl ends where the recorded ground truth ends."""
    from rosbags.highlevel import AnyReader

    filtered = tmp_path / "robot_only.bag"  # the robot's topics, without the navigation run's map -> odom
    ros(
        ros_env,
        "rosbag",
        "filter",
        str(recording()),
        str(filtered),
        "topic != '/tf' or m.transforms[0].child_frame_id != 'odom'",
        timeout=60,
    )
    with AnyReader([filtered]) as reader:
        truth = [
            reader.deserialize(raw, c.msgtype)
            for c, _, raw in reader.messages([c for c in reader.connections if c.topic == "/ground_truth/odom"])
        ]
    end = truth[-1].pose.pose.position
    port = free_port()
    env = {**ros_env, "ROS_MASTER_URI": f"http://127.0.0.1:{port}/"}
    master = subprocess.Popen(
        [require("rosmaster"), "--core", "-p", str(port)], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        time.sleep(1.5)
        start = truth[0].pose.pose.position
        play = subprocess.Popen(
            [require("rosbag"), "play", "--delay=3", str(filtered)],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        run = LiveRun(
            "localization",
            master=env["ROS_MASTER_URI"],
            follow_clock=True,
            map=str(room_map),
            sim="false",
            x=str(start.x),
            y=str(start.y),
        )
        try:
            play.wait(60)
            time.sleep(1.0)  # the bag's clock has stopped, and with it the run: its tf can be read from here
            x, y, _ = run.ex.tf.lookup_pose2d("map", "chassis", None)
        finally:
            run.close()
    finally:
        master.terminate()
        master.wait(5)
    assert math.hypot(end.x - start.x, end.y - start.y) > 1.0  # the robot did drive in the recording
    assert math.hypot(x - end.x, y - end.y) < 0.2
