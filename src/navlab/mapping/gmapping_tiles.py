"""GMapping's particle maps as copy-on-write tiles (as GMapping's own reference-counted map patches).

A particle's log-odds map is a ``table`` (rows, columns) of tile ids into one ``pool`` (tiles, TILE, TILE)
of float32 cells shared by every particle: cell (j, i) of the map is ``pool[table[j >> SHIFT, i >> SHIFT],
j & MASK, i & MASK]``. Tile 0 is all zeros (unknown) and never written; a particle that writes into a tile
it shares (with another particle, or tile 0) first takes a private copy (``_own``). Resampling copies a
particle's map by copying its small table, so 30 particles descended from one ancestor hold about one map
plus what each changed since. Reference counts are recounted from the tables when particles change.

Lattice conventions as in ``mapping.occupancy``: the map holds the cells of a fixed lattice anchored at
(``ox``, ``oy``) from lattice cell (``oi``, ``oj``) on; cells outside it read as unknown.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from navlab.gridline import TIE_LATE, line, line_cell
from navlab.mapping.occupancy import beam_end

SHIFT = 6
TILE = 1 << SHIFT  # cells per tile side (64 cells: 3.2 m at 5 cm, 16 KiB of float32)
MASK = TILE - 1


class TilePool:
    """The tiles every particle's table points into, with their reference counts (tile 0: all zeros)."""

    def __init__(self, capacity: int = 64) -> None:
        self.tiles = np.zeros((max(capacity, 2), TILE, TILE), dtype=np.float32)
        self.refs = np.zeros(len(self.tiles), dtype=np.int64)
        self.refs[0] = 1 << 40  # never freed, never written

    def recount(self, tables: list[np.ndarray]) -> None:
        """Reference counts from the particles' tables (a tile nobody holds becomes free)."""
        counts = np.bincount(np.concatenate([t.ravel() for t in tables]), minlength=len(self.refs))
        self.refs[:] = counts
        self.refs[0] = 1 << 40

    def free(self, need: int) -> np.ndarray:
        """Ids of at least ``need`` free tiles (the pool grows by at least half when short), lowest first.
        Growing replaces ``tiles`` and ``refs``: read them after this call."""
        ids = np.flatnonzero(self.refs == 0)
        if len(ids) < need:
            old = len(self.tiles)
            cap = max(old + old // 2, old + need - len(ids))
            tiles = np.empty((cap, TILE, TILE), dtype=np.float32)
            tiles[:old] = self.tiles
            self.tiles = tiles
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
                table[tj, ti] = n
                n += 1
    pool.recount([table])
    return pool, table


def to_dense(tiles: np.ndarray, table: np.ndarray) -> np.ndarray:
    """The map a table describes, as one (rows, columns) float32 array."""
    th, tw = table.shape
    out = tiles[table.ravel()].reshape(th, tw, TILE, TILE)
    return np.ascontiguousarray(out.transpose(0, 2, 1, 3)).reshape(th * TILE, tw * TILE)


@numba.njit(cache=True, inline="always")
def cell(tiles: np.ndarray, table: np.ndarray, j: int, i: int) -> float:
    """The map's cell (row ``j``, column ``i``), both inside the table's cells."""
    return tiles[table[j >> SHIFT, i >> SHIFT], j & MASK, i & MASK]


@numba.njit(cache=True, inline="always")
def _own(
    tiles: np.ndarray, table: np.ndarray, refs: np.ndarray, free: np.ndarray, used: np.ndarray, tj: int, ti: int
) -> int:
    """The id of tile (``tj``, ``ti``) of this particle's map after making it private: a shared tile (or
    tile 0) is first copied into the next of the ``free`` tiles (``used[0]`` of them taken so far)."""
    t = table[tj, ti]
    if refs[t] == 1:
        return t
    new = free[used[0]]
    used[0] += 1
    tiles[new] = tiles[t]
    refs[t] -= 1
    refs[new] = 1
    table[tj, ti] = new
    return new


@numba.njit(cache=True)
def raycast_tiles(
    tiles: np.ndarray,
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
    raises its end cell by ``l_occ`` (``update``: (l_occ, l_free, clamp); clamped to ±clamp); cells
    outside the map are skipped. Tiles written are made private first."""
    ox, oy, oi, oj, res = lattice
    px, py, _pt = pose
    ranges, angles, max_urange, max_range = scan
    l_occ, l_free, clamp = update
    th, tw = table.shape
    h, w = th * TILE, tw * TILE
    i0 = math.floor((px - ox) / res) - oi
    j0 = math.floor((py - oy) / res) - oj
    last_tj, last_ti, t = -1, -1, 0  # the tile written last (rays cross few tiles: mostly the same one)
    for k in range(ranges.shape[0]):
        r = ranges[k]
        if not (r > 0.0) or r >= max_range:
            continue
        i1, j1, hit = beam_end(lattice, pose, r, angles[k], max_urange)
        ln = line(i0, j0, i1, j1, TIE_LATE)
        for n in range(ln[0]):  # the end cell excluded
            i, j = line_cell(ln, n)
            if 0 <= i < w and 0 <= j < h:
                tj, ti = j >> SHIFT, i >> SHIFT
                if tj != last_tj or ti != last_ti:
                    t = _own(tiles, table, refs, free, used, tj, ti)
                    last_tj, last_ti = tj, ti
                v = tiles[t, j & MASK, i & MASK] + l_free
                tiles[t, j & MASK, i & MASK] = v if v > -clamp else -clamp
        if hit and 0 <= i1 < w and 0 <= j1 < h:
            tj, ti = j1 >> SHIFT, i1 >> SHIFT
            if tj != last_tj or ti != last_ti:
                t = _own(tiles, table, refs, free, used, tj, ti)
                last_tj, last_ti = tj, ti
            v = tiles[t, j1 & MASK, i1 & MASK] + l_occ
            tiles[t, j1 & MASK, i1 & MASK] = v if v < clamp else clamp
