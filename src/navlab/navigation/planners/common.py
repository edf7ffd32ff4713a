"""What the global planners share: costmap and pose checks, a binary heap for Numba, path helpers.

Cell coordinates: cell ``(i, j)`` is ``data[j, i]``; "centre coordinates" ``u = (x - origin_x) / res - 0.5``
put cell centres on integers. Paths are float (N, 2) arrays in metres in the costmap's frame.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numba
import numpy as np

from navlab.core import read_params
from navlab.grid import COST_LETHAL, Grid
from navlab.navigation.errors import NavigationError
from navlab.plugins import BuiltFromParams


def check_costmap(costmap: Grid, who: str) -> np.ndarray:
    """The costmap's uint8 cost array; refuses other dtypes, empty grids and a rotated origin."""
    data = np.asarray(costmap.data)
    if data.dtype != np.uint8 or data.ndim != 2 or data.size == 0:
        raise NavigationError(
            f"{who}: costmap must be a 2-D uint8 grid of costmap_2d costs, got {data.dtype} {data.shape}"
        )
    if costmap.origin[2] != 0.0:
        raise NavigationError(f"{who}: costmap origin yaw must be 0, got {costmap.origin[2]}")
    return data


def pose_cell(costmap: Grid, pose: Any, what: str, who: str) -> tuple[int, int, float, float]:
    """(i, j, u, v) of ``pose`` (x, y[, yaw]): its cell and centre coordinates; outside the map is an error."""
    try:
        x, y = float(pose[0]), float(pose[1])
    except (TypeError, ValueError, IndexError):
        raise NavigationError(f"{who}: {what} must be (x, y, yaw) in metres, got {pose!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise NavigationError(f"{who}: {what} must be finite, got ({x}, {y})")
    ij = costmap.world_to_cell(np.array([[x, y]]))
    if not costmap.in_bounds(ij)[0]:
        xmin, ymin, xmax, ymax = costmap.bounds()
        raise NavigationError(
            f"{who}: {what} ({x:.3f}, {y:.3f}) is outside the costmap "
            f"[{xmin:.2f}, {xmax:.2f}] x [{ymin:.2f}, {ymax:.2f}] m ({costmap.frame_id} frame)"
        )
    res = costmap.resolution
    u = (x - costmap.origin[0]) / res - 0.5
    v = (y - costmap.origin[1]) / res - 0.5
    return int(ij[0, 0]), int(ij[0, 1]), u, v


def check_start(data: np.ndarray, i: int, j: int, start: Any, who: str) -> None:
    """A start on a lethal cell is an error (the robot's centre cannot be in an obstacle); an inscribed start
    is fine (the planner clears the robot's cell, as navfn's ``clearRobotCell`` does)."""
    if data[j, i] == COST_LETHAL:
        raise NavigationError(
            f"{who}: start ({float(start[0]):.3f}, {float(start[1]):.3f}) is in an obstacle "
            f"(cost {COST_LETHAL} at cell ({i}, {j})); is the robot localized?"
        )


def check_request(
    costmap: Grid, start: Any, goal: Any, who: str
) -> tuple[np.ndarray, tuple[int, int, float, float], tuple[int, int, float, float]]:
    """The costmap's cost array and the start's and goal's (i, j, u, v) (:func:`pose_cell`), checked as navfn checks
    a request: the costmap (:func:`check_costmap`), both poses on it, the start not in an obstacle."""
    data = check_costmap(costmap, who)
    s = pose_cell(costmap, start, "start", who)
    g = pose_cell(costmap, goal, "goal", who)
    check_start(data, s[0], s[1], start, who)
    return data, s, g


class GridPlanner(BuiltFromParams):
    """What the grid planners share: their parameters (``params_class``, from a ROS parameter dict or an instance),
    ``last_failure`` (why the last call found no path, "" on success) and ``stats`` (the last search's counts)."""

    params_class: ClassVar[type[Any]]
    name = ""

    def __init__(self, params: Any = None) -> None:
        self.params = read_params(self.params_class, params)
        self.last_failure = ""
        self.stats: dict[str, int] = {}


def path_length(path: np.ndarray | None) -> float:
    """Length (m) of a polyline (N, 2); 0 for None or a single point."""
    if path is None or len(path) < 2:
        return 0.0
    return float(np.hypot(*np.diff(np.asarray(path)[:, :2], axis=0).T).sum())


def to_world(costmap: Grid, uv: np.ndarray) -> np.ndarray:
    """Metres (N, 2) of centre coordinates ``uv`` (N, 2)."""
    res = costmap.resolution
    return np.stack([costmap.origin[0] + (uv[:, 0] + 0.5) * res, costmap.origin[1] + (uv[:, 1] + 0.5) * res], axis=1)


def dedupe(path: np.ndarray, eps: float = 1e-9) -> np.ndarray:
    """``path`` without consecutive repeated points."""
    if len(path) < 2:
        return path
    keep = np.ones(len(path), bool)
    keep[1:] = np.hypot(*np.diff(path, axis=0).T) > eps
    return path[keep]


# --- an indexed binary min-heap (one entry per cell, decrease-key) ---------------------------------


@numba.njit(cache=True, inline="always")
def _put(keys: np.ndarray, vals: np.ndarray, pos: np.ndarray, k: int, key: float, val: int) -> None:  # pragma: no cover
    """Entry ``val`` with ``key`` at heap slot ``k`` (its ``pos`` follows)."""
    keys[k] = key
    vals[k] = val
    pos[val] = k


@numba.njit(cache=True, inline="always")
def _sift_up(keys: np.ndarray, vals: np.ndarray, pos: np.ndarray, k: int, key: float, val: int) -> None:
    """Put entry ``val`` with ``key`` at slot ``k`` or above, moving larger parents down (each slot written once)."""
    while k > 0:
        parent = (k - 1) >> 1
        above = keys[parent]
        if above <= key:
            break
        _put(keys, vals, pos, k, above, vals[parent])
        k = parent
    _put(keys, vals, pos, k, key, val)


@numba.njit(cache=True, inline="always")
def iheap_update(keys: np.ndarray, vals: np.ndarray, pos: np.ndarray, size: int, key: float, val: int) -> int:
    """Insert ``val`` with ``key``, or lower its key if it is queued (``pos[val]`` >= 0); returns the new size.
    ``pos`` (one int per cell) starts at -1; ``keys``/``vals`` hold at most one entry per cell."""
    k = pos[val]
    if k < 0:
        k = size
        size += 1
    elif keys[k] <= key:
        return size
    _sift_up(keys, vals, pos, k, key, val)
    return size


@numba.njit(cache=True, inline="always")
def iheap_pop(keys: np.ndarray, vals: np.ndarray, pos: np.ndarray, size: int) -> int:
    """Remove the root (read ``keys[0]``, ``vals[0]`` first; its ``pos`` becomes -2); returns the new size."""
    pos[vals[0]] = -2
    size -= 1
    if size == 0:
        return 0
    key = keys[size]
    val = vals[size]
    k = 0
    while True:
        left = 2 * k + 1
        if left >= size:
            break
        child = left
        below = keys[left]
        if left + 1 < size and keys[left + 1] < below:
            child = left + 1
            below = keys[child]
        if key <= below:
            break
        _put(keys, vals, pos, k, below, vals[child])
        k = child
    _put(keys, vals, pos, k, key, val)
    return size
