"""navfn's wave in Dijkstra order (``use_dijkstra: true``) on a bucketed priority queue.

The queue is a ring of key buckets (a Dial queue over the float keys) with an exact binary heap for the current
bucket only, so cells leave it in key order as from one heap; only the order among equal keys differs, which does
not change the potentials (checked bit for bit against the single heap on captured and random plans). A cell whose
key falls is queued again; its older entry is skipped when it surfaces (the cell is settled by then). A settled
cell gives its neighbours keys at most its own plus the dearest cell cost, and the ring spans more than that, so
no entry wraps round. A* order keeps navfn's single heap: there, tie order can change which value a cell settles
with."""

from __future__ import annotations

import math

import numba
import numpy as np

RING = 1024  # buckets in the ring; the width adapts to the cost table so that RING - 4 buckets span one step


@numba.njit(cache=True, inline="always")
def _heap_push(hkey: np.ndarray, hcell: np.ndarray, size: int, key: float, cell: int) -> int:  # pragma: no cover
    """Sift ``(key, cell)`` up from slot ``size``; returns the new size."""
    k = size
    while k > 0:
        up = (k - 1) >> 1
        if hkey[up] <= key:
            break
        hkey[k] = hkey[up]
        hcell[k] = hcell[up]
        k = up
    hkey[k] = key
    hcell[k] = cell
    return size + 1


@numba.njit(cache=True, inline="always")
def _heap_pop(hkey: np.ndarray, hcell: np.ndarray, size: int) -> int:  # pragma: no cover
    """Remove the root (read it first); returns the new size."""
    size -= 1
    key = hkey[size]
    cell = hcell[size]
    k = 0
    while True:
        child = 2 * k + 1
        if child >= size:
            break
        below = hkey[child]
        if child + 1 < size and hkey[child + 1] < below:
            child += 1
            below = hkey[child]
        if key <= below:
            break
        hkey[k] = below
        hcell[k] = hcell[child]
        k = child
    hkey[k] = key
    hcell[k] = cell
    return size


@numba.njit(cache=True)
def propagate(
    data: np.ndarray,
    table: np.ndarray,
    start: int,
    goal: int,
    stop_at_goal: bool,
    margin: float,
) -> tuple[np.ndarray, int]:
    """Fast marching from ``start`` over the costmap costs ``data`` (H, W) uint8, a cell costing ``table[data]``
    (``cell_costs``, inf = obstacle; the start's own cost is never read: it is settled first). Returns the potential
    (exact where settled, an upper bound on the front, inf beyond) and the number of settled cells. With
    ``stop_at_goal`` it stops once the queue's keys pass the goal's by ``margin``, so the goal sits inside
    settled cells and the gradient around it is defined."""
    h, w = data.shape
    n = h * w
    c = data.ravel()
    pot = np.full(n, np.inf)
    done = np.zeros(n, np.bool_)
    # a settled cell's neighbour gets a key <= its key + the dearest cell
    step = 0.0
    for v in table:
        if math.isfinite(v) and v > step:
            step = v
    inv = (RING - 4) / (step + 1.0)  # buckets per unit of key
    cap = 4 * n + 1  # entries ever queued: the start, then at most one per settled cell and side
    hkey = np.empty(cap)
    hcell = np.empty(cap, np.int32)
    lkey = np.empty(cap)  # ring buckets: singly linked lists in one pool
    lcell = np.empty(cap, np.int32)
    lnext = np.empty(cap, np.int32)
    head = np.full(RING, -1, np.int32)
    used = 0
    waiting = 0  # entries in the ring; the heap holds every entry of bucket <= cur, the ring those above
    pot[start] = 0.0
    cur = 0
    size = _heap_push(hkey, hcell, 0, 0.0, start)
    settled = 0
    stop_key = np.inf
    while True:
        if size == 0:
            if waiting == 0:
                break
            cur += 1
            while head[cur % RING] < 0:
                cur += 1
            e = head[cur % RING]
            head[cur % RING] = -1
            while e >= 0:
                size = _heap_push(hkey, hcell, size, lkey[e], lcell[e])
                waiting -= 1
                e = lnext[e]
        key_k = hkey[0]
        if key_k > stop_key:
            break
        k = hcell[0]
        size = _heap_pop(hkey, hcell, size)
        if done[k]:  # an older, larger entry of a cell settled already
            continue
        done[k] = True
        settled += 1
        if stop_at_goal and k == goal:
            stop_key = key_k + margin
        ki = k % w
        kj = k // w
        for d in range(4):
            mi = ki
            mj = kj
            if d == 0:
                mi -= 1
            elif d == 1:
                mi += 1
            elif d == 2:
                mj -= 1
            else:
                mj += 1
            if mi < 0 or mj < 0 or mi >= w or mj >= h:
                continue
            m = mj * w + mi
            if done[m]:
                continue
            hc = table[c[m]]
            if not math.isfinite(hc):
                continue
            ta = np.inf
            if mi > 0 and done[m - 1]:
                ta = pot[m - 1]
            if mi < w - 1 and done[m + 1] and pot[m + 1] < ta:
                ta = pot[m + 1]
            tb = np.inf
            if mj > 0 and done[m - w]:
                tb = pot[m - w]
            if mj < h - 1 and done[m + w] and pot[m + w] < tb:
                tb = pot[m + w]
            if tb < ta:
                ta, tb = tb, ta
            diff = tb - ta
            if diff >= hc:
                new = ta + hc
            else:
                new = 0.5 * (ta + tb + math.sqrt(2.0 * hc * hc - diff * diff))
            if new < pot[m]:
                pot[m] = new
                key = new
                b = int(key * inv)  # monotone in key: a larger bucket never holds a smaller key
                if b <= cur:
                    size = _heap_push(hkey, hcell, size, key, m)
                else:
                    if b - cur >= RING:  # pragma: no cover - excluded by the width above
                        raise ValueError("navfn wave: a key beyond the bucket ring")
                    s = b % RING
                    lkey[used] = key
                    lcell[used] = m
                    lnext[used] = head[s]
                    head[s] = used
                    used += 1
                    waiting += 1
    return pot.reshape(h, w), settled
