"""Dubins curves (Dubins 1957; the six words of Shkel & Lumelsky 2001): the shortest forward path between two
poses for a car with a minimum turning radius, used by the Hybrid-A* planner's analytic expansion.

A path is three segments, each ``L`` (left arc), ``S`` (straight) or ``R`` (right arc), with lengths in
units of the turning radius. Every candidate word is integrated and kept only if it really ends at the goal
(so a degenerate case cannot return a wrong curve). Poses (x m, y m, yaw rad).
"""

from __future__ import annotations

import math

import numpy as np

TWO_PI = 2.0 * math.pi


def _mod(a: float) -> float:
    return a % TWO_PI


def _words(alpha: float, beta: float, d: float) -> list[tuple[str, float, float, float]]:
    """Candidate (word, t, p, q) for the normalised problem: start heading ``alpha``, goal heading ``beta``,
    distance ``d`` (in radii) along +x."""
    sa, sb, ca, cb = math.sin(alpha), math.sin(beta), math.cos(alpha), math.cos(beta)
    cab = math.cos(alpha - beta)
    out: list[tuple[str, float, float, float]] = []
    tmp = 2 + d * d - 2 * cab + 2 * d * (sa - sb)
    if tmp >= 0:
        th = math.atan2(cb - ca, d + sa - sb)
        out.append(("LSL", _mod(-alpha + th), math.sqrt(tmp), _mod(beta - th)))
    tmp = 2 + d * d - 2 * cab + 2 * d * (sb - sa)
    if tmp >= 0:
        th = math.atan2(ca - cb, d - sa + sb)
        out.append(("RSR", _mod(alpha - th), math.sqrt(tmp), _mod(-beta + th)))
    tmp = -2 + d * d + 2 * cab + 2 * d * (sa + sb)
    if tmp >= 0:
        p = math.sqrt(tmp)
        th = math.atan2(-ca - cb, d + sa + sb) - math.atan2(-2.0, p)
        out.append(("LSR", _mod(-alpha + th), p, _mod(-beta + th)))
    tmp = -2 + d * d + 2 * cab - 2 * d * (sa + sb)
    if tmp >= 0:
        p = math.sqrt(tmp)
        th = math.atan2(ca + cb, d - sa - sb) - math.atan2(2.0, p)
        out.append(("RSL", _mod(alpha - th), p, _mod(beta - th)))
    tmp = (6 - d * d + 2 * cab + 2 * d * (sa - sb)) / 8
    if abs(tmp) <= 1:
        p = _mod(TWO_PI - math.acos(tmp))
        t = _mod(alpha - math.atan2(ca - cb, d - sa + sb) + p / 2)
        out.append(("RLR", t, p, _mod(alpha - beta - t + p)))
    tmp = (6 - d * d + 2 * cab + 2 * d * (sb - sa)) / 8
    if abs(tmp) <= 1:
        p = _mod(TWO_PI - math.acos(tmp))
        t = _mod(-alpha - math.atan2(ca - cb, d + sa - sb) + p / 2)
        out.append(("LRL", t, p, _mod(beta - alpha - t + p)))
    return out


def _step(x: float, y: float, th: float, kind: str, length: float, radius: float) -> tuple[float, float, float]:
    """The pose after ``length`` m of segment ``kind`` from (x, y, th)."""
    if kind == "S":
        return x + length * math.cos(th), y + length * math.sin(th), th
    sign = 1.0 if kind == "L" else -1.0
    dth = sign * length / radius
    return (
        x + sign * radius * (math.sin(th + dth) - math.sin(th)),
        y - sign * radius * (math.cos(th + dth) - math.cos(th)),
        th + dth,
    )


def sample(
    start: tuple[float, float, float], word: str, lengths: tuple[float, float, float], radius: float, step: float
) -> np.ndarray:
    """Poses (N, 3) every ``step`` m along a Dubins path (``lengths`` in m), the start excluded, the end included."""
    out = []
    x, y, th = start
    for kind, seg in zip(word, lengths, strict=True):
        n = max(1, math.ceil(seg / step)) if seg > 1e-9 else 0
        for k in range(1, n + 1):
            out.append(_step(x, y, th, kind, seg * k / n, radius))
        if n:
            x, y, th = out[-1]
    return np.array(out, dtype=np.float64).reshape(-1, 3)


def shortest(
    start: tuple[float, float, float], goal: tuple[float, float, float], radius: float
) -> tuple[str, tuple[float, float, float]] | None:
    """The shortest Dubins path from ``start`` to ``goal`` with turning radius ``radius`` m: (word, segment
    lengths in m), or None if no word checks out."""
    dx, dy = goal[0] - start[0], goal[1] - start[1]
    d = math.hypot(dx, dy) / radius
    theta = math.atan2(dy, dx) if d > 1e-12 else 0.0
    alpha, beta = _mod(start[2] - theta), _mod(goal[2] - theta)
    best: tuple[float, str, tuple[float, float, float]] | None = None
    for word, t, p, q in sorted(_words(alpha, beta, d), key=lambda c: c[1] + c[2] + c[3]):
        lengths = (t * radius, p * radius, q * radius)
        end = sample(start, word, lengths, radius, 1e9)
        if len(end) == 0:
            end = np.array([start])
        ex, ey, eth = end[-1]
        if (
            math.hypot(ex - goal[0], ey - goal[1]) < 1e-3 * max(radius, 1.0)
            and abs(math.remainder(eth - goal[2], TWO_PI)) < 1e-3
        ):
            best = (sum(lengths), word, lengths)
            break
    return None if best is None else (best[1], best[2])
