"""The paper's mapping step in simulation: SLAM while driving in room.world, scored against the world.

Each run maps the shipped room with the shipped robot (MuJoCo physics, 720-ray lidar at 40 Hz,
slam_gmapping) and compares the saved map with the world's true occupancy.
"""

import json

import numpy as np
import pytest

from navlab.cli import main
from navlab.experiments.mapping_run import run_mapping
from navlab.mapping import load_map

# A loop through the room's open middle, clear of the partitions and the pillar (world frame = odom).
ROUTE = """\
waypoints:
  - [1.2, -1.0]
  - [-1.5, -0.9]
  - [-1.6, 1.2]
  - [0.8, 1.0]
  - [0.0, 0.0]
"""


@pytest.fixture(scope="module")
def route_file(tmp_path_factory):
    f = tmp_path_factory.mktemp("route") / "loop.yaml"
    f.write_text(ROUTE)
    return f


def test_route_mapping_puts_walls_where_the_world_has_them(route_file, tmp_path, capsys):
    r = run_mapping(world="room", driver="route", route=route_file, out=tmp_path / "m", duration=150, quiet=True)
    s = r.scores
    assert r.finished, "the route did not finish within 150 s"
    assert s["precision"] >= 0.9 and s["recall"] >= 0.8, s
    assert s["mean_wall_error_m"] <= 0.05, s  # within one 5 cm cell
    saved = load_map(tmp_path / "m" / "map.yaml")
    assert saved.resolution == pytest.approx(0.05)
    assert (tmp_path / "m" / "map.png").stat().st_size > 10_000
    # the saved (trinary) map scores the same way from the command line, trajectory included
    assert main(["eval", "map", str(tmp_path / "m" / "map.yaml"), "--world", "room", "--json"]) == 0
    e = json.loads(capsys.readouterr().out)
    assert e["precision"] >= 0.9 and e["recall"] >= 0.8 and e["mean_wall_error_m"] <= 0.05, e
    assert e["position_error_mean_m"] == s["position_error_mean_m"]


def test_slam_beats_raw_odometry_when_encoders_are_off(route_file, tmp_path):
    r = run_mapping(
        world="room",
        driver="route",
        route=route_file,
        out=tmp_path / "m",
        duration=150,
        quiet=True,
        sim_params={"odometry_noise": 0.03},
        seed=0,
    )
    s = r.scores
    assert s["odometry_position_error_mean_m"] > 0.15, s  # the noisy encoders really drift
    assert s["position_error_mean_m"] < 0.5 * s["odometry_position_error_mean_m"], s
    assert s["precision"] >= 0.8, s


def test_exploration_covers_the_room(tmp_path):
    r = run_mapping(world="room", driver="explore", out=tmp_path / "m", duration=300, quiet=True)
    s = r.scores
    assert r.finished, "exploration did not finish within 300 s"
    assert s["coverage"] >= 0.95, s
    assert s["precision"] >= 0.9, s
    assert np.isfinite(s["position_error_max_m"]) and s["position_error_max_m"] < 0.2, s
