"""Helpers of the ROS 1 tests, in a module of their own: `from conftest import` would pick whichever tests
folder's conftest was imported first when several folders run together."""

from __future__ import annotations

import shutil
import socket
import struct
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from navlab.ros1.live import LiveRun

SYSTEM_PYTHON = "/usr/bin/python3"
TOOLS = {
    "Xvfb": "xvfb",
    "rviz": "rviz",
    "rosmaster": "python3-rosmaster",
    "rostopic": "python3-rostopic",
    "rosbag": "python3-rosbag",
    "rosservice": "python3-rosservice",
    "rosparam": "python3-rosparam",
    "rosnode": "python3-rosnode",
}


def require(tool: str) -> str:
    path = shutil.which(tool)
    if path is None:
        pytest.fail(f"{tool} is missing: `make install` installs it (apt-get install {TOOLS.get(tool, tool)})")
    return path


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def ros(env: dict[str, str], *cmd: str, timeout: float = 30.0, ok: tuple[int, ...] = (0,)) -> str:
    """Run a ROS command line tool; its stdout (the test fails with its stderr if it fails)."""
    done = subprocess.run([require(cmd[0]), *cmd[1:]], env=env, capture_output=True, text=True, timeout=timeout)
    assert done.returncode in ok, f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr[-2000:]}"
    return done.stdout


def rospy(env: dict[str, str], code: str, timeout: float = 60.0) -> str:
    """Run a rospy script under the system Python (where ROS lives); its stdout."""
    done = subprocess.run([SYSTEM_PYTHON, "-c", code], env=env, capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, f"rospy script failed ({done.returncode}): {done.stderr[-2000:]}"
    return done.stdout


def send_move_base_goal(env: dict[str, str], x: float, y: float, timeout: float = 60.0) -> int:
    """A rospy ``SimpleActionClient('move_base', MoveBaseAction)`` sends (x, y) in map; the final goal state
    (actionlib_msgs/GoalStatus: 3 is SUCCEEDED)."""
    out = rospy(
        env,
        f"""
import rospy, actionlib
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
rospy.init_node('goal_sender', anonymous=True)
client = actionlib.SimpleActionClient('move_base', MoveBaseAction)
assert client.wait_for_server(rospy.Duration(15)), 'no move_base action server'
goal = MoveBaseGoal()
goal.target_pose.header.frame_id = 'map'
goal.target_pose.pose.position.x = {x}
goal.target_pose.pose.position.y = {y}
goal.target_pose.pose.orientation.w = 1.0
client.send_goal(goal)
client.wait_for_result(rospy.Duration({timeout}))
print(client.get_state())
""",
        timeout=timeout + 30,
    )
    return int(out.strip())


def run_with_ros(env: dict[str, str], launch: str, *, follow_clock: bool = False, **args: str) -> LiveRun:
    """``launch`` started here and offered on the master of ``env`` (real time, or following /clock)."""
    return LiveRun(launch, master=env["ROS_MASTER_URI"], follow_clock=follow_clock, **args)


def read_xwd(path: Path) -> np.ndarray:
    """The RGB pixels (H, W, 3) of an X window dump, as Xvfb writes its screen with ``-fbdir`` (32-bit TrueColor)."""
    raw = path.read_bytes()
    fields = struct.unpack(">25I", raw[:100])
    header_size, width, height, bytes_per_line, ncolors = fields[0], fields[4], fields[5], fields[12], fields[19]
    offset = header_size + 12 * ncolors
    rows = np.frombuffer(raw, dtype=np.uint8, count=bytes_per_line * height, offset=offset).reshape(height, -1)
    return rows[:, : width * 4].reshape(height, width, 4)[..., [2, 1, 0]].copy()  # BGRX in memory


class Screen:
    """A virtual X display (Xvfb) whose framebuffer is readable as a file."""

    def __init__(self, folder: Path, width: int = 800, height: int = 600) -> None:
        self.folder = folder
        self.display = f":{free_port() % 500 + 100}"
        self.proc = subprocess.Popen(
            [
                require("Xvfb"),
                self.display,
                "-screen",
                "0",
                f"{width}x{height}x24",
                "-fbdir",
                str(folder),
                "-nolisten",
                "tcp",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        deadline = time.monotonic() + 10
        while not (folder / "Xvfb_screen0").exists() and time.monotonic() < deadline:
            time.sleep(0.1)

    def grab(self) -> np.ndarray:
        return read_xwd(self.folder / "Xvfb_screen0")

    def close(self) -> None:
        self.proc.terminate()
        self.proc.wait(5)
