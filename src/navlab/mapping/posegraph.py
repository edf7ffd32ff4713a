"""Sparse 2D pose-graph optimisation (Gauss-Newton on SE(2), scipy.sparse, Cauchy kernel on loop edges).

Nodes are poses (x, y, theta) in the map frame; an edge (i, j, z, info) says "pose j seen from pose i
is z" with a 3x3 information matrix. The first node is held fixed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from navlab.geometry import wrap_angle


@dataclass
class PoseGraph:
    """Poses (N, 3) and edges; ``optimize`` updates ``poses`` in place."""

    poses: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    edges_i: list[int] = field(default_factory=list)
    edges_j: list[int] = field(default_factory=list)
    edges_z: list[np.ndarray] = field(default_factory=list)
    edges_info: list[np.ndarray] = field(default_factory=list)
    edges_robust: list[bool] = field(default_factory=list)

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

    def residuals(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Edge errors e (M, 3) and Jacobians A = de/dxi, B = de/dxj (M, 3, 3), plus index arrays."""
        i = np.asarray(self.edges_i)
        j = np.asarray(self.edges_j)
        z = np.asarray(self.edges_z)
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
        return np.sqrt(np.einsum("mi,mij,mj->m", e, np.asarray(self.edges_info), e))

    def remove_edge(self, k: int) -> None:
        """Drop edge ``k``."""
        for lst in (self.edges_i, self.edges_j, self.edges_z, self.edges_info, self.edges_robust):
            del lst[k]

    def chi2(self) -> float:
        """Sum of squared Mahalanobis edge errors (no robust kernel)."""
        if not self.edges_i:
            return 0.0
        e = self.residuals()[0]
        info = np.asarray(self.edges_info)
        return float(np.einsum("mi,mij,mj->", e, info, e))

    def optimize(self, *, iterations: int = 10, kernel: float = 3.0, tol: float = 1e-6) -> int:
        """Gauss-Newton (IRLS) with a Cauchy kernel of width ``kernel`` (Mahalanobis) on robust edges.

        Returns the number of iterations run.
        """
        n = len(self.poses)
        if n < 2 or not self.edges_i:
            return 0
        info = np.asarray(self.edges_info)
        robust = np.asarray(self.edges_robust)
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
            r3 = np.arange(3)
            rows, cols, vals = [], [], []
            for blk, bi, bj in ((haa, i, i), (hab, i, j), (hab.transpose(0, 2, 1), j, i), (hbb, j, j)):
                rows.append((3 * bi[:, None, None] + r3[None, :, None]).repeat(3, axis=2).ravel())
                cols.append((3 * bj[:, None, None] + r3[None, None, :]).repeat(3, axis=1).ravel())
                vals.append(blk.ravel())
            h = sp.coo_matrix(
                (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(3 * n, 3 * n)
            ).tocsr()
            g = np.zeros(3 * n)
            np.add.at(g, (3 * i[:, None] + r3[None, :]).ravel(), ga.ravel())
            np.add.at(g, (3 * j[:, None] + r3[None, :]).ravel(), gb.ravel())
            # fix node 0
            hh = h[3:, 3:] + sp.identity(3 * n - 3, format="csr") * 1e-9
            dx = spsolve(hh.tocsc(), -g[3:])
            step = dx.reshape(-1, 3)
            self.poses[1:] += step
            self.poses[:, 2] = wrap_angle(self.poses[:, 2])
            if np.abs(step).max() < tol:
                return it + 1
        return iterations
