"""The pure simulator: driving, turning, torque limit, lidar semantics, spawning, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_helpers import box_model, make_mybot, make_room

from navlab.sim import SimError, Simulation
from navlab.sim.simulation import lidar_angles
from navlab.world import WorldModel

WHEEL_R = 0.08
HALF_SEP = 0.2


def _drive(sim: Simulation, v: float, w: float, seconds: float) -> None:
    sim.set_wheel_velocity_targets((v - w * HALF_SEP) / WHEEL_R, (v + w * HALF_SEP) / WHEEL_R)
    sim.advance_to(sim.time_ns + round(seconds * 1e9))


def test_drives_two_metres_straight() -> None:
    sim = Simulation(make_mybot(), make_room(), seed=0)
    x0, y0, yaw0 = sim.base_pose2d()
    _drive(sim, 0.5, 0.0, 4.0)
    x, y, yaw = sim.base_pose2d()
    assert x - x0 == pytest.approx(2.0, abs=0.1)
    assert abs(y - y0) < 0.02
    assert abs(yaw - yaw0) < 0.01
    assert sim.link_pose().position[2] == pytest.approx(0.08, abs=0.005)  # stayed on its wheels


def test_turns_three_radians_in_place() -> None:
    sim = Simulation(make_mybot(), make_room(), seed=0)
    _drive(sim, 0.0, 1.0, 3.0)
    x, y, yaw = sim.base_pose2d()
    assert yaw == pytest.approx(3.0, abs=0.15)
    assert math.hypot(x, y) < 0.02


def test_torque_limit_caps_acceleration() -> None:
    weak = Simulation(make_mybot(torque=0.5), make_room(), seed=0)
    strong = Simulation(make_mybot(torque=15.0), make_room(), seed=0)
    for sim in (weak, strong):
        _drive(sim, 0.5, 0.0, 0.3)
    v_weak = weak.link_velocity()[0][0]
    v_strong = strong.link_velocity()[0][0]
    # 2 wheels x 0.5 N m / 0.08 m on 14 kg plus the wheels' rotational inertia (2 kg equivalent)
    expected = 2 * 0.5 / WHEEL_R / 16.0 * 0.3
    assert v_weak == pytest.approx(expected, rel=0.05)
    assert v_strong == pytest.approx(0.5, abs=0.02)


def test_lidar_sees_wall_at_known_distance_within_noise() -> None:
    sim = Simulation(make_mybot(noise=0.01), make_room(), seed=3)
    ranges = sim.scan()
    angles = lidar_angles(make_mybot().lidars[0])
    assert ranges.dtype == np.float32 and ranges.shape == (720,)
    east = np.abs(angles) < math.atan2(3.9, 5.0)  # beams ending on the east wall's inner face, x = 5
    expected = 5.0 / np.cos(angles[east])
    err = ranges[east] - expected
    assert np.mean(np.abs(err) < 3 * 0.01) > 0.99  # gaussian: 99.7 % of beams within 3 sigma
    assert np.all(np.abs(err) < 5 * 0.01)
    assert abs(np.mean(err)) < 3 * 0.01 / math.sqrt(len(err))  # no bias
    assert np.std(err) == pytest.approx(0.01, rel=0.25)  # the noise is really there


def test_lidar_inf_beyond_range_max_and_nothing_under_range_min() -> None:
    far = WorldModel("far", models=[box_model("far_wall", 30.0, 0.0, (0.2, 60.0, 2.0))])
    ranges = Simulation(make_mybot(), far, seed=0).scan()
    assert np.all(np.isinf(ranges))  # only a wall 30 m away: beyond the 25 m range

    # a small box at the laser's height 0.11 m in front of it, clear of the chassis: inside range_min,
    # so (as in Gazebo, whose rays start at range_min) the beam sees the wall behind it
    sim = Simulation(make_mybot(noise=0.0), make_room(), seed=0)
    laser_z = sim.data.site_xpos[sim._lidar_site[0]][2]
    tiny = box_model("tiny", 0.12, 0.0, (0.02, 0.02, 0.02))
    tiny.pose = (0.12, 0.0, laser_z, 0.0, 0.0, 0.0)
    sim.spawn(tiny)
    ranges = sim.scan()
    finite = ranges[np.isfinite(ranges)]
    assert finite.min() >= 0.2
    assert ranges[360] == pytest.approx(5.0, abs=1e-3)  # beam 360 of 720 points straight ahead


def test_spawned_box_appears_in_next_scan_and_removal_clears_it() -> None:
    sim = Simulation(make_mybot(noise=0.0), make_room(), seed=0)
    sim.step(100)
    assert sim.scan()[360] == pytest.approx(5.0, abs=1e-3)
    sim.spawn(box_model("box1", 2.0, 0.0, (0.5, 0.5, 0.5), static=False))
    assert sim.scan()[360] == pytest.approx(1.75, abs=1e-3)
    sim.step(500)  # a dynamic box rests on the floor and the robot keeps its state
    assert sim.model_pose("box1").position[2] == pytest.approx(0.25, abs=0.005)
    assert sim.scan()[360] == pytest.approx(1.75, abs=5e-3)
    assert sim.time_ns == 600 * sim.dt_ns
    sim.remove("box1")
    assert sim.scan()[360] == pytest.approx(5.0, abs=1e-3)
    with pytest.raises(SimError, match="box1"):
        sim.remove("box1")


def test_spawn_keeps_robot_motion() -> None:
    sim = Simulation(make_mybot(), make_room(), seed=0)
    _drive(sim, 0.5, 0.0, 1.0)
    before = sim.base_pose2d()
    sim.spawn(box_model("box1", -3.0, 2.0, (0.3, 0.3, 0.3)))
    assert sim.base_pose2d() == pytest.approx(before, abs=1e-9)
    _drive(sim, 0.5, 0.0, 1.0)  # still commanded, still moving at 0.5 m/s
    assert sim.base_pose2d()[0] - before[0] == pytest.approx(0.5, abs=0.02)


def test_same_seed_same_scans() -> None:
    def scans(seed: int) -> list[np.ndarray]:
        sim = Simulation(make_mybot(), make_room(), seed=seed)
        out = []
        for _ in range(3):
            _drive(sim, 0.3, 0.2, 0.2)
            out.append(sim.scan())
        return out

    a, b, c = scans(5), scans(5), scans(6)
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert not np.array_equal(a[0], c[0])


def test_bad_input_is_a_clear_error() -> None:
    robot = make_mybot()
    robot.diff_drive.left_joint = "no_such_joint"  # type: ignore[union-attr]
    with pytest.raises(SimError, match="no_such_joint"):
        Simulation(robot, make_room())
    robot = make_mybot()
    robot.lidars[0].link = "nowhere"
    with pytest.raises(SimError, match="nowhere"):
        Simulation(robot, make_room())
    with pytest.raises(SimError, match="timestep"):
        Simulation(make_mybot(), make_room(), timestep=0.005)
    sim = Simulation(make_mybot(), make_room())
    with pytest.raises(SimError, match="wall_north"):
        sim.spawn(box_model("wall_north", 1.0, 1.0, (0.1, 0.1, 0.1)))


def test_numba_lidar_matches_mj_multiray() -> None:
    from dataclasses import replace

    from navlab.description import Origin
    from navlab.sim import primitive_model

    robot = make_mybot(noise=0.0)
    tilted = replace(robot.lidars[0], origin=Origin((0.0, 0.0, 0.0), (0.25, 0.1, 0.0)), name="tilted")
    robot.lidars.append(tilted)  # looks down at the floor on one side, up on the other
    sim = Simulation(robot, make_room(), seed=0, robot_pose=(-1.0, 0.5, 0.7))
    sim.spawn(primitive_model("box", "crate", (0.4, 0.7, 0.5), x=1.0, y=1.5, yaw=0.6))
    sim.spawn(primitive_model("cylinder", "drum", (0.3, 0.8), x=-3.0, y=-1.0))
    sim.spawn(primitive_model("sphere", "ball", (0.3,), x=-1.0, y=-2.0, static=False))
    sim.step(50)
    for index in (0, 1):
        fast = sim.true_ranges(index, backend="numba")
        ref = sim.true_ranges(index, backend="mujoco")
        assert np.array_equal(np.isinf(fast), np.isinf(ref))
        both = np.isfinite(ref)
        assert both.sum() > 500
        np.testing.assert_allclose(fast[both], ref[both], atol=1e-9)
    assert np.nanmin(np.where(np.isfinite(ref), ref, np.nan)) < 1.0  # the tilted lidar sees the floor


def test_scan_in_one_call_matches_the_cast_then_the_noise() -> None:
    """Simulation.scan's fused cast + noise gives the ranges of true_ranges + finish_ranges with the same draws."""
    from navlab.sim.raycast import finish_ranges

    sim = Simulation(make_mybot(noise=0.01), make_room(), seed=3, robot_pose=(-1.0, 0.5, 0.7))
    sim.step(20)
    cfg = sim.robot.lidars[0]  # type: ignore[union-attr]
    for _ in range(3):
        got = sim.scan(0, np.random.default_rng(7))
        dist = sim.true_ranges(0)
        want = np.empty(len(dist), dtype=np.float32)
        normals = np.random.default_rng(7).standard_normal(len(dist))
        finish_ranges(dist, normals, cfg.noise_mean, cfg.noise_stddev, cfg.range_min, cfg.range_max, want)
        assert np.isfinite(got).sum() > 500
        assert got.tobytes() == want.tobytes()
        sim.step(10)


