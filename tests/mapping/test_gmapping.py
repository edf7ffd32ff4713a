"""The GMapping-style RBPF: corrects drifting odometry in a synthetic room; seeded; parameter names."""

from __future__ import annotations

import numpy as np
import pytest

from navlab.core import read_params
from navlab.mapping import MappingError
from navlab.mapping.gmapping import GMapping, GMappingParams


def _run(world, odometry_noise, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, GMapping]:
    rng = np.random.default_rng(11)
    gt = world.route()[:230]
    odo = odometry_noise(gt, rng)
    g = GMapping(GMappingParams(particles=12, linearUpdate=0.3, angularUpdate=0.2), rng=np.random.default_rng(seed))
    for p_true, p_odo in zip(gt, odo, strict=True):
        g.add_scan(world.scan(p_true, rng), world.angle_min, world.angle_increment, p_odo)
    return gt, odo, g.finish(), g


def test_rbpf_beats_drifting_odometry_and_is_seeded(synth_world, odometry_noise):
    gt, odo, est, g = _run(synth_world, odometry_noise, seed=3)
    err_odo = np.hypot(*(odo - gt)[:, :2].T)
    err = np.hypot(*(est - gt)[:, :2].T)
    assert err_odo.max() > 0.4
    assert err.max() < 0.15 and err.mean() < 0.06
    assert g.updates > 20
    # the best particle's map has walls where the world has them: the bottom wall y = 0
    grid = g.map()
    occ = grid.cell_to_world(np.argwhere(grid.occupied_mask())[:, ::-1])
    assert np.any(np.abs(occ[:, 1]) < 0.1)
    _, _, est2, _ = _run(synth_world, odometry_noise, seed=3)
    np.testing.assert_array_equal(est, est2)


def test_gmapping_parameter_names_and_defaults():
    p = GMappingParams()
    assert (p.particles, p.linearUpdate, p.angularUpdate, p.delta, p.sigma, p.lsigma, p.ogain) == (
        30,
        1.0,
        0.5,
        0.05,
        0.05,
        0.075,
        3.0,
    )
    assert (p.srr, p.srt, p.str, p.stt, p.resampleThreshold, p.iterations) == (0.1, 0.2, 0.1, 0.2, 0.5, 5)
    with pytest.raises(MappingError, match="did you mean 'linearUpdate'"):
        read_params(GMappingParams, {"linearupdate": 0.5})
