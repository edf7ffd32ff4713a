"""``--view`` on other verbs: the viewer is served while the run lasts, and the verb's output is unchanged."""

from __future__ import annotations

import argparse
import json

import pytest
from viz_helpers import next_state
from websockets.sync.client import connect

from navlab.cli import main
from navlab.cli.runs import viewing
from navlab.experiments.session import start_run


def test_sim_and_launch_take_view(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "--duration", "0.2", "--json", "--view", "--view-port", "0", "--no-browser"]) == 0
    out = capsys.readouterr()
    assert "viewer: http://127.0.0.1:" in out.err and json.loads(out.out)["sim_s"] == pytest.approx(0.2)
    assert main(["launch", "sim", "--duration", "0.2", "--json", "--view", "--view-port", "0", "--no-browser"]) == 0
    out = capsys.readouterr()
    assert (
        "viewer: http://127.0.0.1:" in out.err and "/initialpose" in json.loads(out.out)["topics"]
    )  # the viewer publishes it


def test_viewing_serves_while_the_block_runs_and_warns_off_loopback(capsys: pytest.CaptureFixture[str]) -> None:
    run = start_run("sim", world="room")
    args = argparse.Namespace(view=True, view_host="127.0.0.1", view_port=0, no_browser=True, foxglove=None)
    with viewing(args, run.executor) as viewer:
        run.run(0.2)
        with connect(viewer.url.replace("http", "ws")) as ws:
            state = next_state(ws)
        assert state["k"] == "state" and 0.0 < state["t"] <= 0.2 + 1e-9 and state["base"] == "chassis"
    with pytest.raises(OSError), connect(viewer.url.replace("http", "ws"), open_timeout=1):
        pass  # closed with the block
    args.view = False
    with viewing(args, run.executor) as none:
        assert none is None
    args = argparse.Namespace(view=True, view_host="0.0.0.0", view_port=0, no_browser=True, foxglove=None)
    with viewing(args, run.executor):
        pass
    assert "warning: the viewer listens on 0.0.0.0" in capsys.readouterr().err


def test_navlab_view_starts_a_launch_with_ros_style_arguments(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["view", "--launch", "sim", "world:=room", "x:=0.5", "--rate", "0", "--duration", "0.2", "--port", "0"]
    assert main([*argv, "--no-browser"]) == 0
    err = capsys.readouterr().err
    assert "viewer: http://127.0.0.1:" in err and "DeprecationWarning" not in err
    assert main(["view", "--launch", "sim", "wrold:=room", "--port", "0", "--no-browser"]) == 2
    assert "did you mean 'world'" in capsys.readouterr().err


def test_navigate_takes_view(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["navigate", "--goal", "1.0", "0.0", "0.0", "--timeout", "0.5", "--json", "--view", "--view-port", "0"]
    assert main([*argv, "--no-browser"]) == 1  # 0.5 s is too short to reach the goal: exit 1, as navigate says
    out = capsys.readouterr()
    assert "viewer: http://127.0.0.1:" in out.err and json.loads(out.out)["goals"][0]["goal"] == [1.0, 0.0, 0.0]
    assert "navlab: 1 of 1 goals not reached (timeout)" in out.err


def test_view_hook_moves_the_page_to_each_new_run_on_the_same_port() -> None:
    import socket

    from navlab.cli.runs import view_hook

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    args = argparse.Namespace(view=True, view_host="127.0.0.1", view_port=port, no_browser=True, foxglove=None)
    with view_hook(args) as on_start:
        first = start_run("sim", world="room", on_start=on_start)
        first.run(0.1)
        second = start_run("sim", world="room", on_start=on_start)
        assert "/navlab_viewer" not in first.executor.nodes and "/navlab_viewer" in second.executor.nodes
        second.run(0.4)
        with connect(f"ws://127.0.0.1:{port}/ws") as ws:
            state = next_state(ws)
        assert 0.2 < state["t"] <= 0.4 + 1e-9  # the second run's clock (the first stopped at 0.1 s)
    assert "/navlab_viewer" not in second.executor.nodes


def test_view_speed_is_a_deprecated_alias_of_rate() -> None:
    """``navlab view --speed`` (the pacing option's old name) still sets the pace, with a warning, this release."""
    import contextlib
    import io

    from navlab.cli import build_parser

    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        args = build_parser().parse_args(["view", "--speed", "0"])
    assert args.rate == 0.0
    assert "--speed is deprecated, use --rate" in err.getvalue()
    assert build_parser().parse_args(["view"]).rate == 1.0
