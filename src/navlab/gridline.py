"""The cells of a straight line between two grid cells (Bresenham), compiled (Numba): the one grid walker of
the SLAM maps' ray casting, the costmap's ray clearing and the local planner's line-of-sight check.

A line from cell (i0, j0) to (i1, j1) has ``steps + 1`` cells, ``steps = max(|i1 - i0|, |j1 - j0|)``: cell
``n`` is ``n`` cells along the major axis and ``round(n * minor / major)`` along the minor one, an
8-connected line (one major step per cell). The two ROS walkers differ only in how they round a tie
(the line passing exactly half-way between two cells), which happens only when ``steps`` is even:

- ``TIE_LATE`` (costmap_2d's ``bresenham2D`` / GMapping's ``GridLineTraversal``): the minor step waits
  (round half down, in cells from the start);
- ``TIE_EARLY`` (base_local_planner's ``LineIterator``, as in TrajectoryPlanner's ``lineCost``): the minor
  step comes first (round half up).

``line(i0, j0, i1, j1, tie)`` sets a line up once; ``line_cell(ln, n)`` is its cell ``n`` (0 = the start,
``steps`` = the end) in closed form, without division (an exact fixed-point one), so no cell waits on
the one before (``line_strides`` + ``line_minor``: the same as a flat index). All are inlined into the
compiled caller.
"""

from __future__ import annotations

import numba

TIE_LATE = 0
TIE_EARLY = 1
_FIXED_BITS = 40
EXACT_STEPS = 4096  # lines up to this many steps use the fixed-point division (exact while x * 2 major < 2**40)

# line(): (steps, i0, j0, major i, major j, minor i, minor j, x0, 2 * minor, 2 * major, mul)
Line = tuple[int, int, int, int, int, int, int, int, int, int, int]


@numba.njit(cache=True, inline="always")
def line(i0: int, j0: int, i1: int, j1: int, tie: int) -> Line:  # pragma: no cover - compiled
    """The line from cell (``i0``, ``j0``) to (``i1``, ``j1``) with the tie rule ``tie`` (``TIE_LATE`` or
    ``TIE_EARLY``), for :func:`line_cell`; its first element is the number of steps (cells - 1)."""
    di, dj = abs(i1 - i0), abs(j1 - j0)
    si = 1 if i1 > i0 else -1
    sj = 1 if j1 > j0 else -1
    if di >= dj:
        dmaj, dmin, mi, mj, ni, nj = di, dj, si, 0, 0, sj
    else:
        dmaj, dmin, mi, mj, ni, nj = dj, di, 0, sj, si, 0
    # cell n is floor((x0 + 2 n dmin) / (2 dmaj)) minor steps from the start: x0 = dmaj - 1 rounds a tie
    # down (the minor step waits), x0 = 2 (dmaj // 2) up (it comes first); they differ only for dmaj even
    x0 = dmaj - 1 if tie == TIE_LATE else 2 * (dmaj // 2)
    mul = ((1 << _FIXED_BITS) + 2 * dmaj - 1) // (2 * dmaj) if 0 < dmaj <= EXACT_STEPS else 0
    return dmaj, i0, j0, mi, mj, ni, nj, x0, 2 * dmin, 2 * dmaj, mul


@numba.njit(cache=True, inline="always")
def line_minor(ln: Line, n: int) -> int:  # pragma: no cover - compiled
    """How many minor-axis steps the line ``ln`` has taken at its cell ``n`` (0 .. steps)."""
    x = ln[7] + n * ln[8]
    mul = ln[10]
    return (x * mul) >> _FIXED_BITS if mul else (x // ln[9] if ln[9] else 0)


@numba.njit(cache=True, inline="always")
def line_cell(ln: Line, n: int) -> tuple[int, int]:  # pragma: no cover - compiled
    """Cell ``n`` (0 .. steps) of the line ``ln`` (from :func:`line`), as (i, j)."""
    q = line_minor(ln, n)
    return ln[1] + n * ln[3] + q * ln[5], ln[2] + n * ln[4] + q * ln[6]


@numba.njit(cache=True, inline="always")
def line_strides(ln: Line, width: int) -> tuple[int, int, int]:  # pragma: no cover - compiled
    """(flat index of the start, flat stride of a major step, of a minor step) of the line ``ln`` in a
    C-contiguous grid ``width`` cells wide: cell ``n`` is at ``start + n * major + line_minor(ln, n) * minor``."""
    return ln[2] * width + ln[1], ln[4] * width + ln[3], ln[6] * width + ln[5]
