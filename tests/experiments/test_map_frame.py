"""Issue 13 item 8: the SLAM map frame follows the odometry source, so a robot spawned away from the
origin is scored correctly with world-frame odometry (Gazebo's default) and with encoder odometry."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from navlab.cli import main
from navlab.experiments.mapping_run import run_mapping

XACRO = Path(__file__).parents[1] / "fixtures" / "tutorial_bot_description" / "urdf" / "tutorial_bot.urdf.xacro"
SPAWN = (1.5, -1.0, 0.6)


@pytest.mark.parametrize(
    ("robot", "map_frame"),
    [
        (str(XACRO), (0.0, 0.0, 0.0)),  # <odometrySource>world</odometrySource>: map = odom = world
        ("mybot", SPAWN),  # encoder odometry: map = odom = the spawn pose
    ],
)
def test_spawn_away_from_origin_scored_in_the_right_map_frame(robot, map_frame, tmp_path, capsys):
    route = tmp_path / "spin.yaml"
    route.write_text("segments:\n  - {linear: 0.0, angular: 0.8, duration: 8.5}\n")
    r = run_mapping(
        world="room", robot=robot, pose=SPAWN, driver="route", route=route, out=tmp_path / "m", duration=12, quiet=True
    )
    s = r.scores
    assert s["map_frame_in_world"] == pytest.approx(list(map_frame))
    assert s["precision"] >= 0.85, s  # walls where the world has them (offset by the spawn pose before the fix)
    assert s["mean_wall_error_m"] <= 0.06, s
    assert s["position_error_mean_m"] <= 0.1, s  # truth overlay in the same frame as the SLAM estimate
    # navlab eval map decides the frame the same way from the robot's odometry source
    capsys.readouterr()
    argv = [
        "eval",
        "map",
        str(r.map_yaml),
        "--world",
        "room",
        "--robot",
        robot,
        "--x",
        str(SPAWN[0]),
        "--y",
        str(SPAWN[1]),
        "--yaw",
        str(SPAWN[2]),
        "--json",
    ]
    assert main(argv) == 0
    e = json.loads(capsys.readouterr().out)
    assert e["map_frame_in_world"] == pytest.approx(list(map_frame))
    assert e["precision"] == pytest.approx(s["precision"]) and e["recall"] == pytest.approx(s["recall"])
    assert e["position_error_mean_m"] <= 0.1, e  # trajectory.txt beside the map, in the same frame
