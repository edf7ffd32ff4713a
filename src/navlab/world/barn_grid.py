"""BARN's 30 x 30 grid of 0.15 m cells (Perille et al. 2020): the cellular automaton that fills it, the robot's
configuration space on it, BARN's test that a world has a way through, and which filled cells hold a written
cylinder. Pure numpy; field frame as in :mod:`navlab.world.clutter` (columns along x from 0, rows along y centred)."""

from __future__ import annotations

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
