"""Absolute trajectory error (navlab eval trajectory): alignment, file formats, CLI; eval relations on a CARMEN log."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from navlab.cli import main
from navlab.experiments.trajectory import align_se2, apply_se2, associate, ate, read_trajectory
from navlab.io import IoError
from navlab.io.carmen import CarmenLog, LaserScan2D, OdomRecord, read_carmen, write_carmen
from navlab.io.poses import write_poses
from navlab.mapping import MappingError


def _loop(n: int = 80) -> tuple[np.ndarray, np.ndarray]:
    t = 500.0 + np.arange(n) * 0.5
    th = np.linspace(0, 2 * math.pi, n)
    return t, np.stack([4 * np.cos(th), 2 * np.sin(th), th + math.pi / 2], axis=1)


def test_rigidly_moved_trajectory_has_zero_ate_and_a_bent_one_does_not():
    _, p = _loop()
    moved = apply_se2((3.0, -1.0, 0.8), p)
    out = ate(moved, p)
    assert out["rmse_m"] < 1e-9 and out["max_m"] < 1e-9 and out["share_over_far"] == 0.0
    assert align_se2(moved[:, :2], p[:, :2])[2] == pytest.approx(-0.8)
    # without alignment the offset shows in full
    assert ate(moved, p, align=False)["mean_m"] > 1.0
    # one pose 2 m off: it dominates the max and is the only one counted as far off
    bent = p.copy()
    bent[10, 1] += 2.0
    out = ate(bent, p)
    assert out["max_m"] > 1.5 and out["share_over_far"] == pytest.approx(1 / 80)
    assert out["rmse_m"] == pytest.approx(
        math.sqrt(
            np.mean(np.hypot(*(apply_se2((out["align_x"], out["align_y"], out["align_yaw"]), bent) - p)[:, :2].T) ** 2)
        )
    )
    with pytest.raises(MappingError, match="79 estimated poses but 80"):
        ate(p[1:], p)


def test_association_pairs_nearest_timestamps_once():
    i, j = associate(np.array([1.0, 1.01, 2.0, 5.0]), np.array([0.995, 2.005, 3.0]), tolerance=0.02)
    assert i.tolist() == [0, 2] and j.tolist() == [0, 1]


def test_formats_navlab_tum_quaternion_map_trajectory_and_carmen(tmp_path):
    t, p = _loop(20)
    write_poses(tmp_path / "est.txt", t, p)
    half = p[:, 2] / 2
    rows = [f"{ti} {x} {y} 0 0 0 {math.sin(h)} {math.cos(h)}" for ti, (x, y, _), h in zip(t, p, half, strict=True)]
    (tmp_path / "tum.txt").write_text("# timestamp tx ty tz qx qy qz qw\n" + "\n".join(rows) + "\n")
    tt, pt = read_trajectory(tmp_path / "tum.txt")
    assert np.allclose(tt, t) and np.allclose(pt[:, :2], p[:, :2])
    assert np.allclose(np.cos(pt[:, 2] - p[:, 2]), 1.0)
    both = np.column_stack([t, p + 0.1, p])
    np.savetxt(tmp_path / "trajectory.txt", both, header="t x y theta true_x true_y true_theta")
    assert np.allclose(read_trajectory(tmp_path / "trajectory.txt")[1], p + 0.1)
    assert np.allclose(read_trajectory(tmp_path / "trajectory.txt", columns="truth")[1], p)
    with pytest.raises(IoError, match="true poses need"):
        read_trajectory(tmp_path / "est.txt", columns="truth")
    # a CARMEN log written by navlab reads back: scans' robot and laser poses, ODOM lines
    log = CarmenLog(None)
    for ti, pose in zip(t, p, strict=True):
        r = np.full(181, 3.0, np.float32)
        r[5] = np.inf
        laser = (pose[0] + 0.1, pose[1], pose[2])
        log.scans.append(LaserScan2D(ti, r, -math.pi / 2, math.pi / 180, 25.0, laser, tuple(pose), kind="ROBOTLASER1"))
        log.odometry.append(OdomRecord(ti + 0.01, tuple(pose), 0.3, 0.1))
    write_carmen(tmp_path / "log.clf", log, comment="test log")
    back = read_carmen(tmp_path / "log.clf")
    assert len(back.scans) == 20 and len(back.odometry) == 20 and not back.skipped
    assert back.scans[3].angle_increment == pytest.approx(math.pi / 180) and back.scans[3].ranges[5] > 25.0
    assert np.allclose(read_trajectory(tmp_path / "log.clf")[1], p, atol=1e-5)
    assert np.allclose(read_trajectory(tmp_path / "log.clf", carmen="laser")[1][:, 0], p[:, 0] + 0.1, atol=1e-5)
    assert np.allclose(read_trajectory(tmp_path / "log.clf", carmen="odom")[0], t + 0.01)


def test_cli_eval_trajectory(tmp_path, capsys):
    t, p = _loop()
    write_poses(tmp_path / "truth.txt", t, p)
    est = apply_se2((1.0, 2.0, -0.3), p)
    est[40:, 0] += 0.8  # half the trajectory shifted: a broken map
    write_poses(tmp_path / "est.txt", t + 0.005, est)
    assert main(["eval", "trajectory", str(tmp_path / "est.txt"), str(tmp_path / "truth.txt"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["poses"] == 80 and 0.3 < out["rmse_m"] <= 0.4  # alignment takes a little of the 0.4 m shift out
    assert 0.4 < out["max_m"] < 0.5 and out["share_over_far"] == 0.0
    assert main(["eval", "trajectory", str(tmp_path / "est.txt"), str(tmp_path / "truth.txt"), "--far", "0.3"]) == 0
    assert "poses off by > 0.3 m: 90.0 %" in capsys.readouterr().out
    write_poses(tmp_path / "late.txt", t + 100.0, p)
    assert main(["eval", "trajectory", str(tmp_path / "late.txt"), str(tmp_path / "truth.txt")]) != 0
    assert "within 0.02 s" in capsys.readouterr().err


def test_eval_relations_takes_a_carmen_logs_own_odometry(capsys, dataset):
    data = dataset("mit-csail")
    assert main(["eval", "relations", str(data / "mit-csail.clf"), str(data / "mit-csail.relations"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["n_scored"] == 1172 and out["trans_abs_mean"] == pytest.approx(1.68, abs=0.01)
