"""Replay in the page: ``navlab view --bag DIR`` plays a recording; seeking shows the robot where it was then."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from viz_helpers import canvas_xy, open_page, pixel

from navlab import msgs
from navlab.core import Node
from navlab.experiments.session import start_run
from navlab.io.rosbag import read_bag
from navlab.viz import Hub, ViewerServer
from navlab.viz.replay import BagPlayer, load_recording, play_bag


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """3 s of the robot driving an arc (0.4 m/s, 0.3 rad/s), recorded as `--record` does."""
    run = start_run("sim", world="room")
    node = run.add(Node, name="driver")
    pub = node.create_publisher(msgs.Twist, "cmd_vel", 1)
    node.create_timer(0.1, lambda: pub.publish(msgs.twist(0.4, 0.3)))
    path = tmp_path_factory.mktemp("replay") / "drive"
    run.run(3.0, record=path)
    return path


@pytest.fixture
def served(bag: Path) -> Iterator[tuple[BagPlayer, ViewerServer]]:
    hub = Hub()
    player = play_bag(bag, hub)
    with ViewerServer(hub, port=0) as server:
        yield player, server
    player.close()


def _odom_at(bag: Path, t_s: float) -> tuple[float, float, float]:
    """The recorded odometry pose at ``t_s`` after the recording's start."""
    rec = load_recording(bag)
    best = None
    for _topic, t_ns, msg in read_bag(bag, topics=["/odom"]):
        if t_ns - rec.t0 <= t_s * 1e9:
            best = msgs.pose2d(msg.pose.pose)
    assert best is not None
    return best


def test_seek_shows_the_robot_where_it_was(
    served: tuple[BagPlayer, ViewerServer], chromium: Any, bag: Path, artifacts: Path
) -> None:
    _player, server = served
    page = open_page(chromium, server.url)
    page.wait_for_selector("#timeline:not([hidden])")
    page.click("#play")  # it starts playing: pause it
    page.wait_for_function("() => navlab.store.state.paused")
    for t in (2.0, 0.5):
        page.locator("#seek").evaluate("(e, v) => { e.value = v; e.dispatchEvent(new Event('input')); }", t)
        page.wait_for_function(f"() => Math.abs(navlab.store.state.t - {t}) < 0.02")
        state = page.evaluate("navlab.store.state")
        x, y, yaw = state["tf"][state["base"]]
        ox, oy, oyaw = _odom_at(bag, t)
        assert math.dist((x, y), (ox, oy)) < 0.03 and abs(math.remainder(yaw - oyaw, math.tau)) < 0.05
        page.wait_for_timeout(150)  # the next frame is drawn
        sx, sy = canvas_xy(page, x, y)  # the robot's yellow outline is drawn around that pose
        ring = [pixel(page, sx + 12 * math.cos(a), sy + 12 * math.sin(a)) for a in [k * math.pi / 8 for k in range(16)]]
        assert any(r > 200 and g > 200 and b < 80 for r, g, b, _a in ring), (t, ring)
        page.screenshot(path=str(artifacts / f"replay_t{t:.1f}.png"))
    assert _odom_at(bag, 2.0)[0] > _odom_at(bag, 0.5)[0] + 0.3  # it did drive between the two
    assert not page.js_errors, page.js_errors  # type: ignore[attr-defined]
    page.close()


def test_replay_plays_to_the_end_and_refuses_live_inputs(bag: Path) -> None:
    hub = Hub()
    player = BagPlayer(load_recording(bag), hub, speed=10.0)
    assert player.submit({"op": "goal", "x": 1.0, "y": 0.0, "yaw": 0.0}) == "goal: a replay cannot change the recording"
    assert player.submit({"op": "seek", "t": "soon"}) is not None
    player.start()
    try:
        deadline = 50
        while not hub.state.get("paused") and deadline:
            import time

            time.sleep(0.1)
            deadline -= 1
        assert hub.state["t"] == pytest.approx(hub.state["t1"], abs=1e-6) and hub.state["t1"] > 2.9
        assert len(hub.traces["/odom"].xy) > 10 and "/mybot/laser/scan" in hub.slots
    finally:
        player.close()


def test_navlab_view_bag_serves_the_replay(bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from navlab.cli import main

    assert main(["view", "--bag", str(bag), "--port", "0", "--no-browser", "--duration", "0.3"]) == 0
    assert "viewer: http://127.0.0.1:" in capsys.readouterr().err
    assert main(["view", "--bag", str(bag.parent / "nothing"), "--port", "0", "--no-browser"]) == 2
    assert "not a rosbag2 recording" in capsys.readouterr().err


def test_recording_is_mcap_with_ros2_schemas_as_foxglove_opens_it(bag: Path) -> None:
    (mcap,) = bag.glob("*.mcap")
    data = mcap.read_bytes()
    assert data.startswith(b"\x89MCAP0\r\n") and data.endswith(b"\x89MCAP0\r\n")
    assert b"ros2msg" in data and b"cdr" in data and b"sensor_msgs/msg/LaserScan" in data
