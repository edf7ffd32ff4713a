"""CARMEN log reader (``FLASER``, ``ODOM``, ``ROBOTLASER1``), as used by the Kümmerle et al. SLAM benchmark,
and a writer (``write_carmen``: ``ROBOTLASER1`` and ``ODOM`` lines).

Poses are (x m, y m, theta rad) in the log's odometry frame; timestamps are the IPC timestamps (s),
which are the ones relations files refer to. Comment lines (``#``) and message types the reader does
not use are ignored; lines of a used type that are truncated or malformed are skipped and counted
(``CarmenLog.skipped``) with a one-line reason each.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from navlab.geometry import wrap_angle
from navlab.io.errors import IoError

NO_RETURN = 81.9  # SICK "no return" in CARMEN logs (81.91 m); such ranges carry no hit
MAX_READINGS = 100_000  # readings per scan line; more is not a laser scan
MAX_LINE = 4 << 20  # characters per line (a 100,000-reading line has under 1 MiB)
MAX_LASER_RANGE = 1000.0  # m: a reading or max range beyond this is not a laser's (the longest reach ~300 m)
MAX_COORDINATE = 1e6  # m: an odometry coordinate beyond this is not a robot's
OUTLIER_WINDOW = 5  # records each side whose median a pose is compared with
OUTLIER_SPEED = 20.0  # m/s: a pose further from its neighbours' median than this speed allows is an outlier
OUTLIER_SLACK = 10.0  # m: ... plus this much


@dataclass
class LaserScan2D:
    """One laser scan with the odometry of the robot and the laser when it was taken.

    ``ranges`` (m, float32); beam k at ``angle_min + k * angle_increment`` (rad) in the laser frame.
    ``laser_pose`` / ``odom_pose``: (x, y, theta) of the laser / robot in the odometry frame.
    """

    timestamp: float
    ranges: np.ndarray
    angle_min: float
    angle_increment: float
    max_range: float
    laser_pose: tuple[float, float, float]
    odom_pose: tuple[float, float, float]
    kind: str = "FLASER"

    @property
    def laser_offset(self) -> tuple[float, float, float]:
        """Pose of the laser in the robot frame (x, y, theta)."""
        rx, ry, rt = self.odom_pose
        lx, ly, lt = self.laser_pose
        c, s = math.cos(rt), math.sin(rt)
        dx, dy = lx - rx, ly - ry
        dt = wrap_angle(lt - rt)
        return c * dx + s * dy, -s * dx + c * dy, dt


@dataclass
class OdomRecord:
    """An ``ODOM`` line: robot pose (x, y, theta) in the odometry frame, velocities (m/s, rad/s)."""

    timestamp: float
    pose: tuple[float, float, float]
    tv: float
    rv: float


@dataclass
class CarmenLog:
    """The scans and odometry of a CARMEN log, in file order, and what was skipped."""

    path: Path | None
    scans: list[LaserScan2D] = field(default_factory=list)
    odometry: list[OdomRecord] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    ignored_types: dict[str, int] = field(default_factory=dict)
    outlier_poses: int = 0  # records rejected because a pose jumps away from its neighbours (counted in skipped)

    @property
    def duration(self) -> float:
        """Seconds between the first and the last scan."""
        return self.scans[-1].timestamp - self.scans[0].timestamp if len(self.scans) > 1 else 0.0


class _Bad(Exception):
    """A malformed line; the message says why."""


def _floats(tokens: list[str], start: int, count: int, what: str) -> list[float]:
    if len(tokens) < start + count:
        raise _Bad(f"{what}: {len(tokens)} fields, expected at least {start + count}")
    try:
        vals = [float(t) for t in tokens[start : start + count]]
    except ValueError as exc:
        raise _Bad(f"{what}: {exc}") from None
    if not all(math.isfinite(v) for v in vals):
        raise _Bad(f"{what}: non-finite number")
    return vals


def _count(tok: list[str], index: int, what: str) -> int:
    """A count field: a whole number 0..MAX_READINGS."""
    value = _floats(tok, index, 1, what)[0]
    if value != int(value) or not 0 <= value <= MAX_READINGS:
        raise _Bad(f"{what} {tok[index]}: expected a whole number 0..{MAX_READINGS}")
    return int(value)


def _fields(tok: list[str], expected: int, what: str) -> None:
    """A line must have exactly the fields its counts announce (with or without host and logger time)."""
    if len(tok) not in (expected, expected - 2):
        raise _Bad(
            f"{what}: {len(tok)} fields, but its counts make {expected} (a count that disagrees with "
            "its readings would shift every field after them)"
        )


def _laser(ranges: list[float], max_range: float, what: str) -> np.ndarray:
    if not 0.0 < max_range <= MAX_LASER_RANGE:
        raise _Bad(f"{what}: max range {max_range} m, expected 0 < max range <= {MAX_LASER_RANGE:g} m")
    r = np.array(ranges, np.float64)
    if r.size and not np.abs(r).max() <= MAX_LASER_RANGE:
        raise _Bad(f"{what}: a reading of {np.abs(r).max():g} m, beyond any laser's range ({MAX_LASER_RANGE:g} m)")
    return r.astype(np.float32)


def _poses(*poses: tuple[float, float, float], what: str) -> None:
    if any(abs(v) > MAX_COORDINATE for pose in poses for v in pose[:2]):
        raise _Bad(f"{what}: a pose coordinate beyond {MAX_COORDINATE:g} m")


def _parse_flaser(tok: list[str]) -> LaserScan2D:
    n = _count(tok, 1, "FLASER count")
    if n <= 1:
        raise _Bad(f"FLASER with {n} readings")
    _fields(tok, n + 11, f"FLASER with {n} readings")
    ranges = _floats(tok, 2, n, f"FLASER with {n} readings")
    x, y, t, ox, oy, ot, ts = _floats(tok, 2 + n, 7, f"FLASER with {n} readings")
    inc = math.pi / (n - 1) if n % 2 == 1 else math.pi / n  # 361 -> 0.5°, 180 -> 1°
    _poses((x, y, t), (ox, oy, ot), what="FLASER")
    return LaserScan2D(ts, _laser(ranges, NO_RETURN, "FLASER"), -math.pi / 2, inc, NO_RETURN, (x, y, t), (ox, oy, ot))


def _parse_robotlaser1(tok: list[str]) -> LaserScan2D:
    head = _floats(tok, 1, 8, "ROBOTLASER1 header")
    _ltype, start, _fov, res, max_range, _acc, _rmode, n_f = head
    if n_f != int(n_f) or not 1 < n_f <= MAX_READINGS:
        raise _Bad(f"ROBOTLASER1 count {tok[8]}: expected a whole number 2..{MAX_READINGS}")
    n = int(n_f)
    ranges = _floats(tok, 9, n, f"ROBOTLASER1 with {n} readings")
    n_rem = _count(tok, 9 + n, "ROBOTLASER1 remission count")
    _fields(tok, n + n_rem + 24, f"ROBOTLASER1 with {n} readings and {n_rem} remissions")
    base = 10 + n + n_rem
    lx, ly, lt, rx, ry, rt = _floats(tok, base, 6, "ROBOTLASER1 poses")
    ts = _floats(tok, base + 11, 1, "ROBOTLASER1 timestamp")[0]
    _poses((lx, ly, lt), (rx, ry, rt), what="ROBOTLASER1")
    return LaserScan2D(
        ts,
        _laser(ranges, max_range, "ROBOTLASER1"),
        start,
        res,
        max_range,
        (lx, ly, lt),
        (rx, ry, rt),
        kind="ROBOTLASER1",
    )


def _parse_odom(tok: list[str]) -> OdomRecord:
    x, y, t, tv, rv, _acc, ts = _floats(tok, 1, 7, "ODOM")
    _poses((x, y, t), what="ODOM")
    return OdomRecord(ts, (x, y, t), tv, rv)


def read_carmen(path: str | os.PathLike[str], *, max_skipped_report: int = 5) -> CarmenLog:
    """Read a CARMEN log; raise ``IoError`` if it cannot be read or holds no laser scan."""
    p = Path(path)
    try:
        if p.exists() and not p.is_file():
            raise IoError(f"cannot read CARMEN log {p}: not a regular file")
        fh = p.open("r", errors="replace")
    except OSError as exc:
        raise IoError(f"cannot read CARMEN log {p}: {exc.strerror or exc}") from None
    log = CarmenLog(p)
    last = {"scan": -math.inf, "odom": -math.inf}  # the latest timestamp of each stream
    lines: dict[str, list[int]] = {"scan": [], "odom": []}  # each record's line number
    with fh:
        lineno = 0
        while line := fh.readline(MAX_LINE):
            lineno += 1
            if len(line) >= MAX_LINE and not line.endswith("\n"):
                while (rest := fh.readline(MAX_LINE)) and not rest.endswith("\n"):
                    pass  # the rest of an over-long line
                log.skipped.append(f"{p.name}:{lineno}: skipped a line longer than {MAX_LINE} characters")
                continue
            tok = line.split(maxsplit=MAX_READINGS + 64)
            if not tok or tok[0].startswith("#"):
                continue
            kind = tok[0]
            try:
                if kind in ("FLASER", "ROBOTLASER1", "ODOM"):
                    rec: LaserScan2D | OdomRecord
                    rec = (
                        _parse_flaser(tok)
                        if kind == "FLASER"
                        else _parse_robotlaser1(tok)
                        if kind != "ODOM"
                        else _parse_odom(tok)
                    )
                    stream = "odom" if kind == "ODOM" else "scan"
                    if rec.timestamp < last[stream]:
                        raise _Bad(
                            f"timestamp {rec.timestamp} is before the previous {stream} "
                            f"({last[stream]}); timestamps must not go backwards"
                        )
                    last[stream] = rec.timestamp
                    if isinstance(rec, OdomRecord):
                        log.odometry.append(rec)
                        lines["odom"].append(lineno)
                    else:
                        log.scans.append(rec)
                        lines["scan"].append(lineno)
                else:
                    log.ignored_types[kind] = log.ignored_types.get(kind, 0) + 1
            except (_Bad, ValueError) as exc:
                log.skipped.append(f"{p.name}:{lineno}: skipped {kind} line ({exc})")
    log.scans = _without_outliers(
        log, log.scans, [[s.odom_pose for s in log.scans], [s.laser_pose for s in log.scans]], lines["scan"]
    )
    log.odometry = _without_outliers(log, log.odometry, [[o.pose for o in log.odometry]], lines["odom"])
    if not log.scans:
        extra = f"; {len(log.skipped)} malformed lines, first: {log.skipped[0]}" if log.skipped else ""
        raise IoError(f"{p}: no FLASER or ROBOTLASER1 scans found{extra}")
    return log


def running_median(x: np.ndarray, half: int) -> np.ndarray:
    """The median of each element's ``2 half + 1`` window of ``x`` (1-D, at least 2 long), the ends mirrored
    about the end elements (``d c b | a b c d | c b a``): scipy.ndimage's ``median_filter(x, 2 half + 1,
    mode="mirror")`` without importing scipy.ndimage (~0.3 s of ``navlab slam``'s CPU)."""
    padded = np.pad(x, half, mode="reflect")
    return np.median(np.lib.stride_tricks.sliding_window_view(padded, 2 * half + 1), axis=1)


def _without_outliers(
    log: CarmenLog, records: list[Any], poses: list[list[tuple[float, float, float]]], linenos: list[int]
) -> list[Any]:
    """``records`` without those with a pose (one list per pose kind) further from the median of its
    ``OUTLIER_WINDOW`` neighbours each side than ``OUTLIER_SLACK`` + ``OUTLIER_SPEED`` x their time span
    allows (one wild pose would otherwise grow a SLAM map without bound); each rejected record is counted."""
    if len(records) < 3:
        return records
    t = np.array([r.timestamp for r in records], dtype=np.float64)
    idx = np.arange(len(t))
    span = np.maximum(t - t[np.maximum(idx - OUTLIER_WINDOW, 0)], t[np.minimum(idx + OUTLIER_WINDOW, len(t) - 1)] - t)
    dev = np.zeros(len(t))
    for kind in poses:
        xy = np.array([p[:2] for p in kind], dtype=np.float64)
        med = np.stack([running_median(xy[:, k], OUTLIER_WINDOW) for k in range(2)], 1)
        dev = np.maximum(dev, np.hypot(*(xy - med).T))
    bad = dev > OUTLIER_SLACK + OUTLIER_SPEED * span
    name = log.path.name if log.path is not None else "log"
    for k in np.flatnonzero(bad):
        log.skipped.append(f"{name}:{linenos[k]}: rejected an outlier pose, {dev[k]:g} m from its neighbours' median")
    log.outlier_poses += int(bad.sum())
    return [r for r, b in zip(records, bad, strict=True) if not b]


def skipped_summary(log: CarmenLog, limit: int = 3) -> str:
    """A short human message about skipped lines ('' if none)."""
    if not log.skipped:
        return ""
    more = f" (and {len(log.skipped) - limit} more)" if len(log.skipped) > limit else ""
    return f"skipped {len(log.skipped)} malformed line(s): " + "; ".join(log.skipped[:limit]) + more


def write_carmen(path: str | os.PathLike[str], log: CarmenLog, *, comment: str = "") -> Path:
    """Write ``log``'s scans as ``ROBOTLASER1`` lines (exact start angle and beam spacing, laser and robot
    poses) and its odometry as ``ODOM`` lines, in timestamp order, atomically; ``read_carmen`` reads them
    back. Non-finite ranges (no return) are written as ``NO_RETURN``. Returns the path."""
    from navlab.io.files import write_text_atomic

    rows: list[tuple[float, str]] = []
    for s in log.scans:
        n = len(s.ranges)
        r = np.where(np.isfinite(s.ranges), s.ranges, NO_RETURN)
        fov = s.angle_increment * (n - 1)
        lx, ly, lt = s.laser_pose
        rx, ry, rt = s.odom_pose
        rows.append(
            (
                s.timestamp,
                (
                    f"ROBOTLASER1 0 {s.angle_min:.9f} {fov:.9f} {s.angle_increment:.9f} {s.max_range:g} 0.01 0 {n} "
                    + " ".join(f"{v:.3f}" for v in r)
                    + f" 0 {lx:.6f} {ly:.6f} {lt:.6f} {rx:.6f} {ry:.6f} {rt:.6f} 0 0 0 0 0 "
                    f"{s.timestamp:.6f} navlab {s.timestamp:.6f}"
                ),
            )
        )
    for o in log.odometry:
        x, y, t = o.pose
        rows.append(
            (
                o.timestamp,
                f"ODOM {x:.6f} {y:.6f} {t:.6f} {o.tv:.6f} {o.rv:.6f} 0 {o.timestamp:.6f} navlab {o.timestamp:.6f}",
            )
        )
    rows.sort(key=lambda row: row[0])
    head = "".join(f"# {line}\n" for line in comment.splitlines())
    out = Path(path)
    try:
        write_text_atomic(out, head + "".join(line + "\n" for _, line in rows))
    except OSError as exc:
        raise IoError(f"cannot write CARMEN log {out}: {exc.strerror or exc}") from None
    return out
