"""Issue 23: a ROS 1 workspace of the shape public robot packages have (tests/fixtures/ros_ws: my_description,
my_gazebo, my_slam, my_navigation) runs unchanged: `navlab roslaunch my_gazebo my_world.launch` simulates,
my_slam maps, my_navigation reaches a goal."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from navlab import msgs
from navlab.cli import main
from navlab.core import Context, Node
from navlab.core.launch import Session, start

WS = Path(__file__).parents[1] / "fixtures" / "ros_ws"
WORLD = WS / "my_gazebo" / "launch" / "my_world.launch"


@pytest.fixture(autouse=True)
def _workspace(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(WS))


def test_roslaunch_my_gazebo_my_world_simulates(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.delenv("ROS_PACKAGE_PATH")  # found through --package-path, as a user passes it
    monkeypatch.chdir(tmp_path)
    assert (
        main(
            [
                "roslaunch",
                "my_gazebo",
                "my_world.launch",
                "--package-path",
                str(WS),
                "--duration",
                "1",
                "--json",
                "--quiet",
                "x_pos:=0.5",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert "/gazebo" in out["nodes"] and out["topics"]["/scan"] >= 4 and out["topics"]["/tf"] >= 25


def test_world_launch_spawns_the_xacro_robot_where_spawn_model_says() -> None:
    session = start(WORLD, launch_args={"x_pos": "0.5", "y_pos": "0.25", "laser_range": "2.0"})
    session.run(0.5)
    gazebo = session.node("gazebo")
    x, y, _ = gazebo.sim.base_pose2d()
    assert (x, y) == pytest.approx((0.5, 0.25), abs=0.02)
    assert gazebo.sim.robot.name == "my_robot" and gazebo.sim.robot.lidars[0].range_max == 2.0  # xacro arg passed
    assert session.params["/use_sim_time"] is True and session.params["/robot_description"].startswith("<")
    assert any("robot_state_publisher" in n for n in session.notes)


def _drive(session: Session, v: float, w: float) -> None:
    node = Node("teleop", context=Context(session.executor))
    pub = node.create_publisher(msgs.Twist, "/cmd_vel", 1)
    node.create_timer(0.1, lambda: pub.publish(msgs.twist(v, w)))


def test_my_slam_maps_the_room() -> None:
    session = start([WORLD, WS / "my_slam" / "launch" / "my_slam.launch"])
    slam = session.node("my_slam_gmapping")
    assert slam.params.particles == 10 and slam.base_frame == "base_footprint"  # from the package's files
    maps: list[object] = []
    probe = Node("probe", context=Context(session.executor))
    probe.create_subscription(msgs.OccupancyGrid, "/map", maps.append, 1)
    _drive(session, 0.0, 0.6)  # turn on the spot: the lidar sweeps the room
    session.run(8.0)
    assert maps, "slam_gmapping published no map"
    grid = np.asarray(maps[-1].data).reshape(maps[-1].info.height, maps[-1].info.width)  # type: ignore[attr-defined]
    res = maps[-1].info.resolution  # type: ignore[attr-defined]
    assert res == pytest.approx(0.05)
    occupied = np.count_nonzero(grid >= 65)
    assert occupied * res > 6.0  # metres of wall seen (the room's perimeter is 14 m)


def test_my_navigation_reaches_a_goal_with_the_models_costmap_files(tmp_path: Path) -> None:
    from navlab.mapping import save_map
    from navlab.world import load_world, true_map

    save_map(true_map(load_world(WS / "my_gazebo" / "worlds" / "my_room.world"), (0.0, 0.0)), tmp_path / "map.yaml")
    session = start(
        [WORLD, WS / "my_navigation" / "launch" / "my_navigation.launch"],
        launch_args={
            "map_file": str(tmp_path / "map.yaml"),
            "model": "large",
            "initial_pose_x": "-1.0",
            "initial_pose_y": "-0.5",
        },
    )
    move_base = session.node("move_base")
    for costmap in (move_base.global_costmap, move_base.local_costmap):  # costmap_common_params_large into both
        assert costmap.layered.footprint.polygon.max() == pytest.approx(0.2 + 0.01)  # + footprint_padding
    assert any("rviz" in n for n in session.notes)
    goal = (1.2, -0.6)
    node = Node("rviz_goal", context=Context(session.executor))
    pub = node.create_publisher(msgs.PoseStamped, "/move_base_simple/goal", 1)
    session.run(0.5)
    pub.publish(
        msgs.PoseStamped(
            header=msgs.Header(stamp=msgs.time_from_ns(session.executor.now_ns), frame_id="map"),
            pose=msgs.Pose(
                position=msgs.Point(x=goal[0], y=goal[1], z=0.0),
                orientation=msgs.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
            ),
        )
    )
    gazebo = session.node("gazebo")

    def arrived() -> bool:
        x, y, _ = gazebo.sim.base_pose2d()
        return math.hypot(x - goal[0], y - goal[1]) < 0.2

    assert session.executor.run_until(arrived, timeout=30.0)


def test_several_launch_files_in_one_call_and_map_saver_writes_the_map(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`navlab launch A.launch B.launch name:=value` (roslaunch a.launch b.launch): the world, gmapping and
    map_saver in one process; map_saver -f writes the first map it receives, as map_server's map_saver does."""
    saver = tmp_path / "save.launch"
    saver.write_text("""<launch>
  <arg name="out"/>
  <include file="$(find my_slam)/launch/my_slam.launch"/>
  <node pkg="map_server" type="map_saver" name="map_saver" args="-f $(arg out)"/>
</launch>""")
    out = tmp_path / "maps" / "room"
    out.parent.mkdir()
    assert main(["launch", str(WORLD), str(saver), f"out:={out}", "--duration", "3", "--json", "--quiet"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert {"/gazebo", "/my_slam_gmapping", "/map_saver"} <= set(summary["nodes"]) and summary["topics"]["/map"] >= 1
    from navlab.mapping import load_map

    grid = load_map(out.with_suffix(".yaml"))
    assert grid.resolution == pytest.approx(0.05) and out.with_suffix(".pgm").is_file()
