"""SLAM maps sized to what was seen: GMapping's maps start at the first scan and grow without moving a
cell (same result as one huge map), and saved maps are cropped to the known area."""

from __future__ import annotations

import numpy as np
import pytest

from navlab.mapping import gmapping, load_map, save_map
from navlab.mapping.gmapping import GMapping, GMappingParams
from navlab.mapping.occupancy import scan_cells


def _run(world, odometry_noise, *, n: int = 230, seed: int = 3, **params) -> tuple[GMapping, np.ndarray]:
    rng = np.random.default_rng(11)
    gt = world.route()[:n]
    odo = odometry_noise(gt, rng)
    p = GMappingParams(particles=8, linearUpdate=0.3, angularUpdate=0.2, **params)
    g = GMapping(p, rng=np.random.default_rng(seed))
    for p_true, p_odo in zip(gt, odo, strict=True):
        g.add_scan(world.scan(p_true, rng), world.angle_min, world.angle_increment, p_odo)
    return g, g.finish()


def test_growing_map_gives_the_same_result_as_one_allocated_huge(synth_world, odometry_noise, monkeypatch):
    # beams cut at 1.5 m: the map must grow as the robot drives around the 8 m x 6 m room
    short = {"maxUrange": 1.5, "maxRange": 30.0}
    grown, poses = _run(synth_world, odometry_noise, **short)
    assert 1 <= grown.map_resizes <= 8  # grown by at least half each time, not scan by scan
    monkeypatch.setattr(gmapping, "MAP_MARGIN_CELLS", 700)  # 35 m of margin: never grows
    huge, poses_huge = _run(synth_world, odometry_noise, **short)
    assert huge.map_resizes == 0
    np.testing.assert_array_equal(poses, poses_huge)
    small, big = grown.map(), huge.map()
    assert big.data.size > 10 * small.data.size
    # every cell sits where it sits in the huge map, with the same value; the huge map knows no more
    centres = small.centers(np.ones(small.data.shape, bool))
    np.testing.assert_array_equal(big.value_at(centres), small.data.ravel())
    assert (big.data >= 0).sum() == (small.data >= 0).sum()


def test_map_starts_at_the_first_scan_and_ends_near_the_room(synth_world, odometry_noise):
    g, _ = _run(synth_world, odometry_noise, n=1)
    first = g.map()
    margin = gmapping.MAP_MARGIN_CELLS * first.resolution
    x0, y0, x1, y1 = first.bounds()
    kx0, ky0, kx1, ky1 = first.known_bounds(margin=0.0)
    assert (kx0 - x0, ky0 - y0, x1 - kx1, y1 - ky1) == pytest.approx((margin,) * 4, abs=0.06)
    g, _ = _run(synth_world, odometry_noise)
    grid = g.map()
    # the room is 8 m x 6 m; the map holds it plus the margin (was 24 m x 24 m allocated up front)
    assert grid.width * grid.resolution < 8 + 2 * margin + 1.0
    assert grid.height * grid.resolution < 6 + 2 * margin + 1.0
    kx0, ky0, kx1, ky1 = grid.known_bounds(margin=0.0)
    assert kx0 < 0.1 and ky0 < 0.1 and kx1 > 7.9 and ky1 > 5.9


def test_scan_cells_cover_what_the_ray_caster_touches():
    from navlab.mapping.occupancy import integrate_scan

    rng = np.random.default_rng(0)
    ranges = rng.uniform(0.2, 12.0, 90)
    ranges[::7] = 40.0  # no returns: ignored
    ranges[::11] = 9.5  # beyond max_urange: clear 5 m only
    angles = np.linspace(-np.pi, np.pi, 90, endpoint=False)
    pose = np.array([0.3, -0.2, 0.4])
    logodds = np.zeros((600, 600))
    integrate_scan(logodds, (-15.0, -15.0), 0.05, pose, ranges, angles, max_urange=8.0, max_range=30.0)
    jj, ii = np.nonzero(logodds)
    lo, hi = scan_cells(pose, ranges, angles, (-15.0, -15.0), 0.05, max_urange=8.0, max_range=30.0)
    # a superset, tight to one cell (a beam cut at max_urange clears up to, not including, its end cell)
    assert np.all(lo <= [ii.min(), jj.min()]) and np.all(lo >= [ii.min() - 1, jj.min() - 1])
    assert np.all(hi >= [ii.max(), jj.max()]) and np.all(hi <= [ii.max() + 1, jj.max() + 1])


def test_slam_map_saves_cropped_to_what_was_seen(synth_world, odometry_noise, tmp_path):
    g, _ = _run(synth_world, odometry_noise, n=60)
    grid = g.map()
    save_map(grid, tmp_path / "m.yaml")
    saved = load_map(tmp_path / "m.yaml")
    jj, ii = np.nonzero(grid.data >= 0)
    assert (saved.width, saved.height) == (ii.max() - ii.min() + 21, jj.max() - jj.min() + 21)
    assert (saved.data < 0).mean() < 0.5
    # free and occupied cells are still free and occupied, at the same place
    np.testing.assert_array_equal(saved.value_at(grid.centers(grid.free_mask())), 0)
    np.testing.assert_array_equal(saved.value_at(grid.centers(grid.occupied_mask())), 100)


def test_resampled_maps_share_their_tiles_and_reference_counts_hold(
    synth_world, odometry_noise, monkeypatch, masks_hold
):
    # copy-on-write maps: after every update, particles drawn from one source hold the same tiles, every
    # tile's reference count is the number of tables holding it, and a tile is written by nobody else
    update = GMapping._update
    checked = {"resampled": 0, "grown": 0}

    def checking(self: GMapping, *args: object) -> None:
        resamples, resizes = self.resamples, self.map_resizes
        update(self, *args)
        tables = [part.table for part in self.particles]
        counts = np.bincount(np.concatenate([t.ravel() for t in tables]), minlength=len(self.pool.refs))
        np.testing.assert_array_equal(self.pool.refs[1:], counts[1:])
        assert not self.pool.tiles[0].any()  # the unknown tile
        masks_hold(self.pool, tables)  # (the matcher's occupied-with-free-behind bits follow the cells)
        checked["grown"] += self.map_resizes > resizes
        if self.resamples > resamples:
            checked["resampled"] += 1
            for a in range(len(self.particles)):
                for b in range(a):
                    if np.array_equal(self.poses[a], self.poses[b]):  # drawn from the same particle
                        np.testing.assert_array_equal(self.particles[a].table, self.particles[b].table)

    monkeypatch.setattr(GMapping, "_update", checking)
    _run(synth_world, odometry_noise, maxUrange=1.5, maxRange=30.0)
    assert checked["resampled"] >= 3 and checked["grown"] >= 1, checked
