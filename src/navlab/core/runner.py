"""Running an executor for a while from the command line: progress bar, optional recording."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from tqdm import tqdm

from navlab.core.executor import Executor


def run_for(
    ex: Executor,
    duration: float,
    *,
    record: str | Path | None = None,
    record_topics: Sequence[str] = (),
    quiet: bool = False,
    chunk: float = 0.5,
    desc: str = "sim",
    until: Callable[[], bool] | None = None,
) -> Path | None:
    """Run ``ex`` for ``duration`` simulated seconds, showing progress in simulated time.

    With ``record``, every (or each chosen) topic is written to a rosbag2 (MCAP) there; its path is
    returned. Stops early if the executor is stopped or ``until()`` becomes true (checked after each event).
    """
    from navlab.core.record import Recorder

    recorder = Recorder(ex, record, topics=record_topics) if record else None
    bar = tqdm(
        total=None if math.isinf(duration) else round(duration, 3),
        unit="sim s",
        desc=desc,
        file=sys.stderr,
        disable=quiet or not sys.stderr.isatty(),
        bar_format="{desc}: {n:.1f} sim s [{rate_fmt}]"
        if math.isinf(duration)
        else "{l_bar}{bar}| {n:.1f}/{total:.1f} sim s [{rate_fmt}]",
    )
    try:
        done = 0.0
        while done < duration - 1e-9:
            step = min(chunk, duration - done)
            t0 = ex.now_ns
            reached = False
            if until is not None:
                reached = ex.run_until(until, timeout=step)
            else:
                ex.run(step)
            done += (ex.now_ns - t0) / 1e9 if reached else step
            bar.update((ex.now_ns - t0) / 1e9)
            if reached or ex.stopped:
                if not math.isinf(duration):  # the bar ends where the run ended, not at the limit
                    bar.total = round(bar.n, 3)
                    bar.refresh()
                break
    except KeyboardInterrupt as exc:  # the recording is closed below: whole up to now
        if recorder is not None:
            exc.add_note(f"the recording {recorder.path} is closed, whole up to {ex.now_ns / 1e9:.1f} simulated s")
        raise
    finally:
        bar.close()
        path = recorder.close() if recorder else None
    return path


def parse_launch_args(items: Sequence[str]) -> dict[str, str]:
    """``name:=value`` command-line items to a dict (ROS's launch argument syntax)."""
    from navlab.core.errors import LaunchError

    out = {}
    for item in items:
        name, sep, value = item.partition(":=")
        if not sep or not name:
            raise LaunchError(f"launch argument {item!r}: expected name:=value")
        out[name] = value
    return out
