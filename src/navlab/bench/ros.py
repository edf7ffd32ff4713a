"""``navlab bench ros``: navlab on a real ROS 1 graph, measured with the real tools.

- ``hz``: the rates a real ``rostopic hz`` measures for the scan (40 Hz), odom and tf of a navigation run kept
  in real time, over ``HZ_WINDOW_S`` wall seconds;
- ``cmd_vel_latency``: from a real rospy node's ``/cmd_vel`` publish (its wall clock) to navlab's wheels
  turning (|joint velocity| > 0.05 rad/s, checked every simulated millisecond): wall and simulated seconds;
- ``hil``: the hardware-in-the-loop outcome table: the same goals driven by the single-process navigation
  run and by ``navigation sim:=false`` against a second navlab process playing the robot.

Needs Debian's ROS 1 tools (``make install``); runs in real time (about two minutes).
"""

from __future__ import annotations

import argparse
import math
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from navlab.core import Timer
from navlab.errors import NavlabError
from navlab.ros1 import LiveRun

HZ_WINDOW_S = 10.0
GOALS = [(1.5, 0.0, 0.0), (1.5, 1.5, 1.57), (-1.0, 1.0, 3.14)]
SYSTEM_PYTHON = "/usr/bin/python3"


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _tool(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        raise NavlabError(f"bench ros: {name} is missing (make install installs Debian's ROS 1 tools)")
    return path


class _Graph:
    """A real rosmaster on a free port and the environment for ROS tools to reach it."""

    def __init__(self, home: Path) -> None:
        port = _free_port()
        self.env = {
            "PATH": "/usr/bin:/bin",
            "ROS_MASTER_URI": f"http://127.0.0.1:{port}/",
            "ROS_IP": "127.0.0.1",
            "ROS_HOME": str(home),
            "HOME": str(home),
        }
        self.uri = self.env["ROS_MASTER_URI"]
        self.proc = subprocess.Popen(
            [_tool("rosmaster"), "--core", "-p", str(port)],
            env=self.env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        time.sleep(1.5)

    def close(self) -> None:
        self.proc.terminate()
        self.proc.wait(5)


def _hz(graph: _Graph, topics: list[str]) -> dict[str, float | None]:
    procs = {
        t: subprocess.Popen(
            ["timeout", "-s", "INT", str(HZ_WINDOW_S), _tool("rostopic"), "hz", t],
            env=graph.env,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        for t in topics
    }
    out: dict[str, float | None] = {}
    for topic, proc in procs.items():
        text, _ = proc.communicate(timeout=HZ_WINDOW_S + 20)
        rates = re.findall(r"average rate: ([0-9.]+)", text)
        out[topic] = round(float(rates[-1]), 2) if rates else None
    return out


def _latency(graph: _Graph, live: LiveRun, repeats: int = 5) -> dict[str, Any]:
    """cmd_vel (rospy publish, wall) -> wheels turning, for ``repeats`` go commands each after a stop."""
    sim = live.session.node("gazebo").sim  # type: ignore[attr-defined]
    joints = [sim.robot.diff_drive.left_joint, sim.robot.diff_drive.right_joint]
    moving: list[tuple[float, int]] = []  # (wall s, sim ns) of each first turning instant
    injected: list[int] = []
    watching = [False]

    def check() -> None:
        if watching[0] and max(abs(sim.joint_velocity(j)) for j in joints) > 0.05:
            watching[0] = False
            moving.append((time.time(), live.ex.now_ns))

    def listen(topic: str, msg: Any, t_ns: int) -> None:
        if topic == "/cmd_vel" and msg.linear.x > 0:
            injected.append(t_ns)
            watching[0] = True

    live.call(lambda: live.ex.add_listener(listen))
    timer = live.call(lambda: Timer(live.ex, 1_000_000, check, 0, live.ex.now_ns))
    script = f"""
import rospy, time
from geometry_msgs.msg import Twist
rospy.init_node('latency_probe')
pub = rospy.Publisher('/cmd_vel', Twist, queue_size=1)
while pub.get_num_connections() == 0:
    time.sleep(0.01)
time.sleep(0.5)
for _ in range({repeats}):
    pub.publish(Twist()); time.sleep(1.5)
    go = Twist(); go.linear.x = 0.3
    print(time.time(), flush=True); pub.publish(go); time.sleep(1.0)
pub.publish(Twist()); time.sleep(0.3)
"""
    done = subprocess.run([SYSTEM_PYTHON, "-c", script], env=graph.env, capture_output=True, text=True, timeout=60)
    sent = [float(v) for v in done.stdout.split()]
    timer.cancel()
    wall = [m[0] - s for m, s in zip(moving, sent, strict=False)]
    simulated = [(m[1] - i) / 1e9 for m, i in zip(moving, injected, strict=False)]
    return {
        "samples": len(wall),
        "wall_median_s": round(statistics.median(wall), 4) if wall else None,
        "wall_max_s": round(max(wall), 4) if wall else None,
        "sim_median_s": round(statistics.median(simulated), 4) if simulated else None,
    }


def _drive(live: LiveRun, goal: tuple[float, float, float], timeout_s: float = 60.0) -> dict[str, Any]:
    mb = live.session.node("move_base")
    handle = live.call(lambda: mb.send_goal(*goal))  # type: ignore[attr-defined]
    t0 = time.monotonic()
    while not handle.done() and time.monotonic() - t0 < timeout_s:
        time.sleep(0.1)
    if not handle.done():
        live.call(mb.cancel_goal)  # type: ignore[attr-defined]
    return {"outcome": handle.state, "sim_s": round((handle.end_s or live.ex.now_ns / 1e9) - handle.start_s, 2)}


def _truth(graph: _Graph) -> tuple[float, float]:
    out = subprocess.run(
        [_tool("rostopic"), "echo", "-n", "1", "/ground_truth/odom/pose/pose/position"],
        env=graph.env,
        capture_output=True,
        text=True,
        timeout=30,
    ).stdout
    x = re.search(r"x: (\S+)", out)
    y = re.search(r"y: (\S+)", out)
    return (float(x.group(1)), float(y.group(1))) if x and y else (math.nan, math.nan)


def run(args: argparse.Namespace) -> dict[str, Any]:
    from navlab.mapping import save_true_map

    with tempfile.TemporaryDirectory(prefix="navlab-bench-ros-") as folder:
        home = Path(folder)
        map_yaml = home / "room.yaml"
        save_true_map("room", (0.0, 0.0), map_yaml)
        graph = _Graph(home)
        try:
            live = LiveRun(master=graph.uri, launch="navigation", world="room", map=str(map_yaml), seed=args.seed)
            try:
                hz = _hz(graph, ["/mybot/laser/scan", "/odom", "/tf"])
                latency = _latency(graph, live)
            finally:
                live.close()
            single = LiveRun(master=graph.uri, launch="navigation", world="room", map=str(map_yaml), seed=args.seed)
            try:
                single_rows = [_drive(single, g) for g in GOALS]
            finally:
                single.close()
            robot = subprocess.Popen(
                [
                    str(Path(sys.executable).parent / "navlab"),
                    "launch",
                    "sim",
                    "ros:=true",
                    "world:=room",
                    "--duration",
                    "600",
                    "--quiet",
                ],
                env={**graph.env, "PATH": f"{Path(sys.executable).parent}:/usr/bin:/bin"},
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            try:
                _truth(graph)  # waits for the robot
                hil = LiveRun(master=graph.uri, launch="navigation", map=str(map_yaml), sim="false", follow_clock=True)
                try:
                    hil_rows = []
                    for g in GOALS:
                        row = _drive(hil, g)
                        x, y = _truth(graph)
                        row["true_error_m"] = round(math.hypot(x - g[0], y - g[1]), 3)
                        hil_rows.append(row)
                finally:
                    hil.close()
            finally:
                robot.terminate()
                robot.wait(10)
        finally:
            graph.close()
    table = [{"goal": list(g), "single": s, "hil": h} for g, s, h in zip(GOALS, single_rows, hil_rows, strict=True)]
    return {"rostopic_hz": hz, "hz_window_s": HZ_WINDOW_S, "cmd_vel_to_wheels": latency, "hil": table}
