"""Issue 13: the TurtleBot3-style fixture robot drives and maps a TurtleBot3-style world (hexagonal
walls from a Y_UP inch COLLADA mesh around a grid of pillars), as it would in Gazebo classic."""

from __future__ import annotations

from pathlib import Path

from navlab.experiments.mapping_run import run_mapping
from navlab.world import load_world

FIX = Path(__file__).parents[1] / "fixtures"
WORLD = FIX / "worlds" / "turtlebot3_style.world"
BURGER = FIX / "turtlebot3_description" / "urdf" / "turtlebot3_burger.urdf.xacro"


def test_hexagon_walls_stand_upright():
    world = load_world(WORLD)
    from navlab.world import extents

    x0, y0, x1, y1 = extents(world, z_min=0.05, z_max=0.3)
    assert x1 - x0 > 4.0 and y1 - y0 > 3.5  # a 4.2 m wide arena at lidar height, not walls lying flat
    assert any("Y_UP" in w for w in world.warnings)


def test_turtlebot3_fixture_drives_and_maps_its_world(tmp_path):
    route = tmp_path / "route.yaml"
    route.write_text(
        "segments:\n  - {linear: 0.0, angular: 0.8, duration: 8.5}\n  - {linear: 0.15, angular: 0.0, duration: 2.0}\n"
    )
    r = run_mapping(
        world=str(WORLD),
        robot=str(BURGER),
        pose=(0.0, -0.55, 0.0),
        driver="route",
        route=route,
        out=tmp_path / "m",
        duration=15,
        quiet=True,
    )
    s = r.scores
    assert r.finished and s["scans_processed"] >= 10, s
    assert s["map_frame_in_world"] == [0.0, 0.0, 0.0]  # TurtleBot3: <odometrySource>world
    assert s["precision"] >= 0.85 and s["recall"] >= 0.4, s
    assert s["position_error_mean_m"] <= 0.1, s
