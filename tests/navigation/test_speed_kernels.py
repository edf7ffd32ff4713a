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
    """Obstacles come and go and the window moves over the world: the layer that keeps its last inflation and
    recomputes only around the changes and the window's edges writes the same master as a layer inflating from
    scratch each time."""
    rng = np.random.default_rng(0)
    params = {"inflation_radius": 0.55, "cost_scaling_factor": 10.0}
    kept = InflationLayer(params, footprint=make_footprint(robot_radius=0.2))
    world = rng.random((300, 300)) < 0.01
    j, i = 100, 100  # the window's lower-left cell in the world
    for step in range(40):
        if step % 3 != 0:  # the window moved by whole cells, now and then by more than the inflation's reach
            far = 40 if step % 9 == 8 else 4
            j, i = j + int(rng.integers(-far, far + 1)), i + int(rng.integers(-far, far + 1))
        flip = rng.random(world.shape) < (0.05 if step % 7 == 6 else 0.0005)  # now and then many changes at once
        world ^= flip
        lethal = world[j : j + 60, i : i + 70] & (step % 11 != 10)  # and now and then no obstacle at all
        data = np.where(lethal, COST_LETHAL, rng.integers(0, 3, lethal.shape)).astype(np.uint8)
        a = Grid(data.copy(), RES, (i * RES, j * RES, 0.0), "odom")
        b = Grid(data.copy(), RES, (i * RES, j * RES, 0.0), "odom")
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
        Footprint(radius, None).fill(grid, (x, y, 0.0), 7)  # the footprint clearing: exactly those cells
        assert sorted(map(tuple, np.argwhere(grid.data == 7)[:, ::-1].tolist())) == sorted(map(tuple, cells.tolist()))


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
    poses = np.column_stack([rng.normal(0, 3, 3000), rng.normal(0, 3, 3000), rng.uniform(-4, 4, 3000)])
    poses[::3, :2] = np.round(poses[::3, :2] * 2) / 2  # on the bins' edges
    ix, iy = (np.floor(poses[:, k] / sampling.BIN_XY).astype(np.int64) + sampling._OFF for k in (0, 1))
    it = np.floor(poses[:, 2] / sampling.BIN_YAW).astype(np.int64) % sampling.N_YAW_BINS
    np.testing.assert_array_equal(sampling.bin_keys(poses), (ix * sampling._SPAN + iy) * sampling.N_YAW_BINS + it)
    for keys in (rng.integers(0, 40, 500), sampling.bin_keys(poses)):
        ukeys, inverse = np.unique(keys, return_inverse=True)
        hashed = sampling.unique_inverse(keys)
        np.testing.assert_array_equal(hashed[0], ukeys)
        np.testing.assert_array_equal(hashed[1], inverse.ravel())
    for spread in (3.0, 0.2, 0.1):  # KLD's count: the first count above the limit for the bins occupied so far
        cand = poses * (spread / 3.0)
        _, first = np.unique(sampling.bin_keys(cand), return_index=True)
        is_new = np.zeros(len(cand), np.int64)
        is_new[first] = 1
        counts = np.arange(1, len(cand) + 1)
        over = np.flatnonzero(counts > sampling.kld_limit(np.cumsum(is_new), 0.01, 0.99, 100, 5000))
        plain = max(min(int(counts[over[0]]) if over.size else len(cand), 5000), 100)
        assert sampling.kld_count(cand, 0.01, 0.99, 100, 5000) == plain
    for size in (1, 7, 300):  # low-variance draws: searchsorted on the running sums, from one rng.random()
        w = rng.random(size) ** 3
        w[rng.random(size) < 0.3] = 0.0
        u = np.random.default_rng(size).random()
        cum = np.cumsum(w)
        plain_idx = np.minimum(np.searchsorted(cum, (u + np.arange(500)) * (cum[-1] / 500), side="right"), size - 1)
        drawn = sampling.low_variance_indices(w, 500, np.random.default_rng(size))
        np.testing.assert_array_equal(drawn, plain_idx)
    path = np.cumsum(rng.normal(0, 0.1, (80, 2)), axis=0)
    pts = rng.normal(0, 1, (5, 2))
    a, ab = path[:-1], np.diff(path, axis=0)
    t = np.clip(((pts[:, None] - a) * ab).sum(axis=2) / (ab**2).sum(axis=1), 0, 1)
    expected = np.hypot(*(pts[:, None] - (a + t[..., None] * ab)).transpose(2, 0, 1)).min(axis=1)
    np.testing.assert_allclose(distance_to_path(pts, path), expected, rtol=1e-12)


