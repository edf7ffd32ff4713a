"""Looking into a launch running in another process: topic list/echo/hz, node list, graph, clean stop."""

import contextlib
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from navlab.cli import main
from navlab.core import CoreError
from navlab.core.introspect import find_running, socket_dir


@pytest.fixture
def running_launch():
    proc = subprocess.Popen(
        [sys.executable, "-m", "navlab.cli", "launch", "talker_listener", "rate:=20"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    sock = socket_dir() / f"{proc.pid}.sock"
    deadline = time.monotonic() + 120  # a cold Numba cache on a loaded machine: start-up takes a while
    while not sock.exists() and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.1)
    assert sock.exists(), proc.stderr.read() if proc.poll() is not None else "no socket after 30 s"
    yield proc
    if proc.poll() is None:
        proc.kill()
        proc.wait(10)


def test_tools_see_a_launch_running_in_another_process(running_launch, capsys):
    pid = str(running_launch.pid)
    assert main(["topic", "list", "-v", "--pid", pid]) == 0
    assert "/chatter [std_msgs/msg/String]" in capsys.readouterr().out
    assert main(["topic", "echo", "/chatter", "--count", "2", "--pid", pid]) == 0
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("data:")]
    assert len(lines) == 2 and lines[0].startswith('data: "Hello World: ')
    assert main(["topic", "hz", "/chatter", "--duration", "1", "--json", "--pid", pid]) == 0
    assert json.loads(capsys.readouterr().out)["average_rate_hz"] == pytest.approx(20.0)
    assert main(["node", "list", "--pid", pid]) == 0
    assert capsys.readouterr().out.split() == ["/listener", "/talker"]
    # a topic nobody publishes: echo waits for it, as rostopic does, here bounded by the launch's clock
    assert main(["topic", "echo", "/nope", "--pid", pid, "--duration", "1.5"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err == [
        "WARNING: topic [/nope] does not appear to be published yet",
        "navlab: no message on /nope: 1.5 simulated s passed",
    ]


def test_echo_runs_until_the_launch_ends(running_launch, capsys):
    import threading

    threading.Timer(1.5, running_launch.send_signal, (signal.SIGTERM,)).start()
    t0 = time.monotonic()
    assert main(["topic", "echo", "/chatter", "--pid", str(running_launch.pid)]) == 0
    assert time.monotonic() - t0 < 15
    assert capsys.readouterr().out.count("\n---\n") >= 10  # 20 Hz for about a second, then the launch ended


def test_sigterm_stops_the_launch_cleanly(running_launch):
    sock = socket_dir() / f"{running_launch.pid}.sock"
    running_launch.send_signal(signal.SIGTERM)
    out, _ = running_launch.communicate(timeout=20)
    assert running_launch.returncode == 0
    assert "/chatter:" in out and not sock.exists()


def test_no_running_launch_is_a_clear_error():
    with pytest.raises(CoreError, match="no running navlab launch with pid"):
        find_running(os.getpid())


def test_map_save_takes_the_map_of_a_running_mapping_launch(tmp_path):
    from navlab.mapping import load_map

    proc = subprocess.Popen(
        [sys.executable, "-m", "navlab.cli", "launch", "mapping", "--rate", "4"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        sock = socket_dir() / f"{proc.pid}.sock"
        deadline = time.monotonic() + 120  # a cold Numba cache on a loaded machine: start-up takes a while
        while not sock.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        assert main(["map", "save", "--out", str(tmp_path), "--pid", str(proc.pid)]) == 0
    finally:
        proc.terminate()
        proc.wait(20)
    grid = load_map(tmp_path / "map.yaml")
    assert (grid.data == 100).sum() > 200  # walls seen by the lidar


def test_remote_cmd_vel_drives_the_robot_of_a_running_launch():
    """What `navlab teleop` does next to a running launch: publish cmd_vel into it from here."""
    from navlab import msgs
    from navlab.core.introspect import RemotePublisher, subscribe

    proc = subprocess.Popen(
        [sys.executable, "-m", "navlab.cli", "launch", "sim", "--rate", "2"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )

    def odom_now():
        with contextlib.closing(subscribe(sock, "/ground_truth/odom")) as stream:
            return next(stream)[1]

    def stamp(odom) -> float:  # simulated seconds
        return odom.header.stamp.sec + 1e-9 * odom.header.stamp.nanosec

    try:
        sock = socket_dir() / f"{proc.pid}.sock"
        deadline = time.monotonic() + 120  # a cold Numba cache on a loaded machine: start-up takes a while
        while not sock.exists() and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.1)
        assert sock.exists(), "the sim launch made no introspection socket in 120 s"
        pub = RemotePublisher(sock)
        odom = odom_now()
        start = stamp(odom)
        deadline = time.monotonic() + 120  # the launch's simulated time, not wall time, decides (machine load)
        sent = 0
        while stamp(odom) - start < 6.0:  # 6 simulated s of 0.5 m/s commands, about 3 m
            assert time.monotonic() < deadline, f"only {stamp(odom) - start:.2f} simulated s in 120 wall s"
            pub.publish("/cmd_vel", msgs.twist(0.5, 0.0))
            sent += 1
            time.sleep(0.1)
            if sent % 5 == 0:
                odom = odom_now()
        pub.close()
        odom = odom_now()
    finally:
        proc.terminate()
        proc.wait(20)
    assert odom.pose.pose.position.x > 1.5  # drove forward about 3 m
