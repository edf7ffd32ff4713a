"""navfn's bucketed wave gives the single heap's potentials bit for bit (only the order among equal keys differs)."""

from __future__ import annotations

import numpy as np

from navlab.navigation.planners.navfn import _propagate
from navlab.navigation.planners.navfn_wave import propagate


def test_bucketed_wave_equals_the_heap_on_random_maps_with_ties() -> None:
    """Random costmaps with lethal and unknown cells, integer cost tables (many equal keys), with and without the
    stop at the goal: the potential and the settled count are the heap's, bit for bit."""
    rng = np.random.default_rng(3)
    levels = np.array([0, 0, 0, 0, 10, 100, 200, 252, 253, 254, 255], np.uint8)
    for t in range(120):
        h, w = (int(x) for x in rng.integers(2, 60, 2))
        data = np.zeros((h, w), np.uint8) if t % 3 == 0 else rng.choice(levels, size=(h, w))
        table = np.minimum(np.round(rng.uniform(1, 300)) + (t % 4) * np.arange(256.0), 253.0 if t % 2 else 900.0)
        table[253:255] = np.inf
        start, goal = (int(x) for x in rng.integers(h * w, size=2))
        stop = t % 5 != 0
        margin = 4.0 * float(table[0])
        want, want_n = _propagate(data, table, start, goal, False, 1.0, stop, margin)
        got, got_n = propagate(data, table, start, goal, stop, margin)
        assert got_n == want_n
        assert got.tobytes() == want.tobytes()
    assert (np.isfinite(got) == np.isfinite(want)).all()


def test_a_cost_table_with_dear_cells_keeps_every_key_inside_the_ring() -> None:
    """The ring's width follows the dearest cell: a 5000-per-cell band is crossed in the heap's order."""
    data = np.zeros((30, 40), np.uint8)
    data[:, 20] = 200
    table = np.ones(256)
    table[200] = 5000.0
    table[253:] = np.inf
    want, _ = _propagate(data, table, 5 * 40 + 2, 25 * 40 + 37, False, 1.0, False, 4.0)
    got, _ = propagate(data, table, 5 * 40 + 2, 25 * 40 + 37, False, 4.0)
    assert got.tobytes() == want.tobytes()
    assert np.isfinite(got).all()
