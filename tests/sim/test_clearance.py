"""Clearance from the simulator's geometry: the distance between the robot's collision shapes and the world's."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from navlab.description import load_robot_named
from navlab.sim import Simulation, primitive_model
from navlab.world import load_world

# the Jackal-sized robot of resources/robots/jackal: a 0.508 x 0.320 m chassis box, wheels (r 0.098 m, 0.04 m wide)
# at y = +-0.37559 / 2, so its widest point is a wheel's outer face at 0.2078 m from the centre line
FRONT, SIDE = 0.254, 0.37559 / 2 + 0.02


@pytest.mark.parametrize(
    ("yaw", "box_xy", "expected"),
    [
        (0.0, (FRONT + 0.3 + 0.2, 0.0), 0.3),  # 0.3 m ahead of the chassis' front face
        (0.0, (0.0, SIDE + 0.25 + 0.2), 0.25),  # 0.25 m beside a wheel (the chassis is 0.048 m further in)
        (math.pi / 2, (SIDE + 0.25 + 0.2, 0.0), 0.25),  # turned: the same wheel now faces +x
        # turned 45 degrees: the chassis corner reaches x = 0.254 cos45 + 0.16 sin45
        (math.pi / 4, (1.0, 0.0), 0.8 - (0.254 + 0.16) * math.sqrt(0.5)),
    ],
)
def test_a_rectangular_robot_beside_a_box_reports_the_geometric_distance(
    yaw: float, box_xy: tuple[float, float], expected: float
) -> None:
    sim = Simulation(load_robot_named("jackal"), load_world("room"), robot_pose=(0.0, 0.0, yaw))
    sim.spawn(primitive_model("box", "box", (0.4, 0.4, 0.5), x=box_xy[0], y=box_xy[1]))
    assert sim.clearance() == pytest.approx(expected, abs=0.01)


def test_clearance_is_negative_in_contact_and_capped_far_away() -> None:
    sim = Simulation(load_robot_named("jackal"), load_world("room"), robot_pose=(0.0, 0.0, 0.0))
    assert sim.clearance(max_distance=0.5) == 0.5  # the room's walls are ~2 m away
    sim.spawn(primitive_model("box", "box", (0.4, 0.4, 0.5), x=FRONT + 0.15, y=0.0))  # 5 cm into the chassis
    assert sim.clearance() == pytest.approx(-0.05, abs=0.01)


def _every_pair(sim: Simulation, max_distance: float = 2.0) -> float:
    """The plain walk: every pair nearest bounding spheres first, until a bound reaches the best distance."""
    m, d, robot, world = sim.model, sim.data, sim._clear_robot, sim._clear_world
    centres = np.linalg.norm(d.geom_xpos[robot][:, None, :] - d.geom_xpos[world][None, :, :], axis=2)
    bound = centres - m.geom_rbound[robot][:, None] - m.geom_rbound[world][None, :]
    best = max_distance
    for k in np.argsort(bound, axis=None):
        i, j = divmod(int(k), len(world))
        if bound[i, j] >= best:
            break
        best = min(best, mujoco.mj_geomDistance(m, d, int(robot[i]), int(world[j]), best, None))
    return float(best)


@pytest.mark.parametrize("robot", ["mybot", "jackal"])
def test_skipping_far_pairs_gives_the_plain_walks_distance_bit_for_bit(robot: str) -> None:
    sim = Simulation(load_robot_named(robot), load_world("room_obstacles"), robot_pose=(0.0, 0.0, 0.0))
    sim.spawn(primitive_model("box", "tilted", (0.3, 0.6, 0.4), x=1.2, y=-0.6, yaw=0.7))
    sim.spawn(primitive_model("cylinder", "post", (0.15, 0.5), x=-0.9, y=0.8))
    sim.spawn(primitive_model("sphere", "ball", (0.2,), x=0.4, y=1.3))
    rng = np.random.default_rng(3)
    values = []
    for _ in range(150):
        sim.teleport(*rng.uniform(-2.0, 2.0, 2), rng.uniform(-math.pi, math.pi))
        values.append(sim.clearance())
        assert values[-1] == _every_pair(sim)
    assert min(values) < 0.0 < max(values)  # in contact and clear both seen
