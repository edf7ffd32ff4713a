"""Gaussian sensor noise in compiled loops: Marsaglia and Tsang's ziggurat (2000) over a SplitMix64 stream.

A frame's noise is drawn from one 64-bit seed taken from the sensor's ``numpy.random.Generator``, so a run stays
seeded (same seed, same noise, bit for bit) while the per-pixel draws cost a few ns inside the sensor's kernel
instead of a separate numpy pass. 128 layers; the layer index and the value come from independent bits.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, uint64

_R = 3.442619855899  # start of the tail
_V = 9.91256303526217e-3  # area of each layer


def _tables() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    kn = np.zeros(128, dtype=np.int64)
    wn = np.zeros(128)
    fn = np.zeros(128)
    m1 = 2147483648.0
    dn = tn = _R
    q = _V / math.exp(-0.5 * dn * dn)
    kn[0] = int((dn / q) * m1)
    kn[1] = 0
    wn[0] = q / m1
    wn[127] = dn / m1
    fn[0] = 1.0
    fn[127] = math.exp(-0.5 * dn * dn)
    for i in range(126, 0, -1):
        dn = math.sqrt(-2.0 * math.log(_V / dn + math.exp(-0.5 * dn * dn)))
        kn[i + 1] = int((dn / tn) * m1)
        tn = dn
        fn[i] = math.exp(-0.5 * dn * dn)
        wn[i] = dn / m1
    for t in (kn, wn, fn):
        t.flags.writeable = False
    return kn, wn, fn


KN, WN, FN = _tables()

_GOLDEN = uint64(0x9E3779B97F4A7C15)
_MIX1 = uint64(0xBF58476D1CE4E5B9)
_MIX2 = uint64(0x94D049BB133111EB)


@njit(cache=True, inline="always")
def mix(z: np.uint64) -> np.uint64:
    """SplitMix64's output function of a state ``z`` (the stream's state steps by the golden gamma)."""
    z = (z ^ (z >> uint64(30))) * _MIX1
    z = (z ^ (z >> uint64(27))) * _MIX2
    return z ^ (z >> uint64(31))


@njit(cache=True, inline="always")
def _uniform(z: np.uint64) -> float:
    """Uniform in (0, 1) from the state ``z``."""
    return (float(mix(z) >> uint64(11)) + 0.5) * (1.0 / 9007199254740992.0)


@njit(cache=True, inline="always")
def _layer(bits: np.uint64) -> tuple[np.int64, int]:
    """(the signed 32-bit value, the layer index) of a draw: independent bits (high half, low 7 bits)."""
    return np.int64(np.int32(np.uint32(bits >> uint64(32)))), int(bits & uint64(127))


@njit(cache=True)
def _tail_or_wedge(z: np.uint64, hz: np.int64, iz: int) -> tuple[float, np.uint64]:
    while True:
        x = hz * WN[iz]
        if iz == 0:  # the tail beyond R
            while True:
                z += _GOLDEN
                x = -math.log(_uniform(z)) / _R
                z += _GOLDEN
                y = -math.log(_uniform(z))
                if y + y >= x * x:
                    break
            return (_R + x if hz > 0 else -_R - x), z
        z += _GOLDEN
        if FN[iz] + _uniform(z) * (FN[iz - 1] - FN[iz]) < math.exp(-0.5 * x * x):
            return x, z
        z += _GOLDEN
        hz, iz = _layer(mix(z))
        if abs(hz) < KN[iz]:
            return hz * WN[iz], z


@njit(cache=True, inline="always")
def normal(z: np.uint64) -> tuple[float, np.uint64]:
    """(a standard normal draw, the stream's next state) from the SplitMix64 state ``z``."""
    z += _GOLDEN
    hz, iz = _layer(mix(z))
    if abs(hz) < KN[iz]:
        return hz * WN[iz], z
    return _tail_or_wedge(z, hz, iz)


def seed_state(rng: np.random.Generator) -> np.uint64:
    """A fresh stream state seeded from ``rng`` (one 64-bit draw)."""
    return np.uint64(rng.integers(0, 2**63, dtype=np.int64))


@njit(cache=True)
def fill_normal(seed: np.uint64, out: np.ndarray) -> None:
    """``out`` (1-D) = standard normal draws in order from the stream seeded with ``seed`` (a numpy uint64)."""
    z = uint64(seed)
    for i in range(out.shape[0]):
        out[i], z = normal(z)