def test_fixed_links_keep_their_frames() -> None:
    sim = Simulation(make_mybot(), make_room(), seed=0, robot_pose=(1.0, 2.0, 0.7))
    _drive(sim, 0.0, 1.0, 0.5)  # turning in place
    chassis = sim.link_pose("chassis")
    laser = sim.link_pose("laser")  # fused into the chassis body, 6 cm above it
    np.testing.assert_allclose(laser.position, chassis.position + np.array([0.0, 0.0, 0.06]), atol=1e-9)
    assert laser.yaw == pytest.approx(chassis.yaw)
    lin, ang = sim.link_velocity("laser")
    assert ang[2] == pytest.approx(1.0, abs=0.05) and np.linalg.norm(lin) < 0.02
    np.testing.assert_allclose(sim.data.site_xpos[sim._lidar_site[0]], laser.position, atol=1e-9)
    with pytest.raises(SimError, match="no link 'nope'"):
        sim.link_pose("nope")


def test_planar_caster_sees_the_floor_up_to_the_cutoff_and_not_beyond() -> None:
    from navlab.sim.raycast import PLANE, cast_planar

    n, h, cutoff = 360, 0.2, 10.0
    a = np.linspace(-math.pi, math.pi, n, endpoint=False)
    for far in (0.999, 1.001):  # the floor's nearest hit just inside, then just beyond the cutoff
        tilt = math.asin(h / (far * cutoff))  # the scan plane pitched down about its y axis
        c, s = math.cos(tilt), math.sin(tilt)
        rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])  # columns: sensor axes in the world
        out = np.empty(n)
        cast_planar(
            np.array([0.0, 0.0, h]),
            rot,
            np.cos(a),
            np.sin(a),
            -math.pi,
            2 * math.pi / n,
            np.array([0], dtype=np.int32),
            np.array([PLANE]),
            np.zeros((1, 3)),
            np.zeros((1, 3)),
            np.eye(3).reshape(1, 9),
            0.05,
            cutoff,
            out,
        )
        dz = -s * np.cos(a)  # world z of each beam direction
        with np.errstate(divide="ignore"):
            expect = np.where(dz < 0, h / -dz, np.inf)
        expect[expect > cutoff] = np.inf
        assert np.isfinite(out).any() == (far < 1.0)
        np.testing.assert_allclose(out[np.isfinite(expect)], expect[np.isfinite(expect)], rtol=1e-12)
        assert np.array_equal(np.isinf(out), np.isinf(expect))


def test_link_state_is_link_pose_and_link_velocity() -> None:
    sim = Simulation(make_mybot(), make_room(), seed=0, robot_pose=(1.0, 2.0, 0.7))
    _drive(sim, 0.3, 0.8, 0.5)
    for link in ("chassis", "laser"):  # the body's own frame, and a link fused into it
        position, quaternion, lin, ang = sim.link_state(link)
        pose = sim.link_pose(link)
        v, w = sim.link_velocity(link)
        assert position == tuple(pose.position) and quaternion == tuple(pose.quaternion)
        assert lin == tuple(v) and ang == tuple(w)
