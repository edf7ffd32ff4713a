"""Sparse 2D pose-graph optimisation (Gauss-Newton on SE(2), scipy.sparse, Cauchy kernel on loop edges).

Nodes are poses (x, y, theta) in the map frame; an edge (i, j, z, info) says "pose j seen from pose i
is z" with a 3x3 information matrix. The first node is held fixed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from navlab.geometry import wrap_angle


@dataclass
class PoseGraph:
    """Poses (N, 3) and edges; ``optimize`` updates ``poses`` in place. Edges change only through
    ``add_edge`` and ``remove_edge`` (their arrays are kept stacked for the optimiser)."""

    poses: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    edges_i: list[int] = field(default_factory=list)
    edges_j: list[int] = field(default_factory=list)
    edges_z: list[np.ndarray] = field(default_factory=list)
    edges_info: list[np.ndarray] = field(default_factory=list)
    edges_robust: list[bool] = field(default_factory=list)
    # stacked edge arrays (i, j, z, info) with spare rows; the first ``_stacked_n`` rows mirror the lists
    _stacked: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = field(
        default=None, init=False, repr=False, compare=False
    )
    _stacked_n: int = field(default=-1, init=False, repr=False, compare=False)

    def add_node(self, pose: np.ndarray) -> int:
        """Append a node; returns its index."""
        self.poses = np.vstack([self.poses, np.asarray(pose, dtype=np.float64)[None, :]])
        return len(self.poses) - 1

    def add_edge(self, i: int, j: int, z: np.ndarray, info: np.ndarray, *, robust: bool = False) -> None:
        """Constraint: pose j in the frame of pose i is ``z`` (x, y, theta) with information ``info``."""
        self.edges_i.append(i)
        self.edges_j.append(j)
        self.edges_z.append(np.asarray(z, dtype=np.float64))
        self.edges_info.append(np.asarray(info, dtype=np.float64))
        self.edges_robust.append(robust)
        m = len(self.edges_i) - 1
        st = self._stacked
        if st is not None and self._stacked_n == m and m < len(st[0]):
            st[0][m], st[1][m], st[2][m], st[3][m] = i, j, self.edges_z[-1], self.edges_info[-1]
            self._stacked_n = m + 1

    def _edge_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Edges' i, j (M,), z (M, 3) and info (M, 3, 3) as arrays (rebuilt from the lists when stale)."""
        m = len(self.edges_i)
        st = self._stacked
        if st is None or self._stacked_n != m:
            cap = 2 * m + 64
            st = (
                np.zeros(cap, dtype=np.int64),
                np.zeros(cap, dtype=np.int64),
                np.zeros((cap, 3)),
                np.zeros((cap, 3, 3)),
            )
            if m:
                st[0][:m], st[1][:m] = self.edges_i, self.edges_j
                st[2][:m], st[3][:m] = self.edges_z, self.edges_info
            self._stacked, self._stacked_n = st, m
        return st[0][:m], st[1][:m], st[2][:m], st[3][:m]

    def residuals(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Edge errors e (M, 3) and Jacobians A = de/dxi, B = de/dxj (M, 3, 3), plus index arrays."""
        i, j, z, _ = self._edge_arrays()
        xi, xj = self.poses[i], self.poses[j]
        ci, si = np.cos(xi[:, 2]), np.sin(xi[:, 2])
        dx, dy = xj[:, 0] - xi[:, 0], xj[:, 1] - xi[:, 1]
        # predicted relative pose in frame i, then error expressed in the frame of the measurement
        px, py = ci * dx + si * dy, -si * dx + ci * dy
        pt = wrap_angle(xj[:, 2] - xi[:, 2])
        cz, sz = np.cos(z[:, 2]), np.sin(z[:, 2])
        ex0, ey0 = px - z[:, 0], py - z[:, 1]
        e = np.stack([cz * ex0 + sz * ey0, -sz * ex0 + cz * ey0, wrap_angle(pt - z[:, 2])], axis=1)
        m = len(i)
        a = np.zeros((m, 3, 3))
        b = np.zeros((m, 3, 3))
        # d(px,py)/dxi
        dpx_dxi = np.stack([-ci, -si, -si * dx + ci * dy], axis=1)
        dpy_dxi = np.stack([si, -ci, -ci * dx - si * dy], axis=1)
        dpx_dxj = np.stack([ci, si, np.zeros(m)], axis=1)
        dpy_dxj = np.stack([-si, ci, np.zeros(m)], axis=1)
        a[:, 0] = cz[:, None] * dpx_dxi + sz[:, None] * dpy_dxi
        a[:, 1] = -sz[:, None] * dpx_dxi + cz[:, None] * dpy_dxi
        a[:, 2, 2] = -1.0
        b[:, 0] = cz[:, None] * dpx_dxj + sz[:, None] * dpy_dxj
        b[:, 1] = -sz[:, None] * dpx_dxj + cz[:, None] * dpy_dxj
        b[:, 2, 2] = 1.0
        return e, a, b, i, j

    def edge_distances(self) -> np.ndarray:
        """Mahalanobis length of each edge's error (M,)."""
        if not self.edges_i:
            return np.zeros(0)
        e = self.residuals()[0]
        return np.sqrt(np.einsum("mi,mij,mj->m", e, self._edge_arrays()[3], e))

    def remove_edge(self, k: int) -> None:
        """Drop edge ``k``."""
        for lst in (self.edges_i, self.edges_j, self.edges_z, self.edges_info, self.edges_robust):
            del lst[k]
        self._stacked_n = -1

    def chi2(self) -> float:
        """Sum of squared Mahalanobis edge errors (no robust kernel)."""
        if not self.edges_i:
            return 0.0
        e = self.residuals()[0]
        info = self._edge_arrays()[3]
        return float(np.einsum("mi,mij,mj->", e, info, e))

    def optimize(self, *, iterations: int = 10, kernel: float = 3.0, tol: float = 1e-6) -> int:
        """Gauss-Newton (IRLS) with a Cauchy kernel of width ``kernel`` (Mahalanobis) on robust edges.

        Returns the number of iterations run.
        """
        n = len(self.poses)
        if n < 2 or not self.edges_i:
            return 0
        i, j, _, info = self._edge_arrays()
        robust = np.asarray(self.edges_robust)
        system = _System(i, j, n)
        r3 = np.arange(3)
        slots = np.concatenate([(3 * i[:, None] + r3[None, :]).ravel(), (3 * j[:, None] + r3[None, :]).ravel()])
        for it in range(iterations):
            e, a, b, i, j = self.residuals()
            d2 = np.einsum("mi,mij,mj->m", e, info, e)
            w = np.where(robust, 1.0 / (1.0 + d2 / kernel**2), 1.0)
            om = info * w[:, None, None]
            # blocks of H and b (batched matrix products: A^T Om A, A^T Om B, B^T Om B, A^T Om e, B^T Om e)
            at_om = a.transpose(0, 2, 1) @ om
            bt_om = b.transpose(0, 2, 1) @ om
            haa = at_om @ a
            hab = at_om @ b
            hbb = bt_om @ b
            ga = (at_om @ e[:, :, None])[:, :, 0]
            gb = (bt_om @ e[:, :, None])[:, :, 0]
            vals = np.concatenate([blk.ravel() for blk in (haa, hab, hab.transpose(0, 2, 1), hbb)])
            # (bincount sums in input order, as np.add.at does, at a fraction of its cost)
            g = np.bincount(slots, weights=np.concatenate([ga.ravel(), gb.ravel()]), minlength=3 * n)
            step = system.solve(vals, -g[3:]).reshape(-1, 3)  # node 0 fixed
            self.poses[1:] += step
            self.poses[:, 2] = wrap_angle(self.poses[:, 2])
            if np.abs(step).max() < tol:
                return it + 1
        return iterations


class _System:
    """The Gauss-Newton system H dx = g of a graph whose edges stay the same (one ``optimize`` call), node 0
    held fixed: H's sparsity pattern and a fill-reducing order of its unknowns are worked out once, so each
    iteration only sums the edges' 3 x 3 blocks into place and factors (SuperLU, symmetric mode, the rows
    and columns pre-permuted by a minimum-degree order of H + H^T: about a quarter of the work of
    ``spsolve``'s default column order on a pose graph)."""

    def __init__(self, i: np.ndarray, j: np.ndarray, n: int) -> None:
        r3 = np.arange(3)
        # the (row, column) of every block entry (A^T A, A^T B, B^T A, B^T B of every edge), as vals is laid out
        rows = np.concatenate(
            [(3 * bi[:, None, None] + r3[None, :, None]).repeat(3, axis=2).ravel() for bi in (i, i, j, j)]
        )
        cols = np.concatenate(
            [(3 * bj[:, None, None] + r3[None, None, :]).repeat(3, axis=1).ravel() for bj in (i, j, i, j)]
        )
        m = 3 * n - 3
        keep = (rows >= 3) & (cols >= 3)
        diag = np.arange(m)
        rows = np.concatenate([rows[keep] - 3, diag])  # node 0's rows and columns dropped; a 1e-9 diagonal
        cols = np.concatenate([cols[keep] - 3, diag])
        self.keep, self.m, self.ridge = keep, m, np.full(m, 1e-9)
        # the order depends on the pattern alone: factor it with values that need no pivoting
        pattern = sp.csc_matrix((np.ones(len(rows)), (rows, cols)), shape=(m, m))
        order = splu(pattern + sp.identity(m, format="csc") * m, permc_spec="MMD_AT_PLUS_A", **_SYMMETRIC).perm_c
        self.order = np.argsort(order)  # unknown k of the permuted system is unknown order[k] of H
        where = np.empty(m, dtype=np.int64)
        where[self.order] = diag
        pr, pc = where[rows], where[cols]
        # each entry's slot among the permuted matrix's stored entries (column major, rows ascending)
        keys, self.slot = np.unique(pc * m + pr, return_inverse=True)
        self.indices = keys % m
        self.indptr = np.searchsorted(keys // m, np.arange(m + 1)).astype(np.int64)

    def solve(self, vals: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        """dx (3 n - 3,) with H (from the blocks ``vals``, laid out as in ``optimize``) dx = ``rhs``."""
        entries = np.concatenate([vals[self.keep], self.ridge])
        data = np.bincount(self.slot, weights=entries, minlength=len(self.indices))
        h = sp.csc_matrix((data, self.indices, self.indptr), shape=(self.m, self.m))
        y = splu(h, permc_spec="NATURAL", **_SYMMETRIC).solve(rhs[self.order])
        dx = np.empty_like(y)
        dx[self.order] = y
        return dx


_SYMMETRIC = {"diag_pivot_thresh": 0.0, "options": {"SymmetricMode": True}}
