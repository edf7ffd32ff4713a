"""Map scoring against a known truth: perfect map, shifted map, partial map, coverage."""

import numpy as np
import pytest

from navlab.experiments.metrics import free_coverage, score_map, trajectory_error
from navlab.grid import Grid, GridMap
from navlab.world import truth_grid


def _truth() -> Grid:
    occ = np.zeros((80, 100), bool)  # 5 × 4 m at 5 cm, origin (-2.5, -2)
    occ[:2, :] = occ[-2:, :] = True
    occ[:, :2] = occ[:, -2:] = True
    return truth_grid(occ, 0.05, (-2.5, -2.0))


def _map_from_truth(truth: Grid, shift_cells: int = 0) -> GridMap:
    data = np.where(truth.data, 100, 0).astype(np.int8)
    return GridMap(data, 0.05, (truth.origin[0] + shift_cells * 0.05, truth.origin[1], 0.0))


def test_perfect_map_scores_one():
    t = _truth()
    s = score_map(_map_from_truth(t), t)
    assert s["precision"] == 1.0 and s["recall"] == 1.0 and s["mean_wall_error_m"] == 0.0
    assert free_coverage(_map_from_truth(t), t) == 1.0


def test_map_shifted_by_three_cells_loses_precision_and_recall():
    t = _truth()
    s = score_map(_map_from_truth(t, 3), t)
    assert s["precision"] < 0.9 and s["recall"] < 0.9


def test_start_pose_is_applied():
    t = _truth()
    m = _map_from_truth(t, 4)  # the map frame is the world shifted by +0.2 m in x ...
    s = score_map(m, t, world_T_map=(-0.2, 0.0, 0.0))  # ... and the evaluator is told so
    assert s["precision"] == 1.0 and s["recall"] == 1.0


def test_unknown_half_halves_coverage():
    t = _truth()
    m = _map_from_truth(t)
    m.data[:, 50:] = -1
    assert free_coverage(m, t) == pytest.approx(0.5, abs=0.05)


def test_trajectory_error():
    est = np.array([[0.0, 0.0, 0.0], [1.0, 0.1, 0.1]])
    tru = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    e = trajectory_error(est, tru)
    assert e["position_error_max_m"] == pytest.approx(0.1)
    assert e["yaw_error_mean_deg"] == pytest.approx(np.degrees(0.05), abs=1e-3)
