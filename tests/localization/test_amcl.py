"""AMCL on the synthetic room: tracking, global localization, kidnapping, determinism, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from amcl_synth import odometry, room_field, route, scan_at

from navlab.localization import Amcl, AmclParams, LocalizationError, Scan, build_field


def _run(
    params: AmclParams, truth: list, odo: list, *, seed: int = 1, init: tuple | None = None, scan_seed: int = 0
) -> tuple[Amcl, np.ndarray]:
    """Run the filter along the route; return it and per-step (position error m, |yaw error| rad)."""
    field = room_field()
    rng = np.random.default_rng(scan_seed)
    amcl = Amcl(field, params, rng=np.random.default_rng(seed))
    if init is None:
        amcl.global_localization()
    else:
        amcl.set_initial_pose(*init)
    errs = []
    for k, pose in enumerate(truth):
        amcl.update(odo[k], scan_at(field, pose, rng))
        ex, ey, eth = amcl.pose_from_odom(odo[k])
        errs.append((math.hypot(ex - pose[0], ey - pose[1]), abs(math.remainder(eth - pose[2], 2 * math.pi))))
    return amcl, np.array(errs)


def test_tracking_follows_the_route_within_centimetres() -> None:
    truth = route(500)  # 50 s, about 12 m driven, odometry 3 % long and drifting in heading
    odo = odometry(truth, np.random.default_rng(5), start=(2.0, -1.0, 0.5))
    params = AmclParams(
        odom_model_type="diff-corrected",
        odom_alpha1=0.05,
        odom_alpha2=0.05,
        odom_alpha3=0.05,
        odom_alpha4=0.05,
        laser_max_beams=60,
    )
    amcl, errs = _run(params, truth, odo, init=truth[0])
    assert errs[:, 0].mean() < 0.05
    assert errs[:, 0].max() < 0.15
    assert math.degrees(errs[:, 1].mean()) < 2.0
    # odometry alone would be off by decimetres by now
    assert amcl.n_updates > 40


def test_tracking_with_ros_defaults_and_beam_model() -> None:
    truth = route(250)
    odo = odometry(truth, np.random.default_rng(6))
    for model in ("likelihood_field", "beam"):
        _, errs = _run(AmclParams(laser_model_type=model, max_particles=2000), truth, odo, init=truth[0])
        assert errs[:, 0].mean() < 0.08, model
        assert math.degrees(errs[:, 1].mean()) < 3.0, model


def test_kld_sampling_shrinks_the_cloud_when_converged() -> None:
    truth = route(200)
    odo = odometry(truth, np.random.default_rng(7))
    amcl, _ = _run(AmclParams(min_particles=150), truth, odo, init=truth[0])
    assert 150 <= amcl.n_particles < 1500  # started with max_particles = 5000
    spread = np.hypot(*(amcl.particles[:, :2] - amcl.particles[:, :2].mean(0)).T)
    assert np.median(spread) < 0.2


def test_global_localization_converges_from_a_uniform_spread() -> None:
    truth = route(450)
    odo = odometry(truth, np.random.default_rng(8))
    amcl, errs = _run(AmclParams(), truth, odo)
    assert errs[0, 0] > 0.5  # it really started lost
    assert errs[-100:, 0].max() < 0.10  # converged and stayed for the last 10 s
    assert amcl.n_particles < 5000


def test_kidnapped_robot_recovers_with_recovery_alphas() -> None:
    full = route(1000)
    k0, jump = 150, 170
    truth = full[:k0] + full[k0 + jump : k0 + jump + 450]
    assert math.dist(truth[k0 - 1][:2], truth[k0][:2]) > 3.0
    odo = odometry(truth, np.random.default_rng(9), teleport_at=k0)
    params = AmclParams(recovery_alpha_slow=0.01, recovery_alpha_fast=0.1)
    _, errs = _run(params, truth, odo, init=truth[0])
    assert errs[k0 - 10 : k0, 0].max() < 0.15  # tracking before
    assert errs[k0 + 5, 0] > 2.0  # lost right after the teleport
    assert errs[-50:, 0].max() < 0.15  # found again and tracking
    # without recovery it stays lost
    _, errs0 = _run(AmclParams(), truth, odo, init=truth[0])
    assert errs0[-50:, 0].min() > 0.5


def test_same_seed_gives_identical_particle_clouds() -> None:
    truth = route(120)
    odo = odometry(truth, np.random.default_rng(3))
    a, _ = _run(AmclParams(max_particles=1000), truth, odo, seed=42)
    b, _ = _run(AmclParams(max_particles=1000), truth, odo, seed=42)
    c, _ = _run(AmclParams(max_particles=1000), truth, odo, seed=43)
    assert np.array_equal(a.particles, b.particles)
    assert np.array_equal(a.weights, b.weights)
    assert not np.array_equal(a.particles.shape, c.particles.shape) or not np.array_equal(a.particles, c.particles)


def test_updates_only_after_enough_motion_or_on_request() -> None:
    field = room_field()
    rng = np.random.default_rng(0)
    amcl = Amcl(field, AmclParams(update_min_d=0.2, update_min_a=0.5), rng=np.random.default_rng(0))
    amcl.set_initial_pose(3.0, 3.0, 0.0)
    scan = scan_at(field, (3.0, 3.0, 0.0), rng)
    assert amcl.update((0.0, 0.0, 0.0), scan)  # the first scan always updates
    assert not amcl.update((0.15, 0.0, 0.0), scan)
    assert not amcl.update((0.15, 0.0, 0.45), scan)
    amcl.request_nomotion_update()
    assert amcl.update((0.15, 0.0, 0.45), scan)
    assert amcl.update((0.15, 0.25, 0.45), scan)  # moved 0.25 m in y since the last update
    assert amcl.n_updates == 3


def test_a_new_initial_pose_is_not_moved_by_motion_from_before_it() -> None:
    field = room_field()
    rng = np.random.default_rng(0)
    amcl = Amcl(field, AmclParams(), rng=np.random.default_rng(0))
    amcl.set_initial_pose(1.0, 1.0, 0.0)
    assert amcl.update((0.0, 0.0, 0.0), scan_at(field, (1.0, 1.0, 0.0), rng))
    amcl.set_initial_pose(3.0, 3.0, 0.0, np.diag([0.01, 0.01, 0.001]))  # robot drove 1 m meanwhile
    assert amcl.update((1.0, 0.0, 0.0), scan_at(field, (3.0, 3.0, 0.0), rng))
    assert math.dist(amcl.estimate[:2], (3.0, 3.0)) < 0.1


def test_all_inf_scan_is_no_update() -> None:
    field = room_field()
    amcl = Amcl(field, AmclParams(), rng=np.random.default_rng(0))
    amcl.set_initial_pose(3.0, 3.0, 0.0)
    before = amcl.particles.copy()
    blank = Scan(
        ranges=np.full(360, np.inf), angle_min=-math.pi, angle_increment=2 * math.pi / 360, range_min=0.1, range_max=8.0
    )
    assert not amcl.update((0.0, 0.0, 0.0), blank)
    nan = Scan(
        ranges=np.full(360, np.nan), angle_min=-math.pi, angle_increment=2 * math.pi / 360, range_min=0.1, range_max=8.0
    )
    assert not amcl.update((1.0, 0.0, 0.0), nan)
    assert np.array_equal(before, amcl.particles)
    assert amcl.n_updates == 0


def test_bad_initial_pose_and_maps_are_refused_with_a_message() -> None:
    field = room_field()
    amcl = Amcl(field, AmclParams(), rng=np.random.default_rng(0))
    with pytest.raises(LocalizationError, match="not finite"):
        amcl.set_initial_pose(float("nan"), 1.0, 0.0)
    with pytest.raises(LocalizationError, match="outside the map"):
        amcl.set_initial_pose(50.0, 1.0, 0.0)
    with pytest.raises(LocalizationError, match="no particles"):
        amcl.update((0.0, 0.0, 0.0), scan_at(field, (3.0, 3.0, 0.0), np.random.default_rng(0)))
    with pytest.raises(LocalizationError, match="no free cells"):
        build_field(np.full((20, 20), 100, dtype=np.int8), 0.05)
    with pytest.raises(LocalizationError, match="no free cells"):
        build_field(np.full((20, 20), -1, dtype=np.int8), 0.05)
    with pytest.raises(LocalizationError, match="resolution"):
        build_field(np.zeros((20, 20), dtype=np.int8), 0.0)
    with pytest.raises(LocalizationError, match="laser_model_type"):
        Amcl(field, AmclParams(laser_model_type="likelihood_feild"), rng=np.random.default_rng(0))
    with pytest.raises(LocalizationError, match="min_particles"):
        Amcl(field, AmclParams(min_particles=500, max_particles=100), rng=np.random.default_rng(0))
