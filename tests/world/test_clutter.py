"""BARN's clutter worlds: determinism, BARN's automaton rule and configuration space cell by cell, the way through
the written .world, the reference path, the graded suite and the ``navlab world clutter`` verb."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from navlab.cli import main
from navlab.world import WorldError, load_world, occupancy
from navlab.world.clutter import (
    CELL,
    CYLINDER_RADIUS,
    FIELD,
    barn_score,
    cellular_automaton,
    clutter_suite,
    configuration_space,
    generate_clutter,
    guaranteed_clearance,
    suite_parameters,
    written_cylinders,
)

BOUNDS = (-5.4, -2.8, 9.0, 2.8)  # m: the whole arena, walls included


def _barn_rule(cells: np.ndarray) -> np.ndarray:
    """One smoothing round read cell by cell from BARN's description: >= 5 filled neighbours fill, <= 1 clear;
    beyond the first and last rows counts as filled, beyond the first and last columns as empty."""
    out = cells.copy()
    for r, c in itertools.product(range(30), range(30)):
        n = 0
        for i, j in itertools.product(range(r - 1, r + 2), range(c - 1, c + 2)):
            if (i, j) != (r, c):
                n += 1 if not 0 <= i < 30 else (bool(cells[i, j]) if 0 <= j < 30 else 0)
        out[r, c] = True if n >= 5 else (False if n <= 1 else cells[r, c])
    return out


def _cell(bounds: tuple[float, float, float, float], res: float, x: float, y: float) -> tuple[int, int]:
    return int((y - bounds[1]) / res), int((x - bounds[0]) / res)


def test_same_seed_same_world_other_seed_other_world() -> None:
    a = generate_clutter(7, fill=0.3, smooth=2)
    b = generate_clutter(7, fill=0.3, smooth=2)
    c = generate_clutter(8, fill=0.3, smooth=2)
    assert np.array_equal(a.cylinders, b.cylinders) and np.array_equal(a.reference_path, b.reference_path)
    assert a.to_sdf() == b.to_sdf()
    assert not np.array_equal(a.cells, c.cells)


def test_cylinder_count_grows_with_fill() -> None:
    counts = [
        np.mean([len(generate_clutter(s, fill=f, smooth=2).cylinders) for s in range(3)])
        for f in (0.05, 0.15, 0.2, 0.25, 0.3)
    ]
    assert all(b > a for a, b in itertools.pairwise(counts)), counts
    assert len(generate_clutter(0, fill=0.0, smooth=0).cylinders) == 60  # the two wall rows alone


def test_automaton_and_configuration_space_follow_barns_rules_cell_by_cell() -> None:
    for seed, fill, smooth in ((0, 0.25, 3), (1, 0.4, 2), (2, 0.15, 4)):
        rng = np.random.default_rng(seed)
        expected = np.ones((30, 30), dtype=bool)
        expected[1:-1] = rng.random((28, 30)) < fill
        for _ in range(smooth):
            expected = _barn_rule(expected)
        cells = cellular_automaton(np.random.default_rng(seed), fill, smooth)
        assert np.array_equal(cells, expected)
        for k in (1, 2, 3):  # the robot's centre cell is free when no cylinder lies in its (2k+1)^2 window
            free = configuration_space(cells, k)
            for r, c in itertools.product(range(30), range(30)):
                window = cells[max(0, r - k) : r + k + 1, max(0, c - k) : c + k + 1]
                assert free[r, c] == (not window.any())
    many = cellular_automaton(np.random.default_rng(5), 0.2, 3, count=4)  # a stack = the same draws one by one
    one_by_one = np.random.default_rng(5)
    assert all(np.array_equal(f, cellular_automaton(one_by_one, 0.2, 3)) for f in many)


def test_cylinders_inside_a_filled_block_are_not_written() -> None:
    cells = np.zeros((30, 30), dtype=bool)
    cells[[0, -1]] = True
    cells[10:15, 10:15] = True  # a 5 x 5 block: 9 hidden cylinders
    pts = written_cylinders(cells)
    assert len(pts) == 60 + 25 - 9
    assert not np.any(np.all(np.isclose(pts, [(12 + 0.5) * CELL, -FIELD / 2 + (12 + 0.5) * CELL]), axis=1))


def test_layout_start_goal_and_grid() -> None:
    w = generate_clutter(1, fill=0.25, smooth=2)
    sx, sy, _ = w.start
    gx, gy, _ = w.goal
    assert (gx - sx, gy - sy) == pytest.approx((10.0, 0.0))
    x, y = w.cylinders[:, 0], w.cylinders[:, 1]
    assert x.min() - CYLINDER_RADIUS >= 0.0 and x.max() + CYLINDER_RADIUS <= FIELD + 1e-9  # field at x 0..4.5
    assert np.abs(y).max() + CYLINDER_RADIUS <= FIELD / 2 + 1e-9
    assert (sx, sy) == pytest.approx((-2.1, -0.25))  # BARN's start: 2.1 m before the field, 0.25 m off centre
    assert gx > FIELD  # the goal is past the field
    # cylinder centres sit on the 0.15 m grid of the 30 x 30 field, whose first and last rows are walls
    for v, off in ((x, 0.0), (y, -FIELD / 2)):
        k = (v - off - CELL / 2) / CELL
        assert np.allclose(k, np.round(k)) and k.min() >= 0 and k.max() <= 29
    assert w.cells.shape == (30, 30) and w.cells[[0, -1]].all()
    assert len(w.cylinders) == len(written_cylinders(w.cells)) and w.attempts >= 1


@pytest.mark.parametrize(("seed", "fill", "smooth"), [(0, 0.15, 2), (1, 0.25, 3), (2, 0.3, 2), (3, 0.3, 4)])
def test_the_jackal_has_a_way_through_the_written_world(tmp_path: Path, seed: int, fill: float, smooth: int) -> None:
    """Independent check: the loaded .world's true occupancy, a distance transform, connectivity: BARN's Jackal
    (2 cells) keeps 0.375 m from every surface on its way from the start to the goal."""
    w = generate_clutter(seed, fill=fill, smooth=smooth)
    world = load_world(w.write_world(tmp_path / "c.world"))
    res = 0.025
    occ = occupancy(world, res, BOUNDS)
    clearance = ndimage.distance_transform_edt(~occ) * res  # m from a free cell centre to an occupied one
    free = clearance > guaranteed_clearance(2) - 2 * res  # less two cells for the grid's rounding
    labels, _ = ndimage.label(free, structure=np.ones((3, 3)))
    start = labels[_cell(BOUNDS, res, *w.start[:2])]
    goal = labels[_cell(BOUNDS, res, *w.goal[:2])]
    assert start and start == goal
    if (fill, smooth) == (0.3, 2):  # most such draws have no way through: BARN draws again
        assert w.attempts > 1


def test_world_file_loads_and_occupancy_matches_the_cylinders(tmp_path: Path) -> None:
    w = generate_clutter(4, fill=0.25, smooth=2)
    path = w.write_world(tmp_path / "sub" / "clutter.world")
    world = load_world(path)
    assert world.ground_plane and not world.warnings
    names = {m.name: m for m in world.models}
    assert len(names["clutter_cylinders"].links) == len(w.cylinders) and names["clutter_cylinders"].static
    assert len(names["clutter_walls"].links) == 3
    # the field's true occupancy, cell by cell, is the cylinders' discs (a cell is occupied if it overlaps one)
    res, bounds = 0.05, (0.0, -FIELD / 2, FIELD, FIELD / 2)
    occ = occupancy(world, res, bounds)
    xs = bounds[0] + (np.arange(occ.shape[1]) + 0.5) * res
    ys = bounds[1] + (np.arange(occ.shape[0]) + 0.5) * res
    gx, gy = np.meshgrid(xs, ys)
    expected = np.zeros_like(occ)
    for cx, cy in w.cylinders:
        dx = np.maximum(np.abs(gx - cx) - res / 2, 0.0)
        dy = np.maximum(np.abs(gy - cy) - res / 2, 0.0)
        expected |= dx * dx + dy * dy < CYLINDER_RADIUS**2 - 1e-9
    assert np.array_equal(occ, expected)
    # and the walls close the start zone (4.2 m wide, its back 2.925 m behind the start) in line with the wall rows
    full = occupancy(world, 0.05, BOUNDS)
    for x in (-4.8, -2.0, -0.1):
        assert full[_cell(BOUNDS, 0.05, x, 2.175)] and full[_cell(BOUNDS, 0.05, x, -2.175)]
        assert not full[_cell(BOUNDS, 0.05, x, 2.0)] and not full[_cell(BOUNDS, 0.05, x, -2.0)]
    assert full[_cell(BOUNDS, 0.05, -5.03, 0.0)] and not full[_cell(BOUNDS, 0.05, -4.9, 0.0)]
    assert not full[_cell(BOUNDS, 0.05, *w.start[:2])] and not full[_cell(BOUNDS, 0.05, *w.goal[:2])]


@pytest.mark.parametrize("seed", [0, 5, 9])
def test_reference_path_is_collision_free_and_at_least_the_straight_line(seed: int) -> None:
    w = generate_clutter(seed, fill=0.3, smooth=3, robot_radius=0.2)
    p = w.reference_path
    assert np.allclose(p[0], w.start[:2]) and np.allclose(p[-1], w.goal[:2])
    length = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    assert w.reference_path_m == pytest.approx(length)
    assert math.isfinite(length) and length >= 10.0 - 1e-9
    assert w.t_opt() == pytest.approx(length / 2.0)
    dense = np.vstack([a + t * (b - a) for a, b in itertools.pairwise(p) for t in np.linspace(0.0, 1.0, 400)])
    d = np.linalg.norm(dense[:, None, :] - w.cylinders[None, :, :], axis=2).min(axis=1)
    assert d.min() >= w.robot_radius + CYLINDER_RADIUS - 1e-6  # the disc never touches a cylinder
    beside_walls = dense[:, 0] <= FIELD  # the side walls run up to the field's far edge
    assert np.abs(dense[beside_walls, 1]).max() <= FIELD / 2 - w.robot_radius + 1e-6


def test_empty_field_reference_is_the_straight_line() -> None:
    w = generate_clutter(0, fill=0.0, smooth=0)
    assert w.reference_path_m == pytest.approx(10.0) and len(w.reference_path) == 2
    assert w.difficulty == 0.0 and w.attempts == 1


def test_a_bigger_robot_gets_a_wider_way_through() -> None:
    for k in (1, 2, 3):
        w = generate_clutter(2, fill=0.25, smooth=3, robot_cells=k)
        assert w.metrics["bottleneck_m"] >= guaranteed_clearance(k) - 0.01
    assert guaranteed_clearance(2) == pytest.approx(0.375)  # the Jackal's 5 x 5 cells


def test_suite_is_graded_and_deterministic() -> None:
    suite = clutter_suite()
    assert len(suite) == 50 and len({w.name for w in suite}) == 50
    d = np.array([w.difficulty for w in suite])
    thirds = [d[:17].mean(), d[17:34].mean(), d[34:].mean()]
    assert thirds[0] < thirds[1] < thirds[2]  # non-decreasing on average
    assert np.corrcoef(np.arange(50), d)[0, 1] > 0.8
    assert d[:10].mean() < 0.07 and d[-10:].mean() > 0.2
    assert all(w.reference_path_m >= 10.0 for w in suite)
    assert min(w.metrics["bottleneck_m"] for w in suite) >= guaranteed_clearance(2) - 0.01
    # BARN's 12 parameter sets in its order, in equal shares
    params = suite_parameters(12)
    assert params == [(f, s) for f in (0.15, 0.2, 0.25, 0.3) for s in (2, 3, 4)]
    assert [(w.fill, w.smooth) for w in suite] == suite_parameters(50) and suite_parameters(50).count((0.3, 4)) == 4
    small = [w.to_sdf() for w in clutter_suite(4, seed=2)]
    assert small == [w.to_sdf() for w in clutter_suite(4, seed=2)]
    assert small != [w.to_sdf() for w in clutter_suite(4, seed=3)]


def test_bad_options_are_one_line_errors() -> None:
    with pytest.raises(WorldError, match=r"fill must be in \[0, 1\], got 1.5"):
        generate_clutter(0, fill=1.5, smooth=1)
    with pytest.raises(WorldError, match="smooth must be an integer >= 0, got -1"):
        generate_clutter(0, fill=0.2, smooth=-1)
    with pytest.raises(WorldError, match=r"fit between the walls 4\.2 m apart"):
        generate_clutter(0, fill=0.2, smooth=1, robot_radius=2.5)
    with pytest.raises(WorldError, match=r"robot_cells must be an integer in 0\.\.13"):
        generate_clutter(0, fill=0.2, smooth=1, robot_cells=14)
    with pytest.raises(WorldError, match="no way through for robot_cells 2"):
        generate_clutter(0, fill=0.6, smooth=1)
    with pytest.warns(DeprecationWarning, match="margin"):
        generate_clutter(0, fill=0.2, smooth=1, margin=0.05)


def test_barn_score() -> None:
    assert barn_score(False, 10.0, 5.0) == 0.0
    assert barn_score(True, 5.0, 5.0) == pytest.approx(0.5)  # faster than 2 T_opt counts as 2 T_opt
    assert barn_score(True, 20.0, 5.0) == pytest.approx(0.25)
    assert barn_score(True, 100.0, 5.0) == pytest.approx(0.125)  # slower than 8 T_opt counts as 8 T_opt


def test_cli_writes_world_png_and_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out, png = tmp_path / "c" / "clutter.world", tmp_path / "c" / "clutter.png"
    code = main(
        [
            "world",
            "clutter",
            "--seed",
            "3",
            "--fill",
            "0.3",
            "--smooth",
            "2",
            "--out",
            str(out.parent),
            "--png",
            "--json",
        ]
    )
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    w = generate_clutter(3, fill=0.3, smooth=2)
    assert out.read_text() == w.to_sdf()
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert summary["reference_path_m"] == pytest.approx(w.reference_path_m, abs=1e-3)
    assert summary["start"] == [-2.1, -0.25, 0.0] and summary["goal"] == pytest.approx([7.9, -0.25, 0.0])
    assert summary["cylinders"] == len(w.cylinders) and summary["world_file"] == str(out)
    # deprecated until the next release: --out FILE.world (and --png FILE.png) as before, with one line saying so
    assert main(["world", "clutter", "--out", str(tmp_path / "d.world"), "--png", str(tmp_path / "d.png")]) == 0
    captured = capsys.readouterr()
    assert "reference path" in captured.out and "start" in captured.out and "goal" in captured.out
    assert (tmp_path / "d.world").is_file() and (tmp_path / "d.png").is_file()
    assert captured.err.count("DeprecationWarning") == 1 and "--out names a folder" in captured.err
    assert main(["world", "clutter", "--out", str(tmp_path / "e"), "--margin", "0.05"]) == 0  # ignored, one line
    captured = capsys.readouterr()
    assert captured.err.count("DeprecationWarning") == 1 and "--margin is ignored" in captured.err
    with pytest.raises(SystemExit) as exc:
        main(["world", "clutter", "--fill", "2", "--out", str(out)])
    assert exc.value.code == 2
    assert "--fill" in capsys.readouterr().err
