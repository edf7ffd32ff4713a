"""The top-level Python API: lazy names, a light ``import navlab``, and the docstring's notebook example."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from importlib.metadata import version

import pytest

import navlab
from navlab.core import Context


def test_import_navlab_is_light():
    heavy = "('mujoco', 'numpy', 'navlab.core', 'rosbags')"
    code = f"import sys, navlab; print(sorted(m for m in {heavy} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_top_level_names():
    from navlab import msgs as msgs_module
    from navlab.core import Executor, Node
    from navlab.core.launch import start

    assert navlab.launch is start and navlab.Executor is Executor and navlab.Node is Node
    assert navlab.msgs is msgs_module and navlab.msgs.Twist is msgs_module.Twist
    assert navlab.__version__ == version("navlab")
    assert {"launch", "Executor", "Node", "msgs", "__version__"} <= set(dir(navlab))
    with pytest.raises(AttributeError, match="no attribute 'lanch'"):
        navlab.lanch  # noqa: B018


def test_user_node_on_a_launch():
    session = navlab.launch("sim", x=0.5)
    heard = []

    class Watch(navlab.Node):
        def __init__(self, executor: navlab.Executor) -> None:
            super().__init__("watch", context=Context(executor))
            self.create_subscription(navlab.msgs.Odometry, "/ground_truth/odom", heard.append, 10)
            pub = self.create_publisher(navlab.msgs.Twist, "/cmd_vel", 1)
            self.create_timer(0.1, lambda: pub.publish(navlab.msgs.twist(0.3, 0.0)))

    Watch(session.executor)
    session.run(2.0)
    x, y, _ = navlab.msgs.pose2d(heard[-1].pose.pose)
    assert x > 0.5 + 0.3 and abs(y) < 0.05  # it drove forward from its start at x = 0.5


def test_docstring_example_maps_the_room(tmp_path, monkeypatch, capsys):
    doc = navlab.__doc__ or ""
    block = doc.split("::\n\n", 1)[1].split("\nTop-level names", 1)[0]
    code = textwrap.dedent(block)
    assert "session.run(60.0)" in code
    monkeypatch.chdir(tmp_path)
    exec(compile(code.replace("session.run(60.0)", "session.run(10.0)"), "navlab.__doc__", "exec"), {})
    assert "scans mapped" in capsys.readouterr().out
    from navlab.mapping import load_map

    grid = load_map(tmp_path / "room.yaml")
    assert (tmp_path / "room.pgm").is_file()
    assert (grid.data == 100).sum() > 100 and (grid.data == 0).sum() > 1000
