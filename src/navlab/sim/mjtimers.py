"""MuJoCo's profiling timers (``MjData.timer``), off while navlab steps its simulations.

MuJoCo times each stage of a step through its global ``mjcb_time`` callback, and the Python bindings install a
native clock there by default: ~28 clock reads a step, ~12 % of a step of navlab's robots (5.3 µs instead of
6.1 µs, measured on ``navlab bench nav``'s run), spent on figures navlab never reads. Turning them off changes no
result, bit for bit (the clock feeds only ``MjData.timer``). A callback the user set with
``mujoco.set_mjcb_time`` is left alone, and setting one afterwards turns the timers back on.
"""

from __future__ import annotations

import ctypes
from pathlib import Path

import mujoco

_LIBRARY_GLOBS = ("libmujoco.so*", "libmujoco*.dylib", "mujoco.dll")


def profiling_timers_off() -> bool:
    """Clear MuJoCo's ``mjcb_time`` when it holds the bindings' default clock (no Python callback set); returns
    whether the timers are off now. Where the library cannot be found, nothing changes (the timers stay on)."""
    if mujoco.get_mjcb_time() is not None:  # the user's own callback: their timers, keep them
        return False
    pointer = _mjcb_time()
    if pointer is None:
        return False
    pointer.value = None
    return True


def _mjcb_time() -> ctypes.c_void_p | None:
    """MuJoCo's global ``mjcb_time`` in the library the bindings loaded (the same file: the same global)."""
    folder = Path(mujoco.__file__).parent
    for pattern in _LIBRARY_GLOBS:
        for path in sorted(folder.glob(pattern)):
            try:
                return ctypes.c_void_p.in_dll(ctypes.CDLL(str(path)), "mjcb_time")
            except (OSError, ValueError):
                continue
    return None
