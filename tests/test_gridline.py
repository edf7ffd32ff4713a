"""The one grid walker gives the cells of ROS's two Bresenham walkers: costmap_2d's ``bresenham2D`` /
GMapping's line traversal (a tie waits) and base_local_planner's ``LineIterator`` (a tie steps first),
for every line in a window and for lines longer than the fixed-point division covers."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from navlab.gridline import EXACT_STEPS, TIE_EARLY, TIE_LATE, line, line_cell


@numba.njit(cache=True)
def _cells(i0: int, j0: int, i1: int, j1: int, tie: int) -> np.ndarray:
    ln = line(i0, j0, i1, j1, tie)
    out = np.empty((ln[0] + 1, 2), dtype=np.int64)
    for n in range(ln[0] + 1):
        out[n, 0], out[n, 1] = line_cell(ln, n)
    return out


def _error_term_walk(i0: int, j0: int, i1: int, j1: int) -> list[tuple[int, int]]:
    """The error-term Bresenham (one err, both axes tested each step), start and end cells included."""
    di, dj = abs(i1 - i0), abs(j1 - j0)
    si, sj = (1 if i1 > i0 else -1), (1 if j1 > j0 else -1)
    err, i, j, out = di - dj, i0, j0, [(i0, j0)]
    while (i, j) != (i1, j1):
        e2 = 2 * err
        if e2 > -dj:
            err -= dj
            i += si
        if e2 < di:
            err += di
            j += sj
        out.append((i, j))
    return out


def _line_iterator(x0: int, y0: int, x1: int, y1: int) -> list[tuple[int, int]]:
    """base_local_planner's LineIterator: a numerator starting at half the major delta."""
    dx, dy = abs(x1 - x0), abs(y1 - y0)
    sx, sy = (1 if x1 >= x0 else -1), (1 if y1 >= y0 else -1)
    if dx >= dy:
        xi1, xi2, yi1, yi2, den, num, add, pixels = 0, sx, sy, 0, dx, dx // 2, dy, dx
    else:
        xi1, xi2, yi1, yi2, den, num, add, pixels = sx, 0, 0, sy, dy, dy // 2, dx, dy
    x, y, out = x0, y0, []
    for _ in range(pixels + 1):
        out.append((x, y))
        num += add
        if num >= den:
            num -= den
            x += xi1
            y += yi1
        x += xi2
        y += yi2
    return out


@pytest.mark.parametrize(("tie", "reference"), [(TIE_LATE, _error_term_walk), (TIE_EARLY, _line_iterator)])
def test_every_line_in_a_window_walks_the_ros_cells(tie: int, reference) -> None:
    span = range(-9, 10)
    for i1 in span:
        for j1 in span:
            got = _cells(3, -2, 3 + i1, -2 + j1, tie)
            assert [tuple(c) for c in got] == reference(3, -2, 3 + i1, -2 + j1), (i1, j1)


def test_the_two_tie_rules_differ_only_on_ties() -> None:
    late, early = _cells(0, 0, 4, 1, TIE_LATE), _cells(0, 0, 4, 1, TIE_EARLY)
    assert late[:, 1].tolist() == [0, 0, 0, 1, 1]  # the line crosses y = 0.5 exactly at cell 2: it waits
    assert early[:, 1].tolist() == [0, 0, 1, 1, 1]  # ... or steps first
    assert np.array_equal(_cells(0, 0, 5, 2, TIE_LATE), _cells(0, 0, 5, 2, TIE_EARLY))  # odd: no tie


def test_long_lines_walk_the_same_cells_past_the_fixed_point_range() -> None:
    rng = np.random.default_rng(3)
    for steps in (EXACT_STEPS - 1, EXACT_STEPS, EXACT_STEPS + 1, 3 * EXACT_STEPS + 7):
        for _ in range(3):
            minor = int(rng.integers(0, steps + 1))
            i1, j1 = (steps, -minor) if rng.random() < 0.5 else (-minor, steps)
            assert [tuple(c) for c in _cells(0, 0, i1, j1, TIE_LATE)] == _error_term_walk(0, 0, i1, j1)
            assert [tuple(c) for c in _cells(0, 0, i1, j1, TIE_EARLY)] == _line_iterator(0, 0, i1, j1)
