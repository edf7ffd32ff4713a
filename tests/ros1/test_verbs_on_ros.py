"""`--ros` on navlab's experiment verbs (navigate, map) and on `navlab view`: a real rospy node on a real rosmaster
receives the run's messages while it runs and sees its nodes, topics and move_base's action interface."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

from ros1_helpers import SYSTEM_PYTHON

NAVLAB = str(Path(sys.executable).parent / "navlab")

# Started before navlab: waits for the first message of a topic, then reads the master's system state
# while the run still goes on.
_LISTENER = """
import json, sys, rosgraph, rospy
from importlib import import_module
topic, pkg, cls, field = sys.argv[1:5]
rospy.init_node('verb_listener', anonymous=True)
msg = rospy.wait_for_message(topic, getattr(import_module(pkg + '.msg'), cls), timeout=120)
for part in field.split('.'):
    msg = getattr(msg, part)
pubs, subs, _ = rosgraph.Master('/verb_listener').getSystemState()
print(json.dumps({"value": msg, "pubs": {t: n for t, n in pubs}, "subs": {t: n for t, n in subs}}))
"""


def _while_running(
    ros_env: dict[str, str], argv: list[str], topic: str, msg_type: str, field: str, *, until_done: bool
) -> tuple[dict[str, Any], str]:
    """Run ``navlab ARGV`` on the master of ``ros_env`` while a rospy node waits for ``topic``'s first message;
    the node's findings and navlab's stdout (after it ends by itself with ``until_done``, else once stopped)."""
    pkg, cls = msg_type.split("/")
    listener = subprocess.Popen(
        [SYSTEM_PYTHON, "-c", _LISTENER, topic, pkg, cls, field],
        env=ros_env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    env = {**os.environ, "ROS_MASTER_URI": ros_env["ROS_MASTER_URI"], "ROS_IP": "127.0.0.1"}
    run = subprocess.Popen([NAVLAB, *argv], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out, err = listener.communicate(timeout=180)
        assert listener.returncode == 0, f"rospy listener failed: {err[-2000:]}"
        if not until_done:
            run.terminate()
        navlab_out, navlab_err = run.communicate(timeout=180)
    finally:
        listener.kill()
        run.kill()
    assert "ROS 1 bridge: master " + ros_env["ROS_MASTER_URI"] in navlab_err
    assert "listening on 127.0.0.1" in navlab_err
    return json.loads(out), navlab_out


def test_navigate_ros_is_on_the_graph_in_real_time_and_reaches_its_goal(ros_env: dict[str, str]) -> None:
    seen, out = _while_running(
        ros_env,
        ["navigate", "--ros", "--world", "room", "--goal", "1.0", "0.0", "0.0", "--timeout", "20", "--json"],
        "/odom",
        "nav_msgs/Odometry",
        "child_frame_id",
        until_done=True,
    )
    assert seen["value"] == "chassis"
    assert seen["pubs"]["/mybot/laser/scan"]  # the lidar plugin publishes it
    assert "/move_base" in seen["subs"]["/move_base/goal"]  # actionlib's server, for SimpleActionClient
    assert "/move_base/status" in seen["pubs"]
    figures = json.loads(out)
    assert figures["goals"][0]["outcome"] == "succeeded"
    assert figures["rtf"] <= 1.1  # real time by default with --ros: outside nodes cannot follow 100x


def test_map_ros_serves_the_growing_map_to_rospy(ros_env: dict[str, str], tmp_path: Path) -> None:
    seen, _ = _while_running(
        ros_env,
        [
            "map",
            "--ros",
            "--world",
            "room",
            "--duration",
            "8",
            "--rate",
            "2",
            "--out",
            str(tmp_path / "map"),
            "--json",
            "--quiet",
        ],
        "/map",
        "nav_msgs/OccupancyGrid",
        "info.resolution",
        until_done=True,
    )
    assert abs(seen["value"] - 0.05) < 1e-9
    assert "/slam_gmapping" in seen["pubs"]["/map"]
    assert seen["pubs"]["/mybot/laser/scan"]  # the lidar plugin publishes it
    assert (tmp_path / "map" / "map.yaml").is_file()


def test_view_ros_registers_the_live_launch_on_the_master(ros_env: dict[str, str]) -> None:
    seen, _ = _while_running(
        ros_env,
        ["view", "--ros", "--no-browser", "--port", "0", "--duration", "60"],
        "/amcl_pose",
        "geometry_msgs/PoseWithCovarianceStamped",
        "header.frame_id",
        until_done=False,
    )
    assert seen["value"] == "map"
    assert "/amcl" in seen["pubs"]["/amcl_pose"]
    assert "/move_base" in seen["subs"]["/move_base_simple/goal"]


def test_the_hook_paces_each_run_and_leaves_runs_without_ros_or_rate_alone() -> None:
    from argparse import Namespace

    from navlab.cli.runs import ros_hook
    from navlab.experiments.session import start_run

    started: list[Any] = []
    with ros_hook(Namespace(ros=False, rate=None), started.append) as on_start:
        assert on_start == started.append  # neither --ros nor --rate: the verb's own hook, nothing else
    with ros_hook(Namespace(ros=False, rate=2.5), started.append) as on_start:
        run = start_run("sim", world="room", on_start=on_start)
    assert started == [run] and run.executor.rate == 2.5  # paced before the viewer's hook reads the pace
