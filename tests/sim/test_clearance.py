"""Clearance from the simulator's geometry: the distance between the robot's collision shapes and the world's."""

from __future__ import annotations

import math

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
