"""Pose files (``timestamp x y theta``): round trip, comments, and errors that name the line."""

from __future__ import annotations

import numpy as np
import pytest

from navlab.errors import NavlabError
from navlab.io import IoError
from navlab.io.poses import read_poses, read_table, write_poses


def test_write_then_read_round_trips_to_micrometres(tmp_path):
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(1e9, 1e9 + 400, 40))  # IPC-style epoch seconds
    poses = np.column_stack([rng.uniform(-50, 50, 40), rng.uniform(-50, 50, 40), rng.uniform(-np.pi, np.pi, 40)])
    write_poses(tmp_path / "p.txt", t, poses)
    t2, p2 = read_poses(tmp_path / "p.txt")
    np.testing.assert_allclose(t2, t, atol=1e-6)
    np.testing.assert_allclose(p2, poses, atol=1e-6)
    assert [f.name for f in tmp_path.iterdir()] == ["p.txt"]  # written atomically, no temporary left


def test_comments_blank_lines_and_extra_columns_are_allowed(tmp_path):
    (tmp_path / "p.txt").write_text("# t x y theta\n\n1.0 2.0 3.0 0.5  # first\n2.0 2.5 3.0 0.6 extra 7\n")
    t, p = read_poses(tmp_path / "p.txt")
    assert t.tolist() == [1.0, 2.0] and p.tolist() == [[2.0, 3.0, 0.5], [2.5, 3.0, 0.6]]


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("1 2 3 0\n1 2 3\n", r"p.txt:2: 3 columns, expected 4 for a pose line"),
        ("1 2 x 0\n", r"p.txt:1: non-numeric value in a pose line"),
        ("# only a comment\n", r"p.txt: no pose lines found"),
    ],
)
def test_malformed_files_name_the_line(tmp_path, text, needle):
    (tmp_path / "p.txt").write_text(text)
    with pytest.raises(IoError, match=needle):
        read_poses(tmp_path / "p.txt")


def test_missing_file_and_mismatched_arrays_are_navlab_errors(tmp_path):
    with pytest.raises(NavlabError, match=r"cannot read relation file .*nope.txt"):
        read_table(tmp_path / "nope.txt", 8, "relation")
    with pytest.raises(IoError, match=r"expected timestamps \(N,\) and poses \(N, 3\)"):
        write_poses(tmp_path / "p.txt", np.zeros(3), np.zeros((2, 3)))
    assert not (tmp_path / "p.txt").exists()
