"""Ceilings on the parameters that size work or memory: one table, one check, one error line.

A parameter file may ask for anything its format can spell; a costmap of 10^14 cells, a rollout of
10^12 poses or a timer at 10^9 Hz would exhaust the machine's memory or never end. Each ceiling below is
far above any configuration a ROS user runs (the ROS defaults are in parentheses) and below what the
machine can hold: memory ceilings are computed from its physical memory (one structure may take at most
a quarter of it). The error names the key, the value and the product that is too big.

=======================  ==========================================================  ======================
ceiling                  what it bounds                                              limit
=======================  ==========================================================  ======================
``rate``                 any frequency: costmap update/publish, controller, planner  1,000 Hz (5-20 Hz)
``grid_cells``           cells of one costmap (width x height / resolution²)         memory / 4 / 16 B
``rollout_poses``        poses simulated per control cycle: DWA/TrajectoryPlanner    memory / 4 / 256 B,
                         samples x steps, MPPI batch_size x time_steps x iterations  at most 50,000,000
``footprint_m``          a footprint point's distance from the robot's centre        100 m
``polygon_points``       points of a footprint polygon                               1,000
``particles``            AMCL max_particles, gmapping particles                      1,000,000 (5,000 / 30)
``lidar_samples``        a ray sensor's horizontal <samples>                         100,000
``coordinate_m``         a start pose, goal or spawned model's coordinate            1,000,000 m
``model_m``              a spawned model's size (box edge, radius, length)           10,000 m
``slam_particle_cells``  gmapping particles x map cells (each particle has a map)    memory / 4 / 4 B
=======================  ==========================================================  ======================
"""

from __future__ import annotations

from dataclasses import dataclass

from navlab.errors import NavlabError
from navlab.io import machine_memory_bytes

MEMORY_SHARE = 4  # one structure may take at most 1/MEMORY_SHARE of the machine's physical memory


@dataclass(frozen=True)
class Ceiling:
    """The largest value a sized quantity may take, its unit and why."""

    limit: float
    unit: str
    why: str


def _memory(bytes_per_item: int, cap: float = float("inf")) -> float:
    return float(min(machine_memory_bytes() // MEMORY_SHARE // bytes_per_item, cap))


def ceilings() -> dict[str, Ceiling]:
    """The table of ceilings (memory ceilings from this machine's memory)."""
    memory = f"a quarter of this machine's {machine_memory_bytes() / 2**30:.1f} GiB"
    return {
        "rate": Ceiling(1000.0, "Hz", "a timer faster than 1 kHz of simulated time only burns CPU"),
        "grid_cells": Ceiling(_memory(16), "cells", f"the layers of a grid must fit in {memory}"),
        "rollout_poses": Ceiling(
            _memory(256, 5e7),
            "poses per cycle",
            f"every pose of one control cycle is held in {memory} and scored in time",
        ),
        "footprint_m": Ceiling(100.0, "m", "a footprint reaching further than 100 m is not a robot"),
        "polygon_points": Ceiling(1000.0, "points", "a footprint is a polygon of a few points"),
        "particles": Ceiling(1e6, "particles", "each particle is updated on every scan"),
        "lidar_samples": Ceiling(1e5, "samples", "a planar lidar has at most a few thousand beams"),
        "coordinate_m": Ceiling(1e6, "m", "start poses, goals and spawned models further out lose all precision"),
        "model_m": Ceiling(1e4, "m", "a model larger than 10 km is not an obstacle"),
        "slam_particle_cells": Ceiling(_memory(4), "cells", f"every particle's map must fit in {memory}"),
    }


def check_ceiling(error: type[NavlabError], what: str, key: str, value: float, ceiling: str) -> None:
    """Raise ``error`` naming ``what``'s parameter ``key`` (or the product of parameters it names) if ``value``
    exceeds the ``ceiling`` of the table."""
    c = ceilings()[ceiling]
    if not value <= c.limit:  # NaN fails too
        amount = f"{value:,.0f} {c.unit}" if abs(value) >= 1e4 else f"{value:g} {c.unit}"
        raise error(f"{what} parameter {key}: {amount}, more than the ceiling of {c.limit:,.0f} {c.unit} ({c.why})")
