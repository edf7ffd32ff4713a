"""Test helpers: a route through the synthetic room and drifting odometry along it."""

from __future__ import annotations

import itertools
import math

import numpy as np

from navlab.localization import MapField, Scan
from navlab.localization.synthetic import room_field, simulated_scan

__all__ = ["odometry", "room_field", "route", "scan_at"]


def scan_at(field: MapField, pose: tuple[float, float, float], rng: np.random.Generator) -> Scan:
    """A 360-beam scan with 1 cm noise from the true pose."""
    return simulated_scan(field, pose, rng)


def route(n_steps: int, dt: float = 0.1) -> list[tuple[float, float, float]]:
    """True poses along a loop around the room's middle (0.3 m/s), one per ``dt`` seconds."""
    poses = []
    x, y, th = 1.0, 1.0, 0.0
    waypoints = [(4.8, 1.0), (4.8, 3.4), (3.8, 4.8), (1.0, 4.8), (1.0, 1.0)]
    k = 0
    for _ in range(n_steps):
        tx, ty = waypoints[k % len(waypoints)]
        if math.hypot(tx - x, ty - y) < 0.15:
            k += 1
            tx, ty = waypoints[k % len(waypoints)]
        want = math.atan2(ty - y, tx - x)
        err = (want - th + math.pi) % (2 * math.pi) - math.pi
        w = max(-1.0, min(1.0, 2.0 * err))
        v = 0.3 if abs(err) < 0.5 else 0.05
        th += w * dt
        x += v * dt * math.cos(th)
        y += v * dt * math.sin(th)
        poses.append((x, y, (th + math.pi) % (2 * math.pi) - math.pi))
    return poses


def odometry(
    truth: list[tuple[float, float, float]],
    rng: np.random.Generator,
    start: tuple[float, float, float] = (0.0, 0.0, 0.0),
    teleport_at: int | None = None,
) -> list[tuple[float, float, float]]:
    """Odometry poses (odom frame starting at ``start``) with a 3 % scale error and noisy heading.

    ``teleport_at``: index where the truth jumps (kidnapping); odometry repeats the previous step there.
    """
    out = [start]
    for k, (a, b) in enumerate(itertools.pairwise(truth)):
        if k + 1 == teleport_at:
            a, b = truth[k - 1], truth[k]
        c, s = math.cos(a[2]), math.sin(a[2])
        dx, dy = b[0] - a[0], b[1] - a[1]
        fx, fy = c * dx + s * dy, -s * dx + c * dy
        dth = (b[2] - a[2] + math.pi) % (2 * math.pi) - math.pi
        fx *= 1.03
        dth = dth * 1.02 + rng.normal(0, 0.002)
        ox, oy, oth = out[-1]
        out.append(
            (ox + math.cos(oth) * fx - math.sin(oth) * fy, oy + math.sin(oth) * fx + math.cos(oth) * fy, oth + dth)
        )
    return out
