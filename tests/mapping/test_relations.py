"""The relations metric (Kümmerle et al. 2009) and its CLI."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from navlab.cli import main
from navlab.experiments.metrics import read_relations, relations_closure, relations_error
from navlab.io import IoError
from navlab.io.poses import write_poses
from navlab.mapping import MappingError


def _traj(n: int = 50) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) * 0.2 + 1000.0
    th = np.linspace(0, 2.0, n)
    return t, np.stack([np.cos(th) * 3, np.sin(th) * 3, th + math.pi / 2], axis=1)


def _relations(t: np.ndarray, p: np.ndarray, pairs: list[tuple[int, int]]) -> np.ndarray:
    rows = []
    for i, j in pairs:
        c, s = math.cos(p[i, 2]), math.sin(p[i, 2])
        dx, dy = p[j, 0] - p[i, 0], p[j, 1] - p[i, 1]
        rows.append([t[i], t[j], c * dx + s * dy, -s * dx + c * dy, p[j, 2] - p[i, 2]])
    return np.array(rows)


def test_perfect_poses_score_zero_and_known_offset_scores_it():
    t, p = _traj()
    rel = _relations(t, p, [(k, k + 1) for k in range(49)] + [(0, 40)])
    out = relations_error(t, p, rel)
    assert out["n_scored"] == 50 and out["trans_abs_mean"] < 1e-9 and out["rot_abs_mean_deg"] < 1e-9
    # shift one pose 10 cm sideways: the two relations touching it each err by 10 cm
    q = p.copy()
    q[10, 0] += 0.1
    out = relations_error(t, q, rel)
    assert out["trans_abs_mean"] == pytest.approx(0.2 / 50, rel=1e-6)
    # the whole trajectory moved rigidly: relative poses unchanged
    c, s = math.cos(0.7), math.sin(0.7)
    r = np.stack([c * p[:, 0] - s * p[:, 1] + 5, s * p[:, 0] + c * p[:, 1] - 2, p[:, 2] + 0.7], axis=1)
    assert relations_error(t, r, rel)["trans_abs_mean"] < 1e-9


def test_closure_of_exact_relations_is_zero_and_of_noisy_ones_gives_their_error():
    t, p = _traj(400)
    pairs = [(k, k + 1) for k in range(399)] + [(k, k + 2) for k in range(398)]  # 398 triangles
    rel = _relations(t, p, pairs)
    exact = relations_closure(rel)
    assert exact["n_triangles"] == 398 and exact["closure_mean_m"] < 1e-9 and exact["noise_floor_m"] < 1e-9
    noisy = rel.copy()
    noisy[:, 2:4] += np.random.default_rng(0).normal(0.0, 0.02, (len(rel), 2))  # 2 cm per axis
    out = relations_closure(noisy)
    # one relation's mean translational error is 0.02 * sqrt(pi / 2) = 0.0251 m; the floor estimates it from
    # the triangles alone, and an estimator with the true poses scores it
    assert out["noise_floor_m"] == pytest.approx(0.02 * math.sqrt(math.pi / 2), rel=0.1)
    assert relations_error(t, p, noisy)["trans_abs_mean"] == pytest.approx(out["noise_floor_m"], rel=0.1)
    assert relations_closure(_relations(t, p, [(0, 1), (2, 3)]))["n_triangles"] == 0


def test_unmatched_timestamps_counted_and_all_unmatched_is_error():
    t, p = _traj()
    rel = _relations(t, p, [(0, 1), (1, 2)])
    rel[1, 1] += 0.05  # no pose at this time
    out = relations_error(t, p, rel)
    assert out["n_relations"] == 2 and out["n_scored"] == 1
    with pytest.raises(MappingError, match="none of the 2 relations"):
        relations_error(t + 500.0, p, rel)


def test_raw_odometry_of_csail_scores_published_value(tmp_path, capsys, dataset):
    from navlab.io.carmen import read_carmen

    data = dataset("mit-csail")
    log = read_carmen(data / "mit-csail.clf")
    write_poses(
        tmp_path / "odom.txt", np.array([s.timestamp for s in log.scans]), np.array([s.odom_pose for s in log.scans])
    )
    assert main(["eval", "relations", str(tmp_path / "odom.txt"), str(data / "mit-csail.relations"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) == {
        "n_relations",
        "n_scored",
        "trans_abs_mean_m",
        "trans_abs_std_m",
        "trans_sq_mean_m2",
        "trans_abs_mean",  # deprecated aliases of the three above, kept one release
        "trans_abs_std",
        "trans_sq_mean",
        "rot_abs_mean_deg",
        "rot_abs_std_deg",
        "rot_sq_mean_deg2",
        "rot_max_deg",
        "rot_over_5deg",
        "reference_n_triangles",
        "reference_closure_median_m",
        "reference_closure_mean_m",
        "reference_noise_floor_m",
    }
    assert out["n_relations"] == 1172 and out["n_scored"] == 1172
    assert out["trans_abs_mean_m"] == out["trans_abs_mean"] and out["trans_sq_mean_m2"] == out["trans_sq_mean"]
    # the reference's own 54 triangles close to 4.4 cm median: poses without error would score about 2.7 cm
    assert out["reference_n_triangles"] == 54
    assert out["reference_noise_floor_m"] == pytest.approx(0.0265, abs=0.001)
    assert out["trans_abs_mean"] == pytest.approx(1.68, abs=0.01)
    assert out["trans_abs_std"] == pytest.approx(5.29, abs=0.01)
    assert out["rot_abs_mean_deg"] == pytest.approx(5.07, abs=0.01)
    assert out["rot_abs_std_deg"] == pytest.approx(8.25, abs=0.01)


def test_bad_relations_file_names_line(tmp_path, capsys):
    (tmp_path / "r.txt").write_text("1 2 0 0 0 0 0\n")
    with pytest.raises(IoError, match=r"r.txt:1: 7 columns, expected 8"):
        read_relations(tmp_path / "r.txt")
    (tmp_path / "p.txt").write_text("1 0 0 0\n")
    assert main(["eval", "relations", str(tmp_path / "p.txt"), str(tmp_path / "r.txt")]) == 2
    assert "r.txt:1" in capsys.readouterr().err
