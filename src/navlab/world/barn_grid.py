"""BARN's 30 x 30 grid of 0.15 m cells (Perille et al. 2020): the cellular automaton that fills it, the robot's
configuration space on it, BARN's test that a world has a way through, which filled cells hold a written
cylinder, and the path its generator saves (path_N.npy, BARN's T_opt). Pure numpy; field frame as in
:mod:`navlab.world.clutter` (columns along x from 0, rows along y centred)."""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

CELL = 0.15  # m: BARN's grid cell (one cylinder's diameter)
CELLS = 30  # cells per side of the field (4.5 m)
FIELD = CELL * CELLS  # m
ROBOT_CELLS = 2  # BARN's jackal_radius: cells the robot reaches beyond its centre cell


def field_centres() -> tuple[np.ndarray, np.ndarray]:
    """x of the field's columns and y of its rows (m): cell centres on the 0.15 m grid."""
    c = (np.arange(CELLS) + 0.5) * CELL
    return c, c - FIELD / 2


# ------------------------------------------------------------------------------ cellular automaton
def cellular_automaton(
    rng: np.random.Generator,
    fill: float,
    smooth: int,
    *,
    fill_threshold: int = 5,
    clear_threshold: int = 1,
    count: int | None = None,
) -> np.ndarray:
    """(30, 30) bool field: rows 0 and 29 filled, the others at random with probability ``fill``, then ``smooth``
    rounds of the rule; ``count`` fields at once ((count, 30, 30), the same as ``count`` calls in a row).

    Each round, a cell with >= ``fill_threshold`` filled neighbours (of 8) fills, one with <=
    ``clear_threshold`` clears, the others keep their state (BARN's 5 and 1); beyond the wall rows counts as
    filled, beyond the first and last columns as empty.
    """
    n_fields = 1 if count is None else count
    cells = np.ones((n_fields, CELLS, CELLS), dtype=bool)
    cells[:, 1:-1] = rng.random((n_fields, CELLS - 2, CELLS)) < fill
    for _ in range(smooth):
        padded = np.pad(cells, ((0, 0), (1, 1), (1, 1)), constant_values=False).view(np.uint8)
        padded[:, [0, -1], :] = 1  # beyond the wall rows counts as filled
        n = sum(
            padded[:, 1 + di : CELLS + 1 + di, 1 + dj : CELLS + 1 + dj].astype(np.int8)
            for di in (-1, 0, 1)
            for dj in (-1, 0, 1)
            if di or dj
        )
        cells = (cells | (n >= fill_threshold)) & (n > clear_threshold)
    return cells[0] if count is None else cells


def configuration_space(cells: np.ndarray, robot_cells: int = ROBOT_CELLS) -> np.ndarray:
    """Where the robot's centre may sit (bool, like ``cells``, one field or a stack): no filled cell within
    ``robot_cells`` cells in either direction (a square window, clipped to the field: beyond its ends is open)."""
    k = robot_cells
    padded = np.pad(cells, [(0, 0)] * (cells.ndim - 2) + [(k, k), (k, k)], constant_values=False)
    rows = np.zeros((*padded.shape[:-2], CELLS, padded.shape[-1]), dtype=bool)
    for d in range(2 * k + 1):  # a square window's maximum: along the rows, then along the columns
        rows |= padded[..., d : d + CELLS, :]
    near = np.zeros(cells.shape, dtype=bool)
    for d in range(2 * k + 1):
        near |= rows[..., d : d + CELLS]
    return ~near


def way_through(free: np.ndarray) -> np.ndarray | bool:
    """BARN's test of a world (of each in a stack): the largest 4-connected free region touching the first column
    is the largest one touching the last column."""
    stack = free.reshape(-1, *free.shape[-2:])
    structure = np.zeros((3, 3, 3), dtype=bool)
    structure[1] = ndimage.generate_binary_structure(2, 1)  # 4-connected within a field, never across fields
    labels, _ = ndimage.label(stack, structure=structure)
    ok = np.zeros(len(stack), dtype=bool)
    first, last = labels[:, :, 0], labels[:, :, -1]
    both = np.intersect1d(first[first > 0], last[last > 0])  # labels are unique across the stack
    if not both.size:
        return bool(ok[0]) if free.ndim == 2 else ok
    sizes = np.bincount(labels.ravel())
    for k in np.unique(np.nonzero(np.isin(first, both))[0]):
        ids_first, ids_last = np.unique(first[k][first[k] > 0]), np.unique(last[k][last[k] > 0])
        ok[k] = ids_first[np.argmax(sizes[ids_first])] == ids_last[np.argmax(sizes[ids_last])]
    return bool(ok[0]) if free.ndim == 2 else ok


