"""The local planners' faster kernels give exactly what the plain ones give (scores, distance maps)."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from navlab.navigation.controllers import mapgrid, ring_bounds
from navlab.navigation.controllers.common import circle_footprint, footprint_outline
from navlab.navigation.controllers.rollout import integrate_rollouts, rollout_scores

RES = 0.05


def _inflated(rng: np.random.Generator, shape: tuple[int, int]) -> np.ndarray:
    """Costs as an inflated costmap has them: LETHAL obstacles, INSCRIBED around them, decaying costs beyond, a
    few unknown cells."""
    lethal = rng.random(shape) < 0.004
    d = ndimage.distance_transform_edt(~lethal) * RES
    cost = np.where(d <= 0.2, 253, np.floor(252 * np.exp(-5.0 * (d - 0.2)))).astype(np.uint8)
    cost[lethal] = 254
    cost[rng.random(shape) < 0.002] = 255
    return cost


def test_ring_scores_equal_every_pose_checked() -> None:
    """TrajectoryPlanner's scores with ring bounds are bit for bit those of checking every pose's footprint, for a
    round and a square robot and a point robot, distances at every pose, at one step or at none, near obstacles and
    the map's edge, rollouts that stop and turn on one spot among them."""
    rng = np.random.default_rng(7)
    square = np.array([[0.25, 0.2], [-0.2, 0.2], [-0.2, -0.2], [0.25, -0.2]])
    seen: set[tuple[bool, float]] = set()
    memo = ring_bounds.new_memo((70, 80))
    for trial in range(40):
        epoch = trial + 1
        cost = _inflated(rng, (70, 80))
        h, w = cost.shape
        x0, y0 = rng.uniform(-0.2, w * RES + 0.2), rng.uniform(-0.2, h * RES + 0.2)  # sometimes off the map
        if trial % 4 == 0:  # walled in: cells no wave from outside reaches
            i0, j0 = int(x0 / RES) - 12, int(y0 / RES) - 12
            cost[max(j0, 0) : j0 + 25, max(i0, 0) : i0 + 25] = 0
            cost[max(j0, 0) : j0 + 25, max(i0, 0) : i0 + 25][[0, -1], :] = 254
            cost[max(j0, 0) : j0 + 25, max(i0, 0) : i0 + 25][:, [0, -1]] = 254
        seeds = np.column_stack([rng.integers(0, w, 6), rng.integers(0, h, 6)])
        path = mapgrid.distance_map(cost, seeds)
        goal_cell = np.array([[rng.integers(0, w), rng.integers(0, h)]])
        goal = mapgrid.distance_map(cost, goal_cell)
        polygon = trial % 3 != 2  # else a point robot
        outline = footprint_outline(circle_footprint(0.21) if trial % 3 else square, RES)
        assert outline is not None
        ox, oy = np.ascontiguousarray(outline[:, 0]), np.ascontiguousarray(outline[:, 1])
        n, steps = 60, 40
        targets = np.column_stack([rng.uniform(-0.2, 0.6, n), rng.uniform(-1.5, 1.5, n)])
        targets[::4, 0] = 0.0  # these stop, then turn on one spot (the FINE bound's case)
        counts = rng.integers(1, steps + 1, n)
        traj = np.empty((n, steps, 3))
        c, s = np.empty((n, steps)), np.empty((n, steps))
        integrate_rollouts(x0, y0, rng.uniform(-3, 3), 0.2, 0.0, targets, counts, 1.7, 2.5, 3.2, True, traj, c, s)
        weights = np.array([0.05, 0.6, 0.8, 0.01])
        offsets, ring_counts = ring_bounds.ring_offsets(outline, RES)
        for at in (-1, 5, -2):  # the memo kept while the costs stay, forgotten (a new epoch) when they change
            ats = np.full(n, at, dtype=np.int64)
            want, got = np.empty(n), np.empty(n)
            args = (1.0 / RES, traj, c, s, ox, oy)
            scoring = (polygon, weights, float(h * w), ats)
            rollout_scores(cost, cost, path, goal, *args, polygon, False, *scoring[1:], want)
            none = np.zeros(0, np.int64)
            waves = [mapgrid.wave_start(cost, z[:, 0].copy(), z[:, 1].copy(), none, none) for z in (seeds, goal_cell)]
            ring_bounds.ring_scores(cost, memo, epoch, offsets, ring_counts, *waves, *args, *scoring, got)
            np.testing.assert_array_equal(got.view(np.int64), want.view(np.int64))
            seen |= {(polygon, float(v)) for v in np.minimum(want, 0.0)}
        # the same rollouts on raised costs (the same distances): the memo of the old costs must not be read
        raised = np.where(cost < 253, np.minimum(cost.astype(np.int64) + 60, 252), cost).astype(np.uint8)
        ats = np.full(n, -1, dtype=np.int64)
        rollout_scores(raised, raised, path, goal, *args, polygon, False, *scoring[1:3], ats, want)
        waves = [mapgrid.wave_start(raised, z[:, 0].copy(), z[:, 1].copy(), none, none) for z in (seeds, goal_cell)]
        ring_bounds.ring_scores(raised, memo, epoch + 1000, offsets, ring_counts, *waves, *args, *scoring[:3], ats, got)
        np.testing.assert_array_equal(got.view(np.int64), want.view(np.int64))
    assert seen == {(p, v) for p in (True, False) for v in (-2.0, -1.0, 0.0)}  # every outcome, for both kinds


def test_a_wave_grown_in_part_reads_as_the_whole() -> None:
    """Path distances looked up cell by cell from a wave grown only as far as each lookup needs equal the whole
    distance map (obstacles, cells kept free, cells no wave reaches)."""
    rng = np.random.default_rng(3)
    for _ in range(20):
        cost = np.where(rng.random((40, 50)) < 0.25, 254, 0).astype(np.uint8)
        seeds = np.column_stack([rng.integers(0, 50, 3), rng.integers(0, 40, 3)])
        free = np.column_stack([rng.integers(0, 50, 4), rng.integers(0, 40, 4)])
        whole = mapgrid.distance_map(cost, seeds, free)
        wave = mapgrid.wave_start(cost, seeds[:, 0].copy(), seeds[:, 1].copy(), free[:, 0].copy(), free[:, 1].copy())
        for k in rng.permutation(cost.size):
            j, i = divmod(int(k), 50)
            assert mapgrid.wave_to(cost, wave, i, j) == whole[j, i]
        assert (whole == cost.size + 1).any() and (whole == cost.size).any()
