"""Resampling, KLD-sampling and particle clustering for AMCL.

KLD-sampling (Fox 2003; ROS amcl ``pf_resample_limit``): particles are histogrammed into bins of
0.5 m × 0.5 m × 10°; after drawing c samples that occupy k bins, drawing stops once
``c > (k-1)/(2 kld_err) * (1 - 2/(9(k-1)) + sqrt(2/(9(k-1))) * kld_z)**3`` (clamped to
[min_particles, max_particles]). As in ROS, ``kld_z`` is used directly as the normal quantile.

Clustering (ROS ``pf_cluster_stats``): occupied bins that touch (26-neighbourhood, yaw wrapping
around) form one cluster; each cluster gets its weight, mean and covariance, and the estimate is
the heaviest cluster's mean.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numba import njit

BIN_XY = 0.5  # m
BIN_YAW = math.radians(10.0)
N_YAW_BINS = 36
_OFF = 1 << 20
_SPAN = 1 << 21


def low_variance_indices(weights: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """Indices of ``n`` draws by low-variance (systematic) resampling; ``weights`` need not sum to 1. The draws
    sit at ``(u + i) * total / n`` for one uniform ``u`` (one ``rng.random()``), each taking the first weight
    whose running sum exceeds it."""
    return _low_variance(np.ascontiguousarray(weights, dtype=np.float64), int(n), rng.random())


@njit(cache=True)
def _low_variance(weights: np.ndarray, n: int, u: float) -> np.ndarray:  # pragma: no cover - compiled
    """:func:`low_variance_indices` from its uniform ``u``: ``searchsorted(cumsum(weights), points, "right")``
    clipped to the last index, by one merge walk (the points are sorted)."""
    cum = np.cumsum(weights)
    step = cum[-1] / n
    last = weights.shape[0] - 1
    out = np.empty(n, dtype=np.int64)
    j = 0
    for i in range(n):
        p = (u + i) * step
        if p != p:  # NaN sorts after every number
            out[i] = last
            continue
        while j <= last and cum[j] <= p:
            j += 1
        out[i] = min(j, last)
    return out


def kld_limit(k: np.ndarray, kld_err: float, kld_z: float, min_n: int, max_n: int) -> np.ndarray:
    """Sample count KLD-sampling asks for when the samples occupy ``k`` bins (ROS ``pf_resample_limit``)."""
    k = np.asarray(k, dtype=np.float64)
    km1 = np.maximum(k - 1.0, 1.0)
    b = 2.0 / (9.0 * km1)
    n = np.ceil(km1 / (2.0 * kld_err) * (1.0 - b + np.sqrt(b) * kld_z) ** 3)
    n = np.where(k <= 1, max_n, n)
    return np.clip(n, min_n, max_n).astype(np.int64)


def bin_keys(poses: np.ndarray) -> np.ndarray:
    """One int64 key per pose for its (x, y, yaw) histogram bin."""
    return _bin_keys(np.ascontiguousarray(poses, dtype=np.float64))


@njit(cache=True, inline="always")
def _bin_key(x: float, y: float, yaw: float) -> np.int64:  # pragma: no cover - compiled
    """The histogram bin key of one pose (floor of x / BIN_XY, y / BIN_XY and yaw / BIN_YAW; yaw bins wrap)."""
    ix = np.int64(math.floor(x / BIN_XY)) + _OFF
    iy = np.int64(math.floor(y / BIN_XY)) + _OFF
    it = np.int64(math.floor(yaw / BIN_YAW)) % N_YAW_BINS
    return (ix * _SPAN + iy) * N_YAW_BINS + it


@njit(cache=True)
def _bin_keys(poses: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """:func:`bin_keys`, compiled."""
    out = np.empty(poses.shape[0], dtype=np.int64)
    for k in range(poses.shape[0]):
        out[k] = _bin_key(poses[k, 0], poses[k, 1], poses[k, 2])
    return out


@functools.lru_cache(maxsize=8)
def _kld_limits(n: int, kld_err: float, kld_z: float, min_n: int, max_n: int) -> np.ndarray:
    """``kld_limit(k)`` for k = 0 .. n (the same NumPy evaluation, done once per parameter set; read-only)."""
    out = kld_limit(np.arange(n + 1), kld_err, kld_z, min_n, max_n)
    out.flags.writeable = False
    return out


@njit(cache=True)
def _first_over(poses: np.ndarray, order: np.ndarray, limits: np.ndarray) -> int:  # pragma: no cover - compiled
    """The first count c (1-based) of the samples ``poses[order]`` whose c samples occupy k bins with
    c > ``limits[k]``; else all (the rows are read in place, not gathered)."""
    table, used = _hash_table(order.shape[0])
    k = 0
    for m in range(order.shape[0]):
        r = order[m]
        if _add(table, used, _bin_key(poses[r, 0], poses[r, 1], poses[r, 2])):
            k += 1
        if m + 1 > limits[k]:
            return m + 1
    return order.shape[0]


def kld_count(
    candidates: np.ndarray,
    kld_err: float,
    kld_z: float,
    min_n: int,
    max_n: int,
    order: np.ndarray | None = None,
) -> int:
    """How many of ``candidates`` (drawn in random order; with ``order``: the rows ``candidates[order]``)
    KLD-sampling keeps: the first count above the limit for the bins occupied so far (the walk stops there; the
    limits are tabulated once)."""
    poses = np.ascontiguousarray(candidates, dtype=np.float64)
    rows = np.arange(poses.shape[0]) if order is None else np.ascontiguousarray(order, dtype=np.int64)
    limits = _kld_limits(rows.shape[0], float(kld_err), float(kld_z), int(min_n), int(max_n))
    n = _first_over(poses, rows, limits)
    return max(min(n, max_n), min_n)


@njit(cache=True, inline="always")
def _slot(table: np.ndarray, used: np.ndarray, key: np.int64) -> int:  # pragma: no cover - compiled
    """The slot of ``key`` in an open-addressing hash table (linear probing; ``used`` marks the taken slots, the
    table's size a power of two): where it is, else the free slot where it goes."""
    size = table.shape[0]
    slot = (key * 0x9E3779B97F4A7C15) >> 40 & (size - 1)
    while used[slot] and table[slot] != key:
        slot = (slot + 1) & (size - 1)
    return slot


@njit(cache=True, inline="always")
def _add(table: np.ndarray, used: np.ndarray, key: np.int64) -> bool:  # pragma: no cover - compiled
    """Put ``key`` in the hash table (see :func:`_slot`); whether it was not there yet."""
    slot = _slot(table, used, key)
    if used[slot]:
        return False
    used[slot] = True
    table[slot] = key
    return True


@njit(cache=True)
def _hash_table(n: int) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """An empty hash table (keys, used) for ``n`` keys: a power of two at least twice ``n`` (and 16) slots."""
    size = 16
    while size < 2 * n:
        size *= 2
    return np.empty(size, dtype=np.int64), np.zeros(size, dtype=np.bool_)


@njit(cache=True)
def unique_inverse(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """``np.unique(keys, return_inverse=True)`` by hashing: the sorted distinct keys, and each key's index among
    them (only the distinct keys are sorted)."""
    table, used = _hash_table(keys.shape[0])
    distinct = np.empty(keys.shape[0], dtype=np.int64)
    n = 0
    for m in range(keys.shape[0]):
        if _add(table, used, keys[m]):
            distinct[n] = keys[m]
            n += 1
    ukeys = np.sort(distinct[:n])
    index = np.empty(table.shape[0], dtype=np.int64)  # slot -> the key's place in ukeys
    for u in range(n):
        index[_slot(table, used, ukeys[u])] = u
    inverse = np.empty(keys.shape[0], dtype=np.int64)
    for m in range(keys.shape[0]):
        inverse[m] = index[_slot(table, used, keys[m])]
    return ukeys, inverse


@dataclass(frozen=True)
class Clusters:
    """Per-cluster weight (sum of normalised weights), mean (x, y, yaw) and 3×3 covariance."""

    weight: np.ndarray  # (C,)
    mean: np.ndarray  # (C, 3)
    cov: np.ndarray  # (C, 3, 3)
    labels: np.ndarray  # (N,) cluster of each particle

    @property
    def best(self) -> int:
        """Index of the heaviest cluster."""
        return int(np.argmax(self.weight))


@njit(cache=True)
def _find(parent: np.ndarray, a: int) -> int:
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@njit(cache=True)
def _label_bins(ukeys: np.ndarray) -> np.ndarray:
    """Connected components of occupied bins (26-neighbourhood, yaw wraps); labels 0..C-1 per bin."""
    u = ukeys.shape[0]
    parent = np.arange(u)
    for a in range(u):
        key = ukeys[a]
        it = key % N_YAW_BINS
        ixy = key // N_YAW_BINS
        ix = ixy // _SPAN
        iy = ixy % _SPAN
        # half of the 26 offsets suffice for an undirected union
        for dx in range(0, 2):
            for dy in range(-1, 2):
                for dt in range(-1, 2):
                    if dx == 0 and (dy < 0 or (dy == 0 and dt <= 0)):
                        continue
                    nk = ((ix + dx) * _SPAN + (iy + dy)) * N_YAW_BINS + (it + dt) % N_YAW_BINS
                    b = np.searchsorted(ukeys, nk)
                    if b < u and ukeys[b] == nk:
                        ra = _find(parent, a)
                        rb = _find(parent, b)
                        if ra != rb:
                            parent[max(ra, rb)] = min(ra, rb)
    labels = np.empty(u, dtype=np.int64)
    remap = np.full(u, -1, dtype=np.int64)
    c = 0
    for a in range(u):
        r = _find(parent, a)
        if remap[r] < 0:
            remap[r] = c
            c += 1
        labels[a] = remap[r]
    return labels


@njit(cache=True)
def _cluster_stats(
    labels: np.ndarray, n_comp: int, poses: np.ndarray, w: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Per cluster: weight, mean (x, y and, in its yaw column, 0 for now), covariance (its yaw-yaw entry 0 for
    now) and the mean direction's length r clipped to [1e-12, 1], from the sums of w, w x, w y, w cos, w sin,
    w xx, w yy and w xy. The same operations, in the same order, as NumPy's array expressions would make; the
    caller takes log(r) and the mean yaw's arctan2 with NumPy (its SIMD log and arctan2 differ from libm's)."""
    acc = np.zeros((n_comp, 8))
    for k in range(poses.shape[0]):
        c = labels[k]
        wk = w[k]
        x = poses[k, 0]
        y = poses[k, 1]
        acc[c, 0] += wk
        acc[c, 1] += wk * x
        acc[c, 2] += wk * y
        acc[c, 3] += wk * math.cos(poses[k, 2])
        acc[c, 4] += wk * math.sin(poses[k, 2])
        acc[c, 5] += wk * x * x
        acc[c, 6] += wk * y * y
        acc[c, 7] += wk * x * y
    wsum = np.empty(n_comp)
    mean = np.zeros((n_comp, 3))
    cs = np.empty((2, n_comp))  # mean cos, mean sin
    cov = np.zeros((n_comp, 3, 3))
    r = np.empty(n_comp)
    for c in range(n_comp):
        wsum[c] = acc[c, 0]
        safe = acc[c, 0] if acc[c, 0] > 0 else 1.0
        mx = acc[c, 1] / safe
        my = acc[c, 2] / safe
        cs[0, c] = acc[c, 3] / safe
        cs[1, c] = acc[c, 4] / safe
        rc = math.hypot(cs[0, c], cs[1, c])
        if rc < 1e-12:
            rc = 1e-12
        if rc > 1.0:
            rc = 1.0
        r[c] = rc
        vx = acc[c, 5] / safe - mx * mx
        vy = acc[c, 6] / safe - my * my
        cov[c, 0, 0] = 0.0 if vx < 0.0 else vx
        cov[c, 1, 1] = 0.0 if vy < 0.0 else vy
        cov[c, 0, 1] = cov[c, 1, 0] = acc[c, 7] / safe - mx * my
        mean[c, 0] = mx
        mean[c, 1] = my
    return wsum, mean, cov, np.vstack((r.reshape(1, n_comp), cs))


def cluster(poses: np.ndarray, weights: np.ndarray) -> Clusters:
    """Group particles into clusters of touching histogram bins and compute their statistics."""
    ukeys, inv = unique_inverse(bin_keys(poses))
    bin_label = _label_bins(ukeys)
    labels = bin_label[inv]
    wsum, mean, cov, rcs = _cluster_stats(
        labels,
        int(bin_label.max()) + 1,
        np.ascontiguousarray(poses, dtype=np.float64),
        np.ascontiguousarray(weights, dtype=np.float64),
    )
    cov[:, 2, 2] = -2.0 * np.log(rcs[0])
    mean[:, 2] = np.arctan2(rcs[2], rcs[1])
    return Clusters(weight=wsum, mean=mean, cov=cov, labels=labels)