def written_cylinders(cells: np.ndarray) -> np.ndarray:
    """(k, 2) centres (m) of the cylinders a world holds: its filled cells but those whose 8 neighbours are all
    filled and inside the field (hidden in a block, as BARN writes none there)."""
    full = ndimage.minimum_filter(cells.astype(np.uint8), size=3, mode="constant", cval=0).astype(bool)
    ii, jj = np.nonzero(cells & ~full)
    xc, yc = field_centres()
    return np.c_[xc[jj], yc[ii]]


# ------------------------------------------------------------------------------- BARN's saved path
# BARN's generator (gen_world_ca.py, the dataset's version) saves path_N.npy: an A* path through the Jackal's
# configuration-space cells, which the challenge's run.py turns into T_opt. Its rows run the other way from
# navlab's: BARN's row r lies at Gazebo x = -4.425 + 0.15 r, which is navlab's row 29 - r (navlab's frame is
# Gazebo's turned by -90 degrees, BARN's forward +y being navlab's +x).
INFLATION_CELLS = 2.0  # round(infl_rad 0.3 m / 0.15 m): cells near a c-space wall that cost extra
PENALTY_FACTOR = 5.0  # a step onto a cell d <= INFLATION_CELLS from a c-space wall costs 5 / d more
# run.py's path_coord_to_gazebo_coord puts cell (r, c) at (0.15 r - 4.575, 0.15 c + 5.075), where the world file
# has that cylinder at (0.15 r - 4.425, 0.15 c + 5.175): in navlab's frame, 0.1 m back and one row (+y) aside.
RUNNER_OFFSET = (-0.10, CELL)  # m (x, y) from a cell's centre to where run.py places a path point

_ALL_MOVES = ((0, 1), (1, 1), (1, 0), (1, -1), (0, -1), (-1, -1), (-1, 0), (-1, 1))
_TURNS = {m: tuple(_ALL_MOVES[(k + d) % 8] for d in (-1, 0, 1)) for k, m in enumerate(_ALL_MOVES)}


def wall_distance(blocked: np.ndarray) -> np.ndarray:
    """BARN's ``closest_wall`` on a c-space: Euclidean distance (cells, centre to centre) from each cell to the
    nearest blocked cell (0 on a blocked one)."""
    return ndimage.distance_transform_edt(~blocked)


