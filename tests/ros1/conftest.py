"""The real ROS 1 Noetic tools (Debian's packages, run by the system Python) as the peers of navlab's bridge.

They are required, not optional: `make install` installs them with apt; a missing one fails the test with
the package to install, instead of skipping it silently.
"""

from __future__ import annotations

import os
import socket
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from ros1_helpers import TOOLS, free_port, require


@pytest.fixture(scope="session")
def ros_env(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, str]]:
    """A real ``rosmaster`` on a free loopback port; the environment for ROS tools to reach it."""
    for tool in TOOLS:
        require(tool)
    port = free_port()
    env = {
        **os.environ,
        "ROS_MASTER_URI": f"http://127.0.0.1:{port}/",
        "ROS_IP": "127.0.0.1",
        "ROS_HOME": str(tmp_path_factory.mktemp("ros_home")),
        "PYTHONPATH": "",
    }
    env.pop("VIRTUAL_ENV", None)
    env["PATH"] = "/usr/bin:/bin"
    master = subprocess.Popen(
        [require("rosmaster"), "--core", "-p", str(port)], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                break
        time.sleep(0.1)
    try:
        yield env
    finally:
        master.terminate()
        master.wait(5)


@pytest.fixture(scope="session")
def room_map(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from navlab.mapping import save_map
    from navlab.world import load_world, true_map

    path = tmp_path_factory.mktemp("map") / "room.yaml"
    save_map(true_map(load_world("room"), (0.0, 0.0)), path)
    return path