def test_controller_scene_kernel_equals_the_plain_steps() -> None:
    """The rollout controllers' compiled scene set-up gives the plan stretch, plan cells and path distances the
    separate steps give (frame change, crop, cells, cells under the robot, wave), for every free-cell mode."""
    from navlab.navigation.controllers import mapgrid
    from navlab.navigation.controllers.common import LocalFrame, circle_footprint, crop_plan, footprint_outline
    from navlab.navigation.controllers.rollout import footprint_cells
    from navlab.navigation.controllers.scene_kernel import moved_length, path_scene, poses_out

    rng = np.random.default_rng(4)
    square = np.array([[0.25, 0.2], [-0.2, 0.2], [-0.2, -0.2], [0.25, -0.2]])
    for trial in range(60):
        cost = np.where(rng.random((60, 70)) < 0.08, 254, rng.integers(0, 200, (60, 70))).astype(np.uint8)
        cost[rng.random(cost.shape) < 0.01] = 255
        origin = (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)), 0.0)
        frame = LocalFrame(*origin)
        pose = (origin[0] + float(rng.uniform(0, 3.5)), origin[1] + float(rng.uniform(0, 3.0)), rng.uniform(-3, 3))
        plan = np.cumsum(rng.normal(0, 0.08, (int(rng.integers(1, 120)), 2)), axis=0) + pose[:2]
        if trial % 7 == 0:
            plan += 5.0  # far from the robot: nothing to crop
        pose_l = frame.pose_in(pose)
        polygon = square if trial % 2 else circle_footprint(0.2)
        edges = footprint_outline(polygon, RES)
        for mode in (0, 1, 2):
            got_plan, got_cells, got_wave = path_scene(
                cost, plan, *origin, RES, pose_l, 0.5 * RES * 70, mode, polygon, edges
            )
            want_plan = crop_plan(frame.points_in(plan), pose_l[0], pose_l[1], 0.5 * RES * 70)
            np.testing.assert_array_equal(got_plan, want_plan)
            if len(want_plan) == 0:
                continue
            want_cells = mapgrid.plan_cells(cost, want_plan, RES)
            np.testing.assert_array_equal(got_cells, want_cells)
            if len(want_cells) == 0:
                continue
            free = None if mode == 0 else footprint_cells(cost.shape, RES, pose_l, polygon if mode == 2 else None)
            mapgrid.wave_to(cost, got_wave, -1, -1)  # grown whole
            np.testing.assert_array_equal(got_wave[0], mapgrid.distance_map(cost, want_cells, free))
    for path in (np.zeros((4, 3)), np.array([[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0], [0.2, 0, 0]], float)):
        moved = np.nonzero(np.any(path[1:] != path[:-1], axis=1))[0]  # _finish's plain form
        assert moved_length(path) == ((int(moved[-1]) + 2) if len(moved) else 1)
    for oyaw in (0.0, 0.7, -2.9):
        frame = LocalFrame(1.25, -3.5, oyaw)
        poses = rng.uniform(-7, 7, (40, 3))
        got = poses_out(poses, 25, frame.ox, frame.oy, oyaw, math.cos(oyaw), math.sin(oyaw))
        np.testing.assert_array_equal(got, frame.poses_out(poses[:25]))


