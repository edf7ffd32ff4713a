"""Running an executor for a while from the command line: progress bar, optional recording."""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
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
) -> Path | None:
    """Run ``ex`` for ``duration`` simulated seconds, showing progress in simulated time.

    With ``record``, every (or each chosen) topic is written to a rosbag2 (MCAP) there; its path is
    returned. Stops early if the executor is stopped.
    """
    from navlab.core.record import Recorder

    recorder = Recorder(ex, record, topics=record_topics) if record else None
    bar = tqdm(
        total=None if math.isinf(duration) else round(duration, 3), unit="sim s", desc=desc, file=sys.stderr,
        disable=quiet or not sys.stderr.isatty(),
        bar_format="{desc}: {n:.1f} sim s [{rate_fmt}]" if math.isinf(duration)
        else "{l_bar}{bar}| {n:.1f}/{total:.1f} sim s [{rate_fmt}]",
    )
    try:
        done = 0.0
        while done < duration - 1e-9:
            step = min(chunk, duration - done)
            t0 = ex.now_ns
            ex.run(step)
            done += step
            bar.update((ex.now_ns - t0) / 1e9)
            if ex.stopped:
                break
    finally:
        bar.close()
        path = recorder.close() if recorder else None
    return path


def positive_seconds(text: str) -> float:
    """argparse ``type=`` for a duration in simulated seconds: a finite number > 0."""
    import argparse
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a duration > 0 s, got {text}")
    return value


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
