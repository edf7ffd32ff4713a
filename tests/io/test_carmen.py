"""CARMEN log reading: the three laser/odometry line types, comments, truncated lines."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navlab.errors import NavlabError
from navlab.io import IoError
from navlab.io.carmen import read_carmen, skipped_summary


def _flaser(n: int, r: float, pose: tuple[float, float, float], ts: float) -> str:
    x, y, t = pose
    ranges = " ".join([f"{r:.2f}"] * n)
    return f"FLASER {n} {ranges} {x} {y} {t} {x} {y} {t} {ts:.5f} host {ts + 0.01:.5f}\n"


def test_reads_flaser_odom_robotlaser_and_skips_comments(tmp_path):
    rl_ranges = " ".join(["2.0"] * 5)
    text = (
        "# a comment\n"
        "PARAM robot_width 0.5 host 0\n"
        + _flaser(361, 1.5, (1.0, 2.0, 0.5), 100.0)
        + "ODOM 1.1 2.1 0.6 0.3 0.1 0.0 100.1 host 100.11\n"
        + f"ROBOTLASER1 0 -1.5708 3.1416 0.7854 30.0 0.01 0 5 {rl_ranges} 0 "
        "1.3 2.0 0.5 1.0 2.0 0.5 0 0 0 0 0 100.2 host 100.21\n"
    )
    path = tmp_path / "a.clf"
    path.write_text(text)
    log = read_carmen(path)
    assert len(log.scans) == 2 and len(log.odometry) == 1 and not log.skipped
    s = log.scans[0]
    assert s.timestamp == pytest.approx(100.0) and len(s.ranges) == 361
    assert s.angle_min == pytest.approx(-math.pi / 2) and s.angle_increment == pytest.approx(math.radians(0.5))
    assert s.laser_pose == pytest.approx((1.0, 2.0, 0.5))
    assert log.odometry[0].pose == pytest.approx((1.1, 2.1, 0.6)) and log.odometry[0].tv == pytest.approx(0.3)
    r = log.scans[1]
    assert r.kind == "ROBOTLASER1" and r.max_range == pytest.approx(30.0) and len(r.ranges) == 5
    # laser 0.3 m along the odometry frame's x from the robot, whose heading is 0.5 rad
    assert r.laser_offset == pytest.approx((0.3 * math.cos(0.5), -0.3 * math.sin(0.5), 0.0))
    assert log.ignored_types == {"PARAM": 1}


def test_truncated_line_is_skipped_and_counted(tmp_path):
    good = _flaser(361, 1.5, (0, 0, 0), 1.0)
    truncated = good[: len(good) // 2] + "\n"
    path = tmp_path / "t.clf"
    path.write_text(good + truncated + _flaser(361, 1.5, (0, 0, 0), 2.0))
    log = read_carmen(path)
    assert len(log.scans) == 2
    assert len(log.skipped) == 1 and "t.clf:2" in log.skipped[0] and "FLASER" in log.skipped[0]
    assert "skipped 1 malformed line" in skipped_summary(log)


def test_log_without_scans_is_an_error(tmp_path):
    path = tmp_path / "empty.clf"
    path.write_text("# nothing\nODOM 0 0 0 0 0 0 1.0 host 1.0\n")
    with pytest.raises(IoError, match="no FLASER or ROBOTLASER1"):
        read_carmen(path)
    with pytest.raises(NavlabError, match=r"cannot read CARMEN log .*missing\.clf"):  # IoError is a NavlabError
        read_carmen(tmp_path / "missing.clf")


def test_reads_real_log_header(dataset):
    log = read_carmen(dataset("mit-csail/mit-csail.clf"))
    assert len(log.scans) == 1988 and not log.skipped
    assert log.duration == pytest.approx(424.0, abs=0.5)
    assert np.all(np.diff([s.timestamp for s in log.scans]) > 0)


def test_lines_whose_counts_disagree_go_backwards_or_are_huge_are_skipped(tmp_path):
    """Issue 14: a count that disagrees with the readings would shift every field; such lines are skipped."""
    good = [_flaser(181, 2.0, (0.1 * k, 0.0, 0.0), 100.0 + k) for k in range(3)]
    tok = good[1].split()
    tok[1] = str(int(tok[1]) - 1)  # one reading fewer announced than given: x would be read from a range
    shifted = " ".join(tok) + "\n"
    backwards = _flaser(181, 2.0, (0.5, 0.0, 0.0), 50.0)
    huge = "FLASER 200000 " + "1 " * 200_000 + "0 0 0 0 0 0 103.0 host 103.0\n"
    giant = "FLASER 2000000 " + "1.0 " * 2_000_000 + "0 0 0 0 0 0 103.0 host 103.0\n"
    path = tmp_path / "bad.clf"
    path.write_text(good[0] + shifted + good[2] + backwards + huge + giant)
    log = read_carmen(path)
    assert [s.timestamp for s in log.scans] == [100.0, 102.0]
    reasons = " | ".join(log.skipped)
    assert "bad.clf:2" in reasons and "fields, but its counts make" in reasons
    assert "bad.clf:4" in reasons and "backwards" in reasons
    assert "bad.clf:5" in reasons and "200000: expected a whole number" in reasons
    assert "bad.clf:6: skipped a line longer than" in reasons


def test_running_median_matches_scipy_median_filter():
    """The outlier filter's running median is scipy's mirrored median filter (which it replaces)."""
    from scipy.ndimage import median_filter

    from navlab.io.carmen import running_median

    rng = np.random.default_rng(3)
    for n in (3, 4, 6, 11, 12, 200):
        x = np.round(rng.normal(size=n) * 5, 1)  # (ties too)
        assert np.array_equal(running_median(x, 5), median_filter(x, size=11, mode="mirror"))
