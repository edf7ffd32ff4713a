"""``navlab bench core``: executor throughput for 10 nodes exchanging small messages at 1 kHz."""

from __future__ import annotations

import argparse
import time
from typing import Any

from navlab.core import Executor, Node
from navlab.msgs import Float64


class _Relay(Node):
    """Publishes on its own topic at 1 kHz and listens to the next node's topic."""

    def __init__(self, executor: Executor, index: int, n: int) -> None:
        super().__init__(executor, name=f"relay_{index}")
        self.received = 0
        self.pub = self.create_publisher(Float64, f"chain_{index}", 10)
        self.create_subscription(Float64, f"chain_{(index + 1) % n}", self._on_msg, 10)
        self.create_timer(0.001, self._tick)

    def _tick(self) -> None:
        self.pub.publish(Float64(data=1.0))

    def _on_msg(self, msg: Any) -> None:
        self.received += 1


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Events per wall second over 10 simulated seconds, and the cost of one publish."""
    ex = Executor(seed=getattr(args, "seed", 0))
    nodes = [_Relay(ex, i, 10) for i in range(10)]
    ex.run(0.1)  # warm up
    events0, t0 = ex.events, time.perf_counter()
    ex.run(10.0)
    wall = time.perf_counter() - t0
    events = ex.events - events0
    pub = nodes[0].pub
    msg = Float64(data=2.0)
    n = 100_000
    t1 = time.perf_counter()
    for _ in range(n):
        pub.publish(msg)
    publish_us = (time.perf_counter() - t1) / n * 1e6  # includes delivery to the subscriber (not running)
    return {
        "events_per_s": round(events / wall),
        "publish_us": round(publish_us, 3),
        "nodes": 10,
        "rate_hz": 1000,
        "sim_s": 10.0,
        "events": events,
        "wall_s": round(wall, 3),
    }


def _rss_mb() -> float:
    """Resident set size of this process (MB, from /proc/self/status)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def run_soak(args: argparse.Namespace) -> dict[str, Any]:
    """``navlab bench soak``: a mapping launch (sim + slam_gmapping + exploration) for ``--minutes`` simulated
    minutes; RSS (MB) after the first simulated minute and at the end, and every 10 minutes between."""
    import gc

    from navlab.core import start

    minutes = float(getattr(args, "minutes", None) or 60.0)
    session = start("mapping", seed=getattr(args, "seed", 0))
    t0 = time.perf_counter()
    samples: dict[str, float] = {}
    for minute in range(1, int(minutes) + 1):
        session.run(60.0)
        if minute == 1 or minute % 10 == 0 or minute == int(minutes):
            gc.collect()
            samples[str(minute)] = round(_rss_mb(), 1)
    first, last = samples["1"], samples[str(int(minutes))]
    return {
        "sim_min": int(minutes),
        "rss_mb_after_1_min": first,
        "rss_mb_end": last,
        "growth_mb": round(last - first, 1),
        "rss_mb_by_minute": samples,
        "wall_s": round(time.perf_counter() - t0, 1),
    }


def run_child(cmd: list[str]) -> dict[str, float]:
    """Run ``cmd`` to its end (output discarded): its wall and CPU seconds (user + system) and peak RSS (MB),
    from ``wait4`` (that child alone). A failing command raises ``RuntimeError`` with its last words."""
    import os
    import subprocess

    t0 = time.perf_counter()
    child = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    assert child.stderr is not None
    err = child.stderr.read().decode(errors="replace")  # (read to the end: a full pipe would block the child)
    _pid, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - t0
    code = os.waitstatus_to_exitcode(status)
    child.returncode = code
    if code:
        raise RuntimeError(f"{' '.join(cmd[2:4])} failed ({code}): {err.strip()[-500:]}")
    return {"wall_s": wall, "cpu_s": usage.ru_utime + usage.ru_stime, "peak_rss_mb": usage.ru_maxrss / 1024}
