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
from navlab.navigation.controllers.rollout import footprint_costs

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
    cmd = shim.command(pose, (0.0, 0.0), local, DT, grid.data, RES, outline)
    assert cmd is not None and cmd[0] == 0.0  # in place
    w = cmd[1]
    err = shim.heading_error(pose, local)
    assert err is not None and abs(err) > 3.0  # the path is behind the robot
    assert w * err > 0  # turn toward it
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
    forward_only = {"use_rotation_shim": True, "rotation_shim_backup_dist": 0.5, "vx_min": 0.0}
    assert MPPIController(forward_only, rng=np.random.default_rng(0))._shim.backup_dist == 0.0  # never backs


def gap() -> Grid:
    """The box in a gap: cylinders 0.33 m to each side of the origin (0.04 m from its sides; its corners reach
    0.333 m, so it cannot turn there) and one 0.6 m ahead."""
    return cylinders((0.0, 0.33), (0.0, -0.33), (0.6, 0.0))


def test_shim_backs_a_box_out_of_a_gap_until_its_turn_is_free():
    """A driver's move: facing away from its path in a gap too tight to turn in, the box backs out straight, stops
    where the turn is free, turns there and drives on; no footprint pose touches a cylinder. Nav2's shim
    (``rotation_shim_backup_dist`` 0) leaves it to MPPI, which does not reach the path's leg in the same time."""
    outline = footprint_outline(np.array(BOX), RES)

    def drive(backup: float) -> tuple[list[tuple[float, float, float, float, float]], float]:
        params = {**JACKAL, "vx_min": -0.35, "use_rotation_shim": True, "rotation_shim_backup_dist": backup}
        ctrl = MPPIController(params, rng=np.random.default_rng(0), footprint=BOX)
        ctrl.set_plan(back_and_up())
        pose, vel, log = (0.0, 0.0, 0.0), (0.0, 0.0), []
        for k in range(160):
            local = syn.window(gap(), pose[0], pose[1])
            vel = ctrl.compute_velocity(pose, vel, local)
            pose = step(pose, vel)
            at = np.array([[pose[0] - local.origin[0], pose[1] - local.origin[1], pose[2]]])
            assert footprint_costs(local.data, RES, at, outline)[0] >= 0  # no contact
            log.append((*pose, *vel))
            if pose[1] > 1.5:
                return log, k * DT
        return log, math.inf

    log, t = drive(0.5)
    first_turn = next(i for i, s in enumerate(log) if abs(s[4]) > 0.1)
    backing = log[:first_turn]
    assert all(s[3] <= 0.0 and s[4] == 0.0 for s in backing)  # straight back first, no turn
    assert all(abs(s[1]) < 1e-9 and abs(s[2]) < 1e-9 for s in backing)  # straight out along its heading
    assert 0.2 < -log[first_turn][0] < 0.5  # out of the gap (the corners clear the cylinders at ~0.25 m) ...
    assert abs(log[first_turn - 1][3]) <= 0.1  # ... and stopped before turning
    assert t < 8.0 < drive(0.0)[1]  # up the path's leg in time; Nav2's shim alone is not
    shim = RotationShim(backup_dist=0.5)
    origin = syn.window(gap(), 0.0, 0.0)
    local = back_and_up()[:, :2] - origin.origin[:2]
    pose = (-origin.origin[0], -origin.origin[1], 0.0)
    assert RotationShim().command(pose, (0.0, 0.0), local, DT, origin.data, RES, outline) is None  # Nav2's: MPPI
    walled = syn.window(cylinders((0.0, 0.33), (0.0, -0.33), (-0.36, 0.0)), 0.0, 0.0)  # a post right behind
    assert shim.command(pose, (0.0, 0.0), local, DT, walled.data, RES, outline) is None  # cannot back: MPPI
