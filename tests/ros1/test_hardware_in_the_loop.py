"""Hardware in the loop, the paper's point: navlab's map_server + amcl + move_base (``sim:=false``) drive a
robot that lives in another process on the ROS graph (here a second navlab run playing the real robot),
reading its scan, odom and tf and following its /clock; a rospy action client's goal is reached."""

from __future__ import annotations

import math
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
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
def drive(ros_env: dict[str, str], hil: LiveRun, tmp_path_factory: pytest.TempPathFactory) -> tuple[int, Path]:
    """move_base drives the robot to (1.5, 0) in map while `rosbag record` records what the robot sends (with
    /clock, for `rosbag play`) from before the goal is sent until its result: the goal's final state and the bag."""
    bag = tmp_path_factory.mktemp("bag") / "robot.bag"
    rec = subprocess.Popen(
        [
            require("rosbag"),
            "record",
            "-O",
            str(bag),
            "/clock",
            "/tf",
            "/tf_static",
            "/odom",
            "/mybot/laser/scan",
            "/ground_truth/odom",
            "__name:=hil_recorder",
        ],
        env=ros_env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 60  # subscribed before the goal is sent (slow on a loaded machine)
        while "/hil_recorder" not in ros(ros_env, "rostopic", "info", "/ground_truth/odom", ok=(0, 1)):
            assert rec.poll() is None, f"rosbag record exited ({rec.returncode})"
            assert time.monotonic() < deadline, "rosbag record did not subscribe to /ground_truth/odom in 60 s"
            time.sleep(0.2)
        state = send_move_base_goal(ros_env, 1.5, 0.0, timeout=90)
    finally:
        rec.send_signal(signal.SIGINT)  # `rosbag record` closes the bag on SIGINT, as on Ctrl-C
        rec.wait(30)
    deadline = time.monotonic() + 60  # its recorder child writes the index and renames the .active file
    while not bag.exists():
        assert time.monotonic() < deadline, f"rosbag record left no {bag.name} 60 s after SIGINT"
        time.sleep(0.2)
    return state, bag


def test_move_base_drives_the_robot_of_another_process_to_the_goal(
    hil: LiveRun, ros_env: dict[str, str], drive: tuple[int, Path]
) -> None:
    assert "/gazebo" not in hil.ex.nodes  # no simulator in this run
    assert drive[0] == 3  # SUCCEEDED
    truth = yaml.safe_load(
        ros(ros_env, "rostopic", "echo", "-n", "1", "/ground_truth/odom/pose/pose/position").split("---")[0]
    )
    assert math.hypot(truth["x"] - 1.5, truth["y"]) < 0.3  # where the robot really is, in its own process


def test_amcl_localizes_on_a_rosbag_play_of_the_robot(
    drive: tuple[int, Path], room_map: Path, ros_env: dict[str, str], tmp_path: Path
) -> None:
    """The recording of the drive above (its map -> odom left out), played by `rosbag play` on a fresh master to
    map_server + amcl (``localization sim:=false``): amcl ends where the recorded ground truth ends."""
    from rosbags.highlevel import AnyReader

    filtered = tmp_path / "robot_only.bag"  # the robot's topics, without the navigation run's map -> odom
    ros(
        ros_env,
        "rosbag",
        "filter",
        str(drive[1]),
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
            play.wait(120)
            stamp = truth[-1].header.stamp
            # rosbag play publishes /clock at 100 Hz, so its last tick may fall up to one period before the last
            # message's stamp: caught up means within two periods of it
            end_ns = stamp.sec * 1_000_000_000 + stamp.nanosec - 20_000_000
            deadline = time.monotonic() + 60  # the run follows the bag's /clock: wait until it has caught up
            while run.ex.now_ns < end_ns:
                assert time.monotonic() < deadline, f"the run reached {run.ex.now_ns / 1e9:.2f} of {end_ns / 1e9:.2f} s"
                time.sleep(0.1)
            time.sleep(1.0)  # its last callbacks run; the clock has stopped, and with it the run: read its tf
            x, y, _ = run.ex.tf.lookup_pose2d("map", "chassis", None)
        finally:
            run.close()
    finally:
        master.terminate()
        master.wait(5)
    assert math.hypot(end.x - start.x, end.y - start.y) > 1.0  # the robot did drive in the recording
    assert math.hypot(x - end.x, y - end.y) < 0.2
