"""The shipped robots of other sizes (TurtleBot3-burger-sized, Jackal-sized) load, drive and scan; every
shipped robot runs in a generated BARN-style clutter world from its start pose."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_helpers import make_room

from navlab import msgs, resources
from navlab.core import Context, Executor, Node
from navlab.description import load_robot
from navlab.sim import launch_sim
from navlab.world import load_world
from navlab.world.clutter import generate_clutter

# name: (base frame, scan topic, beams, forward speed m/s, lidar x ahead of the base frame in m)
ROBOTS = {
    "tb3_burger": ("base_footprint", "scan", 360, 0.2, -0.032),
    "jackal": ("base_link", "front/scan", 720, 0.5, 0.12),
}


class _Driver:
    """Publishes the current (v, w) on cmd_vel at 20 Hz and keeps the scans of ``scan_topic``."""

    def __init__(self, ex: Executor, scan_topic: str) -> None:
        self.cmd = (0.0, 0.0)
        self.scans: list[object] = []
        node = Node("driver", context=Context(ex))
        node.create_subscription(msgs.LaserScan, scan_topic, self.scans.append)
        pub = node.create_publisher(msgs.Twist, "cmd_vel")
        node.create_timer(0.05, lambda: pub.publish(msgs.twist(*self.cmd)))


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_shipped_robot_drives_straight_and_turns(name: str) -> None:
    base, topic, beams, speed, laser_x = ROBOTS[name]
    robot = load_robot(resources.robot(name))
    assert not robot.warnings
    assert robot.diff_drive is not None and robot.diff_drive.robot_base_frame == base
    ex = Executor(seed=0)
    sim = launch_sim(ex, world=make_room(5.0, 3.0), robot=robot, pose=(0.0, 0.0, 0.0)).sim
    drive = _Driver(ex, topic)
    ex.run(0.5)  # settle on the floor
    assert sim.link_pose(base).position[2] == pytest.approx(0.0, abs=0.01)
    x0, y0, _ = sim.base_pose2d(base)

    drive.cmd = (speed, 0.0)  # 1 m straight ahead
    ex.run(1.0 / speed)
    drive.cmd = (0.0, 0.0)
    ex.run(1.0)
    x, y, yaw = sim.base_pose2d(base)
    assert math.hypot(x - x0, y - y0) == pytest.approx(1.0, abs=0.06)
    assert abs(y - y0) < 0.03 and abs(yaw) < 0.03

    # beam straight ahead: from the lidar to the east wall at x = 2.5 (noise 1 cm; TB3's LDS reaches 3.5 m)
    scan = drive.scans[-1]
    ranges = np.asarray(scan.ranges)  # type: ignore[attr-defined]
    assert len(ranges) == beams
    ahead = int(np.argmin(np.abs(scan.angle_min + scan.angle_increment * np.arange(beams))))  # type: ignore[attr-defined]
    assert ranges[ahead] == pytest.approx(2.5 - (x + laser_x), abs=0.05)

    drive.cmd = (0.0, 1.0)  # a quarter turn in place at 1 rad/s
    ex.run(math.pi / 2)
    drive.cmd = (0.0, 0.0)
    ex.run(1.0)
    x2, y2, yaw2 = sim.base_pose2d(base)
    assert yaw2 == pytest.approx(math.pi / 2, abs=0.12)
    assert math.hypot(x2 - x, y2 - y) < 0.05  # turned about the base frame
    roll_pitch = sim.link_pose(base)
    assert roll_pitch.position[2] == pytest.approx(0.0, abs=0.01)  # still upright on the floor


def test_jackal_gpu_argument_selects_the_gpu_laser() -> None:
    cpu = load_robot(resources.robot("jackal"))
    gpu = load_robot(resources.robot("jackal"), args={"gpu": "true"})
    assert 'filename="libgazebo_ros_laser.so"' in cpu.urdf_xml and 'type="gpu_ray"' not in cpu.urdf_xml
    assert 'filename="libgazebo_ros_gpu_laser.so"' in gpu.urdf_xml and 'type="gpu_ray"' in gpu.urdf_xml
    assert gpu.lidars[0].samples == cpu.lidars[0].samples == 720
    assert gpu.lidars[0].max_angle - gpu.lidars[0].min_angle == pytest.approx(1.5 * math.pi, abs=1e-4)


@pytest.mark.parametrize("name", ["mybot", "tb3_burger", "jackal"])
def test_robot_runs_in_a_generated_clutter_world(name: str, tmp_path: object) -> None:
    clutter = generate_clutter(3, fill=0.3, smooth=2)
    path = clutter.write_world(tmp_path / "clutter.world")  # type: ignore[operator]
    world = load_world(path)
    ex = Executor(seed=0)
    gazebo = launch_sim(ex, world=world, robot=name, pose=clutter.start)
    base = "chassis" if name == "mybot" else ROBOTS[name][0]
    drive = _Driver(ex, "/mybot/laser/scan" if name == "mybot" else ROBOTS[name][1])
    drive.cmd = (0.2, 0.0)
    ex.run(0.5)
    x, y, _ = gazebo.sim.base_pose2d(base)
    assert x == pytest.approx(clutter.start[0] + 0.2 * 0.45, abs=0.05) and abs(y - clutter.start[1]) < 0.02
    assert drive.scans  # the lidar sees the clutter world: nearest return within the walls' reach
    ranges = np.asarray(drive.scans[-1].ranges)  # type: ignore[attr-defined]
    assert np.nanmin(np.where(np.isfinite(ranges), ranges, np.nan)) < 3.0