def barn_astar(
    blocked: np.ndarray, start: tuple[int, int], end: tuple[int, int], dist: np.ndarray
) -> list[tuple[int, int]] | None:
    """BARN's A* from ``start`` to ``end`` (row, col) over the free cells of ``blocked``, or None.

    Its rules, quirks included: 8 moves from the start, then only straight on or a 45 degree turn from the step
    that reached a cell; no diagonal step between two blocked cells; a step costs its length; a cell is closed
    once expanded (by position, whatever its heading). An open cell's key is g + penalty when first reached (no
    heuristic: BARN adds ``child.f``, still 0, where it meant h) and g + h + penalty when a cheaper step
    re-parents it (h: straight-line cells to ``end``); penalty = 5 / d on cells within 2 cells (``dist``) of a
    wall. The cell with the least key is expanded next, the earliest reached on a tie.
    """
    import heapq

    rows, cols = blocked.shape
    g: dict[tuple[int, int], float] = {start: 0.0}
    key: dict[tuple[int, int], float] = {start: 0.0}
    parent: dict[tuple[int, int], tuple[int, int] | None] = {start: None}
    order = {start: 0}
    heap = [(0.0, 0, start)]
    closed: set[tuple[int, int]] = set()
    while heap:
        f, _, cur = heapq.heappop(heap)
        if cur in closed or key[cur] != f:
            continue  # expanded already, or an entry from before a re-parenting
        closed.add(cur)
        if cur == end:
            path = [cur]
            while (p := parent[path[-1]]) is not None:
                path.append(p)
            return path[::-1]
        up = parent[cur]
        moves = _ALL_MOVES if up is None else _TURNS[(cur[0] - up[0], cur[1] - up[1])]
        for dr, dc in moves:
            r, c = cur[0] + dr, cur[1] + dc
            if not (0 <= r < rows and 0 <= c < cols) or blocked[r, c]:
                continue
            if dr and dc and blocked[r, cur[1]] and blocked[cur[0], c]:
                continue
            child = (r, c)
            if child in closed:
                continue
            child_g = g[cur] + math.sqrt(dr * dr + dc * dc)
            d = float(dist[r, c])
            penalty = PENALTY_FACTOR / d if d <= INFLATION_CELLS else 0.0
            if child in order:
                if child_g < g[child]:
                    parent[child], g[child] = cur, child_g
                    key[child] = child_g + math.sqrt((r - end[0]) ** 2 + (c - end[1]) ** 2) + penalty
                    heapq.heappush(heap, (key[child], order[child], child))
            else:
                order[child] = len(order)
                parent[child], g[child], key[child] = cur, child_g, child_g + 0 + penalty
                heapq.heappush(heap, (key[child], order[child], child))
    return None


def _biggest_region_at(labels: np.ndarray, col: int) -> int:
    """Label of BARN's biggest region with a cell in column ``col`` (the first such in row order on a tie)."""
    sizes = np.bincount(labels.ravel())
    best, best_size = 0, 0
    for lab in labels[:, col]:
        if lab and sizes[lab] > best_size:
            best, best_size = int(lab), int(sizes[lab])
    return best


def barn_path(cells: np.ndarray, rng: np.random.Generator, robot_cells: int = ROBOT_CELLS) -> np.ndarray | None:
    """The path BARN's generator would save for ``cells`` (navlab's rows), as navlab (row, col) cells, or None
    (BARN throws such a world away): from a random row of the first column in the biggest region there to a
    random row of the last column in the biggest region there (BARN's draw order: start, then end), by
    :func:`barn_astar` on the configuration space (BARN's rows: navlab's upside down). The start cell comes
    twice, as in BARN's file (its ``get_path`` adds it before the search's own path, which starts with it)."""
    blocked = ~configuration_space(cells[::-1], robot_cells)  # BARN's row order
    labels, _ = ndimage.label(~blocked, structure=ndimage.generate_binary_structure(2, 1))
    first, last = _biggest_region_at(labels, 0), _biggest_region_at(labels, CELLS - 1)
    if not first or first != last:
        return None
    left = np.flatnonzero(labels[:, 0] == first)
    right = np.flatnonzero(labels[:, -1] == last)
    start = (int(left[rng.integers(len(left))]), 0)
    end = (int(right[rng.integers(len(right))]), CELLS - 1)
    path = barn_astar(blocked, start, end, wall_distance(blocked))
    if path is None:
        return None
    rc = np.array([start, *path])
    return np.c_[CELLS - 1 - rc[:, 0], rc[:, 1]]


def barn_path_points(path: np.ndarray, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """(n + 2, 2) points (m, navlab's field frame) of a :func:`barn_path` as the challenge's run.py scores it:
    the start, each cell where run.py places it (``RUNNER_OFFSET`` from its centre), the goal."""
    xc, yc = field_centres()
    pts = np.c_[xc[path[:, 1]] + RUNNER_OFFSET[0], yc[path[:, 0]] + RUNNER_OFFSET[1]]
    return np.vstack([start, pts, goal])


def barn_path_length(path: np.ndarray, start: np.ndarray, goal: np.ndarray) -> float:
    """run.py's path length (m): the sum of the legs of :func:`barn_path_points` (T_opt = length / 2 m/s)."""
    return float(np.linalg.norm(np.diff(barn_path_points(path, start, goal), axis=0), axis=1).sum())
