"""The shipped robot and worlds through the shipped launch file: what the lidar sees is the world."""

from __future__ import annotations

import numpy as np
from scipy.ndimage import binary_dilation

from navlab import msgs
from navlab.core import Context, Node
from navlab.core.launch import start
from navlab.world import occupancy


def test_sim_launch_scans_land_on_the_worlds_walls() -> None:
    session = start("sim", world="room_obstacles", x="0.5", y="-0.5", yaw="0.3")
    ex = session.executor
    sim = session.node("gazebo").sim
    assert sim.base_pose2d()[:2] == (0.5, -0.5)
    points = []
    site = sim._lidar_site[0]

    def on_scan(scan: object) -> None:  # beam endpoints in the world, from the true sensor pose
        ranges = np.asarray(scan.ranges, dtype=float)  # type: ignore[attr-defined]
        angles = scan.angle_min + scan.angle_increment * np.arange(len(ranges))  # type: ignore[attr-defined]
        hit = np.isfinite(ranges)
        local = np.stack([ranges * np.cos(angles), ranges * np.sin(angles), np.zeros_like(ranges)], axis=1)[hit]
        world = sim.data.site_xpos[site] + local @ sim.data.site_xmat[site].reshape(3, 3).T
        points.append(world[:, :2])

    probe = Node("probe", context=Context(ex))
    probe.create_subscription(msgs.LaserScan, "/mybot/laser/scan", on_scan)
    cmd = probe.create_publisher(msgs.Twist, "cmd_vel")
    probe.create_timer(0.1, lambda: cmd.publish(msgs.twist(0.3, 0.5)))
    session.run(2.0)
    pts = np.concatenate(points)
    assert len(points) == 80 and len(pts) > 80 * 700  # a closed room: nearly every beam returns
    res, bounds = 0.05, (-6.0, -5.0, 6.0, 5.0)
    grid = binary_dilation(occupancy(sim.world, res, bounds), iterations=2)  # 10 cm: noise + cell size
    j = ((pts[:, 0] - bounds[0]) / res).astype(int)
    i = ((pts[:, 1] - bounds[1]) / res).astype(int)
    assert np.mean(grid[i, j]) > 0.99
