"""MPPI's rotation shim (Nav2's RotationShimController's rule): a robot standing facing away from its path turns in
place toward it first, where the turn is free, and only when it stands still."""

import math

import numpy as np
import pytest

from navlab.grid import Grid
from navlab.navigation.controllers import synthetic as syn
from navlab.navigation.controllers.common import footprint_outline
from navlab.navigation.controllers.mppi import MPPIController
from navlab.navigation.controllers.mppi_rotation import RotationShim

RES, DT = 0.05, 0.05  # m, s
BOX = [[-0.254, -0.215], [-0.254, 0.215], [0.254, 0.215], [0.254, -0.215]]  # the Jackal's footprint
JACKAL = {  # the Jackal's clutter settings (params/jackal)
    "vx_max": 2.0,
    "vx_std": 0.4,
    "time_steps": 40,
    "use_cost_regulated_linear_velocity_scaling": True,
    "inflation_cost_scaling_factor": 10.0,  # syn.inflated's
    "CostCritic": {"consider_footprint": True},
}


def cylinders(*centres: tuple[float, float]) -> Grid:
    """10 m x 10 m of open ground around the origin with 0.075 m cylinders at ``centres``, inflated."""
    mask = syn.disc_mask((200, 200), RES, np.array(centres), np.full(len(centres), 0.075), (-5.0, -5.0))
    return Grid(syn.inflated(mask, RES), RES, (-5.0, -5.0, 0.0), "odom")


def slot() -> Grid:
    """A row of cylinders 0.45 m to each side of the origin (the box turns in place there, and cannot drive while
    turning) and one 0.7 m ahead."""
    return cylinders(*[(x, y) for x in (-0.3, 0.0, 0.3) for y in (0.45, -0.45)], (0.7, 0.0))


def step(pose: tuple[float, float, float], cmd: tuple[float, float]) -> tuple[float, float, float]:
    x, y, th = pose
    return x + cmd[0] * math.cos(th) * DT, y + cmd[0] * math.sin(th) * DT, th + cmd[1] * DT


def back_and_up() -> np.ndarray:
    """A plan from the origin 0.8 m back (-x), then 3.2 m to +y: behind the robot facing +x."""
    back = np.column_stack([np.linspace(0.0, -0.8, 17), np.zeros(17)])
    up = np.column_stack([np.full(64, -0.8), np.linspace(0.05, 3.2, 64)])
    return np.column_stack([np.vstack([back, up]), np.zeros(81)])


def test_shim_turns_a_standing_robot_toward_its_path_only_when_free():
    shim = RotationShim()
    grid = syn.window(slot(), 0.0, 0.0)
    outline = footprint_outline(np.array(BOX), RES)
    ox, oy = grid.origin[:2]
    local = back_and_up()[:, :2] - (ox, oy)
    pose = (-ox, -oy, 0.0)
    w = shim.command(pose, (0.0, 0.0), local, DT, grid.data, RES, outline)
    err = shim.heading_error(pose, local)
    assert err is not None and abs(err) > 3.0  # the path is behind the robot
    assert w is not None and w * err > 0  # turn toward it
    assert w <= shim.max_angular_accel * DT + 1e-12  # from standing, within the angular acceleration
    assert shim.command(pose, (0.5, 0.0), local, DT, grid.data, RES, outline) is None  # moving: MPPI drives
    ahead = np.column_stack([np.linspace(0.0, 2.0, 41), np.zeros(41)]) - (ox, oy)
    assert shim.command(pose, (0.0, 0.0), ahead, DT, grid.data, RES, outline) is None  # facing its path
    # cylinders 0.26 m to the sides of the box: its corners would hit them
    tight = syn.window(cylinders((0.0, 0.33), (0.0, -0.33)), 0.0, 0.0)
    assert shim.command(pose, (0.0, 0.0), local, DT, tight.data, RES, outline) is None


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_mppi_with_the_shim_gets_going_on_a_path_behind_it_sooner(seed):
    """Standing in the slot facing away from its path, plain MPPI backs and wriggles out (> 5.5 s to 1.5 m up the
    path, or not in 10 s); with the shim it turns in place and drives forward (< 5.5 s)."""

    def time_to_leg(shim: bool) -> float:
        ctrl = MPPIController({**JACKAL, "use_rotation_shim": shim}, rng=np.random.default_rng(seed), footprint=BOX)
        ctrl.set_plan(back_and_up())
        world = slot()
        pose, vel = (0.0, 0.0, 0.0), (0.0, 0.0)
        for k in range(200):
            vel = ctrl.compute_velocity(pose, vel, syn.window(world, pose[0], pose[1]))
            pose = step(pose, vel)
            if pose[1] > 1.5:
                return k * DT
        return math.inf

    assert time_to_leg(True) < 5.5 < time_to_leg(False)


def test_shim_parameters():
    assert MPPIController(rng=np.random.default_rng(0))._shim is None  # off by default: MPPI unchanged
    ctrl = MPPIController({"use_rotation_shim": True, "angular_dist_threshold": 1.0}, rng=np.random.default_rng(0))
    assert ctrl._shim == RotationShim(angular_dist_threshold=1.0)
    with pytest.raises(Exception, match="rotate_to_heading_angular_vel"):
        MPPIController({"rotate_to_heading_angular_vel": 0.0}, rng=np.random.default_rng(0))
