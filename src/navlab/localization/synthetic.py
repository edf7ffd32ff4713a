"""A synthetic world for trying AMCL without the simulator: a grid room and a ray-cast laser.

Used by the benchmark, the tests and the example. Poses are in the map frame (m, rad).
"""

from __future__ import annotations

import math

import numpy as np

from navlab.localization.amcl import Scan
from navlab.localization.field import MapField, build_field
from navlab.localization.raycast import cast_rays


def room_grid(resolution: float = 0.05) -> np.ndarray:
    """An 8 m × 6 m room (0.1 m walls, lower-left inner corner at (0, 0) when the origin is (-0.2, -0.2))
    with three boxes placed so that no symmetry remains; int8 occupancy, row 0 = lowest y."""
    h, w = round(6.4 / resolution), round(8.4 / resolution)
    g = np.zeros((h, w), dtype=np.int8)
    wall = round(0.3 / resolution)
    g[:wall, :] = 100
    g[-wall:, :] = 100
    g[:, :wall] = 100
    g[:, -wall:] = 100

    def box(x0: float, y0: float, x1: float, y1: float) -> None:
        # (x, y) in the room frame, i.e. 0.2 m from the grid corner
        g[
            round((y0 + 0.2) / resolution) : round((y1 + 0.2) / resolution),
            round((x0 + 0.2) / resolution) : round((x1 + 0.2) / resolution),
        ] = 100

    box(1.8, 1.8, 2.6, 2.4)
    box(5.3, 3.8, 5.8, 5.4)
    box(6.0, 0.2, 6.8, 1.2)
    g[: round(0.2 / resolution), :] = -1  # unknown space beyond the bottom wall
    return g


def room_field(resolution: float = 0.05, max_dist: float = 2.0) -> MapField:
    """``room_grid`` as a ``MapField`` with origin (-0.2, -0.2, 0): free space spans about x 0.1..7.9, y 0.1..5.9."""
    return build_field(room_grid(resolution), resolution, (-0.2, -0.2, 0.0), max_dist=max_dist)


def simulated_scan(
    field: MapField,
    pose: tuple[float, float, float],
    rng: np.random.Generator,
    *,
    n_beams: int = 360,
    range_max: float = 8.0,
    noise: float = 0.01,
) -> Scan:
    """A full-circle scan from ``pose`` (the laser at the robot origin): ray-cast ranges plus Gaussian
    noise (std ``noise`` m); beams that hit nothing within ``range_max`` read ``inf`` (as Gazebo's)."""
    inc = 2 * math.pi / n_beams
    bearings = -math.pi + np.arange(n_beams) * inc
    g = field.to_grid(np.array([pose], dtype=np.float64))
    r = cast_rays(field.occupied, field.resolution, g, bearings, range_max)[0]
    r = r + rng.normal(0.0, noise, r.shape)
    r[r >= range_max] = np.inf
    return Scan(ranges=r, angle_min=-math.pi, angle_increment=inc, range_min=0.1, range_max=range_max)
