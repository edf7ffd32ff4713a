"""A lidar's Gaussian noise draws: NumPy's own ``Generator.standard_normal`` values, drawn in a compiled loop.

Gazebo's lidar noise is one standard normal per beam from the sensor's ``numpy.random.Generator``. NumPy draws
them with O'Neill's PCG64 (the XSL-RR output of a 128-bit LCG) and Marsaglia and Tsang's 256-layer ziggurat; for
720 beams that costs ~12 µs a scan, mostly a mispredicted sign branch. :class:`NormalDraws` runs the same two
algorithms, with NumPy's ziggurat tables, on the generator's own state (a view of its memory, so the generator
stays in step with every draw made here): the same values bit for bit in ~3 µs. Whenever it cannot be sure of that
(another bit generator, a NumPy whose PCG64 state is laid out differently, the tables missing), or when a check
draw against NumPy disagrees, it draws with NumPy itself.
"""

from __future__ import annotations

import copy
import ctypes
import sys
from typing import Any

import numpy as np
from llvmlite import ir  # type: ignore[import-untyped]
from numba import njit, types
from numba.extending import intrinsic

try:  # NumPy's ziggurat tables, as Numba ships them for its own Generator support (the same values)
    from numba.np.random._constants import fi_double, ki_double, wi_double, ziggurat_nor_inv_r, ziggurat_nor_r
except ImportError:  # pragma: no cover - another Numba: NumPy draws
    _TABLES = None
else:
    _TABLES = (
        np.ascontiguousarray(ki_double, dtype=np.uint64),
        np.ascontiguousarray(wi_double, dtype=np.float64),
        np.ascontiguousarray(fi_double, dtype=np.float64),
    )

PCG64_MULT = 0x2360ED051FC65DA44385DF649FCCF645  # PCG's default 128-bit LCG multiplier (NumPy's PCG64)
CHECK_DRAWS = 4096  # draws compared with NumPy's before a generator is trusted to the compiled loop


def _lcg_step_typer(typingctx: Any, hi: Any, lo: Any, inc_hi: Any, inc_lo: Any) -> Any:
    """(hi, lo) 64-bit halves of ``state * PCG64_MULT + inc`` modulo 2**128 (LLVM's 128-bit integers)."""
    sig = types.UniTuple(types.uint64, 2)(types.uint64, types.uint64, types.uint64, types.uint64)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:  # pragma: no cover - compiled
        i64, i128 = ir.IntType(64), ir.IntType(128)
        sixty_four = ir.Constant(i128, 64)

        def join(h: Any, lo_: Any) -> Any:
            return builder.or_(builder.shl(builder.zext(h, i128), sixty_four), builder.zext(lo_, i128))

        s = builder.add(builder.mul(join(args[0], args[1]), ir.Constant(i128, PCG64_MULT)), join(args[2], args[3]))
        new = (builder.trunc(builder.lshr(s, sixty_four), i64), builder.trunc(s, i64))
        return context.make_tuple(builder, signature.return_type, new)

    return sig, codegen


_lcg_step: Any = intrinsic(_lcg_step_typer)


@njit(cache=True, inline="always")
def _next64(st: np.ndarray) -> np.uint64:  # pragma: no cover - compiled
    """PCG64's next 64-bit output; ``st`` = (state low, state high, inc low, inc high) words, advanced in place."""
    hi, lo = _lcg_step(st[1], st[0], st[3], st[2])
    st[0] = lo
    st[1] = hi
    rot = hi >> np.uint64(58)
    x = hi ^ lo
    return (x >> rot) | (x << ((np.uint64(64) - rot) & np.uint64(63)))


@njit(cache=True, inline="always")
def _next_double(st: np.ndarray) -> float:  # pragma: no cover - compiled
    """A double in [0, 1) from the top 53 bits of the next output (NumPy's ``next_double``)."""
    return np.float64(_next64(st) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True)
