"""Pose files: one ``timestamp x y theta`` line per pose (s, m, m, rad; ``#`` comments allowed), as
written by ``navlab slam`` and read by ``navlab eval relations``; and the whitespace-separated number
tables they and relations files share.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from navlab.io.errors import IoError
from navlab.io.files import write_text_atomic


def read_table(path: str | os.PathLike[str], min_cols: int, what: str) -> np.ndarray:
    """The first ``min_cols`` numbers of every non-comment line, as an (N, min_cols) float64 array.

    ``what`` names a line in messages (``"pose"``, ``"relation"``). Raises ``IoError`` naming the
    file and line for an unreadable file, a short or non-numeric line, or a file without lines.
    """
    p = Path(path)
    try:
        if p.exists() and not p.is_file():  # a FIFO would block, a device never end
            raise IoError(f"cannot read {what} file {p}: not a regular file")
        lines = p.read_text().splitlines()
    except OSError as exc:
        raise IoError(f"cannot read {what} file {p}: {exc.strerror or exc}") from None
    rows = []
    for lineno, line in enumerate(lines, 1):
        s = line.split("#", 1)[0].split()
        if not s:
            continue
        if len(s) < min_cols:
            raise IoError(f"{p}:{lineno}: {len(s)} columns, expected {min_cols} for a {what} line")
        try:
            rows.append([float(v) for v in s[:min_cols]])
        except ValueError:
            raise IoError(f"{p}:{lineno}: non-numeric value in a {what} line") from None
    if not rows:
        raise IoError(f"{p}: no {what} lines found")
    return np.array(rows, dtype=np.float64)


def read_poses(path: str | os.PathLike[str]) -> tuple[np.ndarray, np.ndarray]:
    """(timestamps (N,) s, poses (N, 3) x m, y m, theta rad) from a ``timestamp x y theta`` file."""
    t = read_table(path, 4, "pose")
    return t[:, 0], t[:, 1:4]


def write_poses(path: str | os.PathLike[str], timestamps: np.ndarray, poses: np.ndarray) -> None:
    """Write ``timestamp x y theta`` lines (6 decimals) atomically; ``poses`` is (N, 3)."""
    t = np.asarray(timestamps, dtype=np.float64)
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) != len(t) or t.ndim != 1:
        raise IoError(f"write_poses {path}: expected timestamps (N,) and poses (N, 3), got {t.shape} and {p.shape}")
    lines = [f"{ti:.6f} {pi[0]:.6f} {pi[1]:.6f} {pi[2]:.6f}\n" for ti, pi in zip(t, p, strict=True)]
    write_text_atomic(path, "".join(lines))
