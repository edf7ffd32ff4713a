"""The navigation stack's compiled steps give exactly what the plain computations they replace give."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
from scipy import ndimage

from navlab.experiments.metrics import distance_to_path
from navlab.grid import COST_LETHAL, Grid
from navlab.localization import sampling
from navlab.navigation.costmap import InflationLayer, make_footprint
from navlab.navigation.costmap.footprint import Footprint
from navlab.navigation.costmap.kernels import inflate_box
from navlab.navigation.scan_points import ScanPoints

RES = 0.05


def _edt_costs(seeds: np.ndarray, table: np.ndarray) -> np.ndarray:
    """The table at each cell's squared cell distance to its nearest seed, from scipy's feature transform."""
    ft = ndimage.distance_transform_edt(~seeds, return_distances=False, return_indices=True)
    jj, ii = np.mgrid[0 : seeds.shape[0], 0 : seeds.shape[1]]
    d2 = (ft[0] - jj) ** 2 + (ft[1] - ii) ** 2
    return table[np.minimum(d2, table.size - 1)]


def test_inflation_kernel_equals_a_euclidean_distance_transform() -> None:
    rng = np.random.default_rng(3)
    table = np.arange(250, dtype=np.uint8)[::-1].copy()  # a different cost for every squared distance
    for density in (0.002, 0.02, 0.2):
        seeds = rng.random((47, 61)) < density
        seeds[5, 7] = True
        out = np.zeros(seeds.shape, np.uint8)
        inflate_box(seeds, (0, 47, 0, 61), (0, 47, 0, 61), table, out)
        np.testing.assert_array_equal(out, _edt_costs(seeds, table))


def test_incremental_and_rolling_inflation_equals_a_fresh_layer() -> None:
    """Obstacles come and go and the window moves: the layer that keeps its last inflation and recomputes only
    around the changes writes the same master as a layer inflating from scratch each time."""
    rng = np.random.default_rng(0)
    params = {"inflation_radius": 0.55, "cost_scaling_factor": 10.0}
    kept = InflationLayer(params, footprint=make_footprint(robot_radius=0.2))
    lethal = rng.random((60, 70)) < 0.01
    origin = (0.0, 0.0)
    for step in range(12):
        if step % 3 == 2:  # a rolling window moved by whole cells
            origin = (origin[0] + RES * int(rng.integers(-3, 4)), origin[1] + RES * int(rng.integers(-3, 4)))
        flip = rng.random(lethal.shape) < 0.002
        lethal = lethal ^ flip
        data = np.where(lethal, COST_LETHAL, rng.integers(0, 3, lethal.shape)).astype(np.uint8)
        a = Grid(data.copy(), RES, (origin[0], origin[1], 0.0), "odom")
        b = Grid(data.copy(), RES, (origin[0], origin[1], 0.0), "odom")
        kept.update_costs(a)
        InflationLayer(params, footprint=make_footprint(robot_radius=0.2)).update_costs(b)
        np.testing.assert_array_equal(a.data, b.data, err_msg=f"step {step}")


def test_round_footprint_cells_are_the_centres_within_the_radius() -> None:
    rng = np.random.default_rng(1)
    for _ in range(200):
        grid = Grid(
            np.zeros((int(rng.integers(3, 40)), int(rng.integers(3, 40))), np.uint8),
            RES,
            (float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), 0.0),
            "map",
        )
        radius = float(rng.uniform(0.01, 0.4))
        x = grid.origin[0] + float(rng.uniform(-0.3, grid.width * RES + 0.3))
        y = grid.origin[1] + float(rng.uniform(-0.3, grid.height * RES + 0.3))
        cells = Footprint(radius, None).cells(grid, (x, y, 0.0))
        jj, ii = np.mgrid[0 : grid.height, 0 : grid.width]
        centres = grid.cell_to_world(np.stack([ii.ravel(), jj.ravel()], axis=1))
        inside = np.hypot(centres[:, 0] - x, centres[:, 1] - y) <= radius
        inside |= (ii.ravel() == math.floor((x - grid.origin[0]) / RES)) & (
            jj.ravel() == math.floor((y - grid.origin[1]) / RES)
        )
        expected = np.stack([ii.ravel(), jj.ravel()], axis=1)[inside]
        assert sorted(map(tuple, cells.tolist())) == sorted(map(tuple, expected.tolist()))


def test_scan_points_are_worked_out_once_per_message() -> None:
    ranges = np.array([1.0, np.inf, np.nan, 0.01, 4.0, 2.5], np.float32)
    msg = SimpleNamespace(ranges=ranges, angle_min=-1.0, angle_increment=0.4, range_min=0.1, range_max=4.0)
    shared = ScanPoints()
    pts, valid = shared.points(msg, 3.0)
    assert shared.points(msg, 3.0)[0] is pts  # the second costmap gets the same points
    a = -1.0 + 0.4 * np.array([0, 1, 3, 4, 5])  # the NaN reading has no end point
    d = np.array([1.0, 3.0, 3.0, 3.0, 2.5])  # no return (inf, under range_min, at range_max): cleared to 3 m
    np.testing.assert_allclose(pts, np.stack([d * np.cos(a), d * np.sin(a)], axis=1), rtol=0, atol=1e-6)
    assert valid.tolist() == [True, False, False, False, True]
    other = SimpleNamespace(**{**vars(msg), "ranges": ranges * 0.5})
    assert not np.array_equal(shared.points(other, 3.0)[0], pts)


def test_kld_bin_count_and_tracking_distance_equal_their_plain_forms() -> None:
    rng = np.random.default_rng(2)
    keys = rng.integers(0, 40, 500)
    _, first = np.unique(keys, return_index=True)
    is_new = np.zeros(keys.size, np.int64)
    is_new[first] = 1
    np.testing.assert_array_equal(sampling.bins_so_far(keys), np.cumsum(is_new))
    path = np.cumsum(rng.normal(0, 0.1, (80, 2)), axis=0)
    pts = rng.normal(0, 1, (5, 2))
    a, ab = path[:-1], np.diff(path, axis=0)
    t = np.clip(((pts[:, None] - a) * ab).sum(axis=2) / (ab**2).sum(axis=1), 0, 1)
    expected = np.hypot(*(pts[:, None] - (a + t[..., None] * ab)).transpose(2, 0, 1)).min(axis=1)
    np.testing.assert_allclose(distance_to_path(pts, path), expected, rtol=1e-12)
