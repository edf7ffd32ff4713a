"""amcl's map distance field: the compiled transform gives scipy's Euclidean distance transform, bit for bit."""

from __future__ import annotations

import numpy as np
from scipy.ndimage import distance_transform_edt

from navlab.localization.field import distance_to


def test_distance_to_is_scipys_edt_bit_for_bit() -> None:
    rng = np.random.default_rng(3)
    for density in (0.002, 0.05, 0.5, 0.95):  # lone obstacles to almost full: long and short envelopes
        for h, w in ((1, 1), (1, 37), (41, 1), (63, 80)):
            features = rng.random((h, w)) < density
            features.flat[rng.integers(h * w)] = True  # at least one
            assert distance_to(features).tobytes() == distance_transform_edt(~features).tobytes()
