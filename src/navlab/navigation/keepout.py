"""Keep-out marks for the global planner: the gap where a robot making no progress toward its goal was held up.

A robot can drive in and out of one pocket for minutes when the global plan threads a gap the local controller
will not take (passable on the global costmap, too costly for the footprint). When the progress checker finds
no progress toward the goal, move_base marks the costliest point of the plan just ahead of the robot as a keep-out
disc, lethal to the planner for the rest of the goal, so that the next plan goes another way. Points (m) are in
the global costmap's frame.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from navlab.grid import COST_LETHAL, COST_UNKNOWN

KEEPOUT_RADIUS_M = 0.2  # m: wide enough to close a gap between two of BARN's 0.15 m cylinders
LOOKAHEAD_M = 3.0  # m along the plan from the robot where the hold-up is looked for


def held_up_at(
    plan: np.ndarray | None, costmap: Any, pose: Any, lookahead: float = LOOKAHEAD_M
) -> tuple[float, float] | None:
    """The costliest known point of ``plan`` (N, 2+) within ``lookahead`` m along it from its point nearest
    ``pose``; None without a plan or pose, or when the plan is free there (cost 0: nothing holds the robot up)."""
    if plan is None or not len(plan) or pose is None:
        return None
    pts = np.asarray(plan, dtype=np.float64)[:, :2]
    k0 = int(np.argmin(np.hypot(*(pts - np.asarray(pose[:2])).T)))
    ahead = pts[k0:]
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(ahead, axis=0).T))])
    ahead = ahead[along <= lookahead]
    costs = costmap.value_at(ahead, outside=0).astype(np.int64)
    costs[costs == COST_UNKNOWN] = 0
    if not costs.size or costs.max() <= 0:
        return None
    x, y = ahead[int(np.argmax(costs))]
    return float(x), float(y)


def with_keepouts(costmap: Any, points: list[tuple[float, float]], radius: float = KEEPOUT_RADIUS_M) -> Any:
    """A copy of ``costmap`` with every cell whose centre is within ``radius`` m of one of ``points`` lethal
    (``costmap`` itself without points)."""
    if not points:
        return costmap
    data = costmap.data.copy()
    reach = int(np.ceil(radius / costmap.resolution)) + 1
    for x, y in points:
        ci, cj = costmap.world_to_cell(np.array([[x, y]]))[0]
        ii, jj = np.mgrid[cj - reach : cj + reach + 1, ci - reach : ci + reach + 1]  # rows j, columns i
        cells = np.stack([jj.ravel(), ii.ravel()], axis=1)
        cells = cells[costmap.in_bounds(cells)]
        near = np.hypot(*(costmap.cell_to_world(cells) - (x, y)).T) <= radius
        data[cells[near, 1], cells[near, 0]] = COST_LETHAL
    return dataclasses.replace(costmap, data=data)
