"""Hardware in the loop, the paper's point: navlab's map_server + amcl + move_base (``sim:=false``) drive a
robot that lives in another process on the ROS graph (here a second navlab run playing the real robot),
reading its scan, odom and tf and following its /clock; a rospy action client's goal is reached."""

from __future__ import annotations

import math
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
from conftest import ros, rospy, run_with_ros

from navlab.ros1.live import LiveRun


@pytest.fixture(scope="module")
def robot(ros_env: dict[str, str]) -> Iterator[subprocess.Popen[bytes]]:
    """The "real robot": a navlab simulation alone, on the wire (real time)."""
    proc = subprocess.Popen([str(Path(sys.executable).parent / "navlab"), "launch", "sim", "ros:=true", "world:=room",
                             "--duration", "300", "--quiet"], env=ros_env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
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


def test_move_base_drives_the_robot_of_another_process_to_the_goal(hil: LiveRun, ros_env: dict[str, str]) -> None:
    assert "/gazebo" not in hil.ex.nodes  # no simulator in this run
    out = rospy(ros_env, """
import rospy, actionlib
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
rospy.init_node('hil_goal_sender')
client = actionlib.SimpleActionClient('move_base', MoveBaseAction)
assert client.wait_for_server(rospy.Duration(15)), 'no move_base action server'
goal = MoveBaseGoal()
goal.target_pose.header.frame_id = 'map'
goal.target_pose.pose.position.x = 1.5
goal.target_pose.pose.orientation.w = 1.0
client.send_goal(goal)
client.wait_for_result(rospy.Duration(90))
print(client.get_state())
""", timeout=120)
    assert out.strip() == "3"  # SUCCEEDED
    truth = yaml.safe_load(ros(ros_env, "rostopic", "echo", "-n", "1", "/ground_truth/odom/pose/pose/position")
                           .split("---")[0])
    assert math.hypot(truth["x"] - 1.5, truth["y"]) < 0.3  # where the robot really is, in its own process