def fill_standard_normal(
    st: np.ndarray, ki: np.ndarray, wi: np.ndarray, fi: np.ndarray, r: float, inv_r: float, out: np.ndarray
) -> None:  # pragma: no cover - compiled
    """``out[:] = standard normals`` as NumPy's ``random_standard_normal`` draws them from PCG64 state ``st``
    (see :func:`_next64`); ``ki``, ``wi``, ``fi``: its ziggurat tables, ``r`` and ``inv_r`` its tail start."""
    mask52 = np.uint64(0x000FFFFFFFFFFFFF)
    one = np.uint64(1)
    for i in range(out.shape[0]):
        while True:
            bits = _next64(st)
            idx = np.intp(bits & np.uint64(0xFF))
            bits >>= np.uint64(8)
            rabs = (bits >> one) & mask52
            x = np.float64(rabs) * wi[idx]
            if bits & one:
                x = -x
            if rabs < ki[idx]:
                out[i] = x
                break
            if idx == 0:  # the tail beyond r
                while True:
                    xx = -inv_r * np.log1p(-_next_double(st))
                    yy = -np.log1p(-_next_double(st))
                    if yy + yy > xx * xx:
                        break
                out[i] = -(r + xx) if (rabs >> np.uint64(8)) & one else r + xx
                break
            if (fi[idx - 1] - fi[idx]) * _next_double(st) + fi[idx] < np.exp(-0.5 * x * x):
                out[i] = x
                break


def _pcg64_words(gen: np.random.Generator) -> np.ndarray | None:
    """The generator's PCG64 state as a writable uint64[4] view of its own memory (state low, state high, inc low,
    inc high), or None unless it is NumPy's PCG64 with that layout (checked against its ``state``)."""
    bg = gen.bit_generator
    if type(bg) is not np.random.PCG64 or sys.byteorder != "little":
        return None
    # NumPy's pcg64_state starts with a pointer to {__uint128_t state; __uint128_t inc}
    address = ctypes.c_void_p.from_address(bg.ctypes.state_address).value
    if not address:
        return None
    words = np.ctypeslib.as_array((ctypes.c_uint64 * 4).from_address(address))
    s = bg.state["state"]
    mask = (1 << 64) - 1
    want = (s["state"] & mask, s["state"] >> 64, s["inc"] & mask, s["inc"] >> 64)
    return words if tuple(int(w) for w in words) == want else None


class NormalDraws:
    """Standard normal draws from ``gen`` into a buffer of ``n``: ``draw()`` returns what
    ``gen.standard_normal(n)`` would (bit for bit, leaving ``gen`` in the same state), compiled when it can."""

    def __init__(self, gen: np.random.Generator, n: int) -> None:
        self.gen = gen
        self.buf = np.empty(n)
        self._words = self._checked_words(gen)
        self._tables = _TABLES if _TABLES is not None else (np.zeros(0, np.uint64), np.zeros(0), np.zeros(0))

    @staticmethod
    def _checked_words(gen: np.random.Generator) -> np.ndarray | None:
        """:func:`_pcg64_words` of ``gen`` if the compiled loop gives NumPy's draws on a copy of it, else None."""
        if _TABLES is None or _pcg64_words(gen) is None:
            return None
        a, b = copy.deepcopy(gen), copy.deepcopy(gen)
        words = _pcg64_words(b)
        if words is None:
            return None
        mine = np.empty(CHECK_DRAWS)
        ki, wi, fi = _TABLES
        fill_standard_normal(words, ki, wi, fi, float(ziggurat_nor_r), float(ziggurat_nor_inv_r), mine)
        same = np.array_equal(a.standard_normal(CHECK_DRAWS).view(np.uint64), mine.view(np.uint64))
        return _pcg64_words(gen) if same and a.bit_generator.state == b.bit_generator.state else None

    @property
    def compiled(self) -> bool:
        """Whether the draws run in the compiled loop (else NumPy's ``standard_normal``)."""
        return self._words is not None

    def draw(self) -> np.ndarray:
        """The next ``n`` standard normals (the buffer, overwritten by the next call)."""
        if self._words is None:
            return self.gen.standard_normal(out=self.buf)
        ki, wi, fi = self._tables
        fill_standard_normal(self._words, ki, wi, fi, ziggurat_nor_r, ziggurat_nor_inv_r, self.buf)
        return self.buf
