"""GMapping's particle maps as copy-on-write tiles (as GMapping's own reference-counted map patches).

A particle's log-odds map is a ``table`` (rows, columns) of tile ids into one ``pool`` (tiles, TILE, TILE)
of float32 cells shared by every particle: cell (j, i) of the map is ``pool[table[j >> SHIFT, i >> SHIFT],
j & MASK, i & MASK]``. Tile 0 is all zeros (unknown) and never written; a particle that writes into a tile
it shares (with another particle, or tile 0) first takes a private copy (``_own``). Resampling copies a
particle's map by copying its small table, so 30 particles descended from one ancestor hold about one map
plus what each changed since. Reference counts are recounted from the tables when particles change.

Beside each tile the pool keeps its occupied-with-free-behind mask (``masks``, uint16, the same id): bit
``NEIGHBOUR_BIT[(dj + 1) * 3 + di + 1]`` of cell (j, i) is set when the cell is occupied (> 0) and its neighbour
(j + dj, i + di) *in the same tile* is free (< 0) — what GMapping's score asks of a match cell and the cell
one step back along the beam — and ``NEAR_OCC`` when some neighbour in the tile is occupied (so a cell that
turns free or stops being free needs no look at its neighbours unless it has that bit). A mask depends on
its own tile only, so it follows the tile's copy-on-write; a neighbour across a tile edge is never marked
(the matcher reads the cells themselves there).

Beside each tile the pool keeps, per cell, GMapping's ``PointAccumulator`` mean of the beam end points that
fell into it (``means``, uint8, the same id): the hits counted (saturating at 255: a running mean then) and
the mean's offset (x, y) in the cell, in 1/256 of a cell (0.2 mm at 5 cm) from its corner; the matcher
measures a beam's end point against that mean, not the cell's centre (GMapping's ``cell.mean()``). A cell no
scan hit has none; cells put in from a dense grid (``from_dense``) count as hit once at their centre.

Lattice conventions as in ``mapping.occupancy``: the map holds the cells of a fixed lattice anchored at
(``ox``, ``oy``) from lattice cell (``oi``, ``oj``) on; cells outside it read as unknown.
"""

from __future__ import annotations

import numba
import numpy as np

from navlab.gridline import TIE_LATE, line, line_cell
from navlab.mapping.occupancy import beam_point, is_return, lattice_cell

SHIFT = 6
TILE = 1 << SHIFT  # cells per tile side (64 cells: 3.2 m at 5 cm, 16 KiB of float32)
MASK = TILE - 1
# the mask bit of each neighbour offset (dj + 1) * 3 + di + 1; the cell itself (4) has none
NEIGHBOUR_BIT = np.array([1, 2, 4, 8, 0, 16, 32, 64, 128], dtype=np.uint16)
NEAR_OCC = 256  # the mask bit of a cell with an occupied neighbour in its tile
MEAN_UNIT = 1.0 / 256.0  # a mean offset's unit, in cells
CENTRE = 128  # the mean offset of a cell's centre


