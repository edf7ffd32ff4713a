"""AMCL's odom_model_type and laser_model_type as plugins: ROS and Nav2 names, "did you mean", new models."""

from __future__ import annotations

import math

import numpy as np
import pytest
from amcl_synth import room_field

from navlab import plugins
from navlab.localization import Amcl, AmclParams, LocalizationError, Scan
from navlab.localization.models import BeamModel, LikelihoodFieldModel, sample_motion_diff, sample_motion_diff_corrected


def test_ros_and_nav2_names_pick_the_models() -> None:
    assert AmclParams(odom_model_type="diff").motion_model() is sample_motion_diff
    for name in ("diff-corrected", "nav2_amcl::DifferentialMotionModel", "differential"):
        assert AmclParams(odom_model_type=name).motion_model() is sample_motion_diff_corrected
    assert AmclParams(laser_model_type="likelihood_field").laser_model() is LikelihoodFieldModel
    assert AmclParams(laser_model_type="beam").laser_model() is BeamModel
    with pytest.raises(LocalizationError, match=r"odom_model_type 'omni'.*known: diff, diff-corrected"):
        AmclParams(odom_model_type="omni").validate()


def test_corrected_model_takes_the_square_root_of_the_variances() -> None:
    a = np.zeros((3000, 3))
    b = np.zeros((3000, 3))
    step = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.1, 0.1, 0.1, 0.1))
    sample_motion_diff_corrected(a, *step, np.random.default_rng(3))
    sample_motion_diff(b, *step, np.random.default_rng(3), corrected=True)
    np.testing.assert_array_equal(a, b)
    assert 0.25 < a[:, 0].std() < 0.4  # sqrt(alpha3) * 1 m, not the variance 0.1 m of ROS's 'diff'


class _UniformModel:
    """A toy laser model: every particle scores the same, so the filter follows odometry only."""

    calls = 0

    def __init__(self, field, params: AmclParams) -> None:
        self.field = field

    @classmethod
    def from_params(cls, params: AmclParams, *, context: plugins.PluginContext) -> _UniformModel:
        return cls(context.map_field, params)

    def weights(self, particles: np.ndarray, beams, laser_pose) -> np.ndarray:
        type(self).calls += 1
        return np.ones(particles.shape[0])


def test_a_new_laser_model_is_one_class_and_one_entry_point(install_plugin_package) -> None:
    install_plugin_package(
        "navlab-test-uniform-model", {"navlab.laser_models": {"uniform": f"{__name__}:_UniformModel"}}
    )
    field = room_field()
    amcl = Amcl(
        field,
        AmclParams(laser_model_type="uniform", max_particles=500, min_particles=500),
        rng=np.random.default_rng(0),
    )
    amcl.set_initial_pose(2.0, 2.0, 0.0)
    scan = Scan(np.full(60, 2.0), -math.pi, 2 * math.pi / 60, 0.1, 10.0)
    assert amcl.update((0.0, 0.0, 0.0), scan) and amcl.update((0.5, 0.0, 0.0), scan)
    assert _UniformModel.calls == 2
    assert math.hypot(amcl.estimate[0] - 2.5, amcl.estimate[1] - 2.0) < 0.15
