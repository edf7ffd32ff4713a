"""navlab.pcg64's compiled permutations are NumPy's, bit for bit, and leave the generator where NumPy's calls would."""

from __future__ import annotations

import copy

import numpy as np

from navlab.pcg64 import Draws


def test_permutations_are_numpys_and_keep_the_generator_in_step() -> None:
    for seed in range(5):
        gen = np.random.default_rng(seed)
        ref = copy.deepcopy(gen)
        draws = Draws(gen)
        assert draws.compiled
        for n in (5000, 4999, 301, 2, 1, 0):  # odd and even counts of 32-bit draws: the spare half carries over
            assert np.array_equal(draws.permutation(n), ref.permutation(n))
            assert gen.standard_normal(3).tobytes() == ref.standard_normal(3).tobytes()
            assert gen.random() == ref.random()  # NumPy's own draws in between stay in step
        assert gen.bit_generator.state == ref.bit_generator.state


def test_another_bit_generator_draws_with_numpy() -> None:
    draws = Draws(np.random.Generator(np.random.Philox(5)))
    ref = np.random.Generator(np.random.Philox(5))
    assert not draws.compiled
    assert np.array_equal(draws.permutation(50), ref.permutation(50))