class TilePool:
    """The tiles every particle's table points into, with their reference counts (tile 0: all zeros)."""

    def __init__(self, capacity: int = 64) -> None:
        self.tiles = np.zeros((max(capacity, 2), TILE, TILE), dtype=np.float32)
        self.masks = np.zeros(self.tiles.shape, dtype=np.uint16)  # each tile's mask (module docstring)
        self.means = np.zeros((*self.tiles.shape, 3), dtype=np.uint8)  # hits, mean x, y offset (docstring)
        self.refs = np.zeros(len(self.tiles), dtype=np.int64)
        self.refs[0] = 1 << 40  # never freed, never written

    def recount(self, tables: list[np.ndarray]) -> None:
        """Reference counts from the particles' tables (a tile nobody holds becomes free)."""
        counts = np.bincount(np.concatenate([t.ravel() for t in tables]), minlength=len(self.refs))
        self.refs[:] = counts
        self.refs[0] = 1 << 40

    def free(self, need: int) -> np.ndarray:
        """Ids of at least ``need`` free tiles (the pool grows by at least half when short), lowest first.
        Growing replaces ``tiles``, ``masks``, ``means`` and ``refs``: read them after this call."""
        ids = np.flatnonzero(self.refs == 0)
        if len(ids) < need:
            old = len(self.tiles)
            cap = max(old + old // 2, old + need - len(ids))
            tiles = np.empty((cap, TILE, TILE), dtype=np.float32)
            tiles[:old] = self.tiles
            self.tiles = tiles
            masks = np.empty(tiles.shape, dtype=np.uint16)
            masks[:old] = self.masks
            self.masks = masks
            means = np.empty((*tiles.shape, 3), dtype=np.uint8)
            means[:old] = self.means
            self.means = means
            self.refs = np.concatenate([self.refs, np.zeros(cap - old, dtype=np.int64)])
            ids = np.flatnonzero(self.refs == 0)
        return ids

    def in_use(self) -> int:
        """Tiles held by some particle (tile 0 not counted)."""
        return int(np.count_nonzero(self.refs[1:]))


def tiles_for(shape: tuple[int, int]) -> tuple[int, int]:
    """(rows, columns) of tiles covering a map of ``shape`` (rows, columns) cells."""
    return -(-shape[0] // TILE), -(-shape[1] // TILE)


def from_dense(grid: np.ndarray) -> tuple[TilePool, np.ndarray]:
    """A pool and table holding ``grid`` (rows, columns; padded with zeros to whole tiles)."""
    th, tw = tiles_for(grid.shape)
    pool = TilePool(th * tw + 1)
    table = np.zeros((th, tw), dtype=np.int64)
    padded = np.zeros((th * TILE, tw * TILE), dtype=np.float32)
    padded[: grid.shape[0], : grid.shape[1]] = grid
    n = 1
    for tj in range(th):
        for ti in range(tw):
            block = padded[tj * TILE : (tj + 1) * TILE, ti * TILE : (ti + 1) * TILE]
            if block.any():
                pool.tiles[n] = block
                mask_tile(pool.tiles[n], pool.masks[n])
                pool.means[n][block > 0] = (1, CENTRE, CENTRE)
                table[tj, ti] = n
                n += 1
    pool.recount([table])
    return pool, table


def to_dense(tiles: np.ndarray, table: np.ndarray) -> np.ndarray:
    """The map a table describes, as one (rows, columns, ...) array (``tiles``: the pool's ``tiles``, ``masks``
    or ``means``)."""
    th, tw = table.shape
    rest = tiles.shape[3:]
    out = tiles[table.ravel()].reshape(th, tw, TILE, TILE, *rest)
    return np.ascontiguousarray(np.swapaxes(out, 1, 2)).reshape(th * TILE, tw * TILE, *rest)


@numba.njit(cache=True, inline="always")
def cell(tiles: np.ndarray, table: np.ndarray, j: int, i: int) -> float:
    """The map's cell (row ``j``, column ``i``), both inside the table's cells."""
    return tiles[table[j >> SHIFT, i >> SHIFT], j & MASK, i & MASK]


@numba.njit(cache=True, inline="always")
def _cell_mask(tiles: np.ndarray, t: int, j: int, i: int) -> int:
    """The mask word of cell (``j``, ``i``) of tile ``t`` (tile coordinates), from its in-tile neighbours."""
    v = tiles[t, j, i]
    m = 0
    for dj in range(-1, 2):
        for di in range(-1, 2):
            jj, ii = j + dj, i + di
            if (dj == 0 and di == 0) or not (0 <= jj < TILE and 0 <= ii < TILE):
                continue
            u = tiles[t, jj, ii]
            if v > 0.0 and u < 0.0:
                m |= NEIGHBOUR_BIT[(dj + 1) * 3 + di + 1]
            if u > 0.0:
                m |= NEAR_OCC
    return m


@numba.njit(cache=True)
def mask_tile(tile: np.ndarray, mask: np.ndarray) -> None:
    """``mask`` (TILE, TILE) worked out from scratch for ``tile`` (module docstring)."""
    tiles, masks = tile.reshape(1, TILE, TILE), mask.reshape(1, TILE, TILE)
    for j in range(TILE):
        for i in range(TILE):
            masks[0, j, i] = _cell_mask(tiles, 0, j, i)


@numba.njit(cache=True, inline="always")
def _remask(tiles: np.ndarray, masks: np.ndarray, t: int, j: int, i: int) -> None:
    """Mend tile ``t``'s mask after its cell (``j``, ``i``) became or stopped being occupied: the cell's own
    word and its in-tile neighbours' (rare: at beam end cells)."""
    for jj in range(max(j - 1, 0), min(j + 2, TILE)):
        for ii in range(max(i - 1, 0), min(i + 2, TILE)):
            masks[t, jj, ii] = _cell_mask(tiles, t, jj, ii)


@numba.njit(cache=True, inline="always")
def _refree(tiles: np.ndarray, masks: np.ndarray, t: int, j: int, i: int) -> None:
    """Mend tile ``t``'s mask after its cell (``j``, ``i``), beside an occupied cell, became or stopped being
    free: the occupied neighbours' bits that point at it."""
    free = tiles[t, j, i] < 0.0
    for dj in range(-1, 2):
        for di in range(-1, 2):
            jj, ii = j + dj, i + di
            if (dj == 0 and di == 0) or not (0 <= jj < TILE and 0 <= ii < TILE) or not tiles[t, jj, ii] > 0.0:
                continue
            back = NEIGHBOUR_BIT[(1 - dj) * 3 + 1 - di]  # the neighbour's bit pointing at this cell
            if free:
                masks[t, jj, ii] |= back
            else:
                masks[t, jj, ii] &= ~back


@numba.njit(cache=True, inline="always")
def _set(tiles: np.ndarray, masks: np.ndarray, t: int, j: int, i: int, add: float, clamp: float) -> None:
    """Cell (``j``, ``i``) of tile ``t`` (tile coordinates) changed by ``add``, clamped to ±``clamp``, its
    tile's mask mended where the cell's change between occupied, free and unknown shows. Only a cell that
    was not already on the side ``add`` moves it to can change (a test the ray's many free cells pass
    cheaply)."""
    old = tiles[t, j, i]
    v = old + add
    tiles[t, j, i] = min(max(v, -clamp), clamp)
    if (old >= 0.0) if add < 0.0 else (old <= 0.0):
        new = tiles[t, j, i]  # (as stored: float32)
        if (old > 0.0) != (new > 0.0):
            _remask(tiles, masks, t, j, i)
        elif (old < 0.0) != (new < 0.0) and masks[t, j, i] & NEAR_OCC:
            _refree(tiles, masks, t, j, i)


@numba.njit(cache=True, inline="always")
def _add_hit(mean: np.ndarray, fx: float, fy: float) -> None:
    """Count one more hit in a cell's ``mean`` (hits, x, y offset: ``means[t, j, i]``) at (``fx``, ``fy``) (in
    cells from its corner, in [0, 1)): the running mean of its hits (the count saturates at 255)."""
    n = min(int(mean[0]) + 1, 255)
    mean[0] = n
    for c, f in ((1, fx), (2, fy)):
        m = mean[c] * MEAN_UNIT
        mean[c] = min(max(round((m + (f - m) / n) * 256.0), 0), 255)


@numba.njit(cache=True, inline="always")
def _own(
    tiles: np.ndarray,
    masks: np.ndarray,
    means: np.ndarray,
    table: np.ndarray,
    refs: np.ndarray,
    free: np.ndarray,
    used: np.ndarray,
    tj: int,
    ti: int,
) -> int:
    """The id of tile (``tj``, ``ti``) of this particle's map after making it private: a shared tile (or
    tile 0) is first copied, with its mask and means, into the next of the ``free`` tiles (``used[0]`` of them taken so
    far)."""
    t = table[tj, ti]
    if refs[t] == 1:
        return t
    new = free[used[0]]
    used[0] += 1
    tiles[new] = tiles[t]
    masks[new] = masks[t]
    means[new] = means[t]
    refs[t] -= 1
    refs[new] = 1
    table[tj, ti] = new
    return new


@numba.njit(cache=True)
def raycast_tiles(
    tiles: np.ndarray,
    masks: np.ndarray,
    means: np.ndarray,
    table: np.ndarray,
    refs: np.ndarray,
    free: np.ndarray,
    used: np.ndarray,
    lattice: tuple[float, float, int, int, float],
    pose: tuple[float, float, float],
    scan: tuple[np.ndarray, np.ndarray, float, float],
    update: tuple[float, float, float],
) -> None:
    """``occupancy._raycast`` into a tiled map (the same cells, the same values, in the same order), for the
    laser at ``pose`` (x, y, theta) on ``lattice`` (anchor x, y, offset column, row, cell size): every beam
    of ``scan`` (ranges, angles, max_urange, max_range) with a range in (0, max_range) lowers the log-odds
    of the cells it crosses (Bresenham, end cell excluded) by ``l_free`` and, if shorter than max_urange,
    raises its end cell by ``l_occ`` (``update``: (l_occ, l_free, clamp); clamped to ±clamp) and adds the end
    point to its cell's mean; cells outside the map are skipped. Tiles written are made private first; their
    ``masks`` follow the cells. A ray's cells already at -clamp are only read: they would stay as they are,
    so a tile the scan crosses only there stays shared (not copied for nothing)."""
    ranges, angles, max_urange, max_range = scan
    l_occ, l_free, clamp = update
    th, tw = table.shape
    h, w = th * TILE, tw * TILE
    flat = tiles.reshape(-1)  # a view (C-contiguous)
    i0, j0 = lattice_cell(lattice, pose[0], pose[1])
    last_tj, last_ti, t, mine = -1, -1, 0, False  # the tile read last (rays cross few tiles), whether it is private
    for k in range(ranges.shape[0]):
        if not is_return(ranges[k], max_range):
            continue
        ex, ey, hit = beam_point(pose, ranges[k], angles[k], max_urange)
        i1, j1 = lattice_cell(lattice, ex, ey)
        ln = line(i0, j0, i1, j1, TIE_LATE)
        for n in range(ln[0]):  # the end cell excluded
            i, j = line_cell(ln, n)
            if 0 <= i < w and 0 <= j < h:
                tj, ti = j >> SHIFT, i >> SHIFT
                if tj != last_tj or ti != last_ti:
                    last_tj, last_ti = tj, ti
                    t = table[tj, ti]
                    mine = refs[t] == 1
                e = numba.uint64(((t << SHIFT) + (j & MASK)) << SHIFT) + numba.uint64(i & MASK)
                if flat[e] <= -clamp:  # at the clamp already (most cells): it stays, and its tile is not copied
                    continue
                if not mine:
                    t = _own(tiles, masks, means, table, refs, free, used, tj, ti)
                    mine = True
                _set(tiles, masks, t, j & MASK, i & MASK, l_free, clamp)
        if hit and 0 <= i1 < w and 0 <= j1 < h:
            tj, ti = j1 >> SHIFT, i1 >> SHIFT
            if tj != last_tj or ti != last_ti or not mine:
                t = _own(tiles, masks, means, table, refs, free, used, tj, ti)
                last_tj, last_ti, mine = tj, ti, True
            _set(tiles, masks, t, j1 & MASK, i1 & MASK, l_occ, clamp)
            _add_hit(
                means[t, j1 & MASK, i1 & MASK],
                (ex - lattice[0]) / lattice[4] - (i1 + lattice[2]),
                (ey - lattice[1]) / lattice[4] - (j1 + lattice[3]),
            )