def test_obstacle_layer_takes_ranges_in_one_call_as_it_takes_their_endpoints() -> None:
    """A scan's ranges into the obstacle layer (one compiled call) give the grid its endpoints give, bit for bit:
    returns, inf, NaN, readings under range_min and at range_max, sensors inside and outside the grid."""
    from navlab.geometry import transform_points2
    from navlab.navigation.costmap import ObstacleLayer

    rng = np.random.default_rng(4)
    marked = cleared = 0
    params = {"obstacle_range": 2.5, "raytrace_range": 3.0, "raytrace_min_range": 0.1, "obstacle_min_range": 0.05}
    for trial in range(30):
        ranges = rng.uniform(0.0, 4.5, 360).astype(np.float32)
        ranges[rng.random(360) < 0.1] = np.inf
        ranges[rng.random(360) < 0.05] = np.nan
        msg = SimpleNamespace(ranges=ranges, angle_min=-3.1, angle_increment=0.0172, range_min=0.12, range_max=4.0)
        sensor = np.array([rng.uniform(-1.0, 5.0), rng.uniform(-1.0, 4.0), rng.uniform(-np.pi, np.pi)])
        clear_to = 3.0 if trial % 2 else 4.0
        layers = [ObstacleLayer(params), ObstacleLayer(params)]
        before = rng.integers(1, 256, (80, 90)).astype(np.uint8)  # what clearing and marking overwrite
        for layer in layers:
            layer.match_size(Grid(np.zeros((80, 90), np.uint8), RES, (0.0, -0.5, 0.0), "map"))
            assert layer.grid is not None
            layer.grid.data[:] = before
        points = ScanPoints()
        pts, valid = points.points(msg, clear_to)
        layers[0].add_scan(sensor[:2], transform_points2(sensor, pts), valid)
        layers[1].add_ranges(sensor, ranges, points.beams(msg), (0.12, 4.0, clear_to))
        assert layers[0].grid is not None and layers[1].grid is not None
        np.testing.assert_array_equal(layers[1].grid.data, layers[0].grid.data, err_msg=f"trial {trial}")
        marked += int((layers[0].grid.data == COST_LETHAL).sum())
        cleared += int((layers[0].grid.data == 0).sum())
    assert marked > 1000 and cleared > 10000  # the scans did mark and clear


def test_ray_clearing_writes_the_cells_of_the_plain_walk() -> None:
    """Rays are walked without per-cell bounds checks (up to where they leave the grid, found beforehand): the same
    cells as the plain walk (cut to max_cells, stopped where it leaves the grid, min_cells kept), rays in and out of
    it, on C- and Fortran-ordered grids."""
    from navlab.gridline import TIE_LATE, line, line_cell
    from navlab.navigation.costmap.raytrace import clear_rays

    rng = np.random.default_rng(5)
    for trial in range(12):
        data = np.zeros((40, 50), np.uint8, order="F" if trial % 3 == 2 else "C")
        x0, y0 = rng.uniform(0, 50), rng.uniform(0, 40)
        ends = np.column_stack([rng.uniform(-20, 70, 60), rng.uniform(-20, 60, 60)])
        min_cells = 0.0 if trial % 2 == 0 else 3.0
        clear_rays(data, x0, y0, ends, 30.0, min_cells, np.uint8(7))
        plain = np.zeros_like(data)
        i0, j0 = math.floor(x0), math.floor(y0)
        for ex, ey in ends:
            dx, dy = ex - x0, ey - y0
            length = math.sqrt(dx * dx + dy * dy)
            if length > 30.0:
                ex, ey = x0 + dx * (30.0 / length), y0 + dy * (30.0 / length)
            ln = line(i0, j0, math.floor(ex), math.floor(ey), TIE_LATE)
            for n in range(ln[0] + 1):
                i, j = line_cell(ln, n)
                if not (0 <= i < 50 and 0 <= j < 40):
                    break
                if (i - i0) ** 2 + (j - j0) ** 2 >= min_cells**2:
                    plain[j, i] = 7
        np.testing.assert_array_equal(data, plain, err_msg=f"trial {trial}")
