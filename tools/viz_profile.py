"""Where a viewer page's CPU goes: one drive of ``navlab bench view``'s scenario watched by headless chromium.

The page is the bench's (:class:`navlab.viz.headless.HeadlessPage`: a user's browser, no automation domain
enabled). Prints the drive's real-time factor and the page's frames per s, chromium's CPU per process (browser,
renderer, gpu-process, utility) and per thread of the renderer and gpu processes (cores: CPU s per wall-clock s
of the drive), with ``--cdp`` the page's ``Performance`` metrics (main thread only), and how often the scene's
caches were drawn anew. A figure for finding what to speed up, not a benchmark (``navlab bench view`` gives
those). Run it under the CPU lock::

    PYTHONPATH=$PWD/src python tools/viz_profile.py --sim 100
    PYTHONPATH=$PWD/src python tools/viz_profile.py --setup "() => { navlab.settings.maxFps = 0.5; }"
"""

from __future__ import annotations

import argparse
import os
import re
import tempfile
import time
from pathlib import Path
from typing import Any

TICK = os.sysconf("SC_CLK_TCK")


def _stat(path: str) -> tuple[str, list[str]]:
    with open(path) as f:
        text = f.read()
    return text[text.index("(") + 1 : text.rindex(")")], text[text.rindex(")") + 2 :].split()


def chromium_processes() -> dict[int, tuple[str, float]]:
    """pid -> (process type, CPU s) of this process's chromium descendants."""
    children: dict[int, list[int]] = {}
    info: dict[int, tuple[str, str, float]] = {}
    for entry in filter(str.isdigit, os.listdir("/proc")):
        try:
            name, rest = _stat(f"/proc/{entry}/stat")
            with open(f"/proc/{entry}/cmdline") as f:
                cmd = f.read().replace("\0", " ")
        except OSError:
            continue
        kind = re.search(r"--type=(\S+)", cmd)
        sub = re.search(r"--utility-sub-type=(\S+)", cmd)
        label = (kind.group(1) if kind else "browser") + (":" + sub.group(1).split(".")[-1] if sub else "")
        children.setdefault(int(rest[1]), []).append(int(entry))
        info[int(entry)] = (name, label, (int(rest[11]) + int(rest[12])) / TICK)
    out, stack = {}, [os.getpid()]
    while stack:
        for pid in children.get(stack.pop(), []):
            stack.append(pid)
            if "chrom" in info[pid][0]:
                out[pid] = info[pid][1:]
    return out


def threads(pid: int) -> dict[str, float]:
    """Thread name -> CPU s of process ``pid``."""
    out: dict[str, float] = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            name, rest = _stat(f"/proc/{pid}/task/{tid}/stat")
        except OSError:
            continue
        out[name] = out.get(name, 0.0) + (int(rest[11]) + int(rest[12])) / TICK
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sim", type=float, default=100.0, help="simulated s to drive (default 100)")
    ap.add_argument("--setup", default="", help="JavaScript run in the page before the drive")
    ap.add_argument("--rate", type=float, default=0.0, help="the viewer's pace (0: as fast as possible, 1: real time)")
    ap.add_argument("--cdp", action="store_true", help="also the page's CDP Performance metrics (main thread)")
    args = ap.parse_args()
    from navlab.bench import view as bench
    from navlab.experiments.session import start_run
    from navlab.mapping import save_true_map
    from navlab.viz.headless import HeadlessPage
    from navlab.viz.viewer import attach

    map_yaml = str(save_true_map("room", (0.0, 0.0), Path(tempfile.mkdtemp(prefix="navlab-viz-profile-")) / "map.yaml"))
    bench._drive(map_yaml, seed=0)  # warm-up: Numba's caches, imports
    run = start_run("navigation", world="room_obstacles", map=map_yaml, seed=0)
    viewer = attach(run.executor, port=0, rate=args.rate)
    page = HeadlessPage(viewer.url, width=1280, height=800)
    try:
        page.wait_for("window.navlab && navlab.store.state")
        run.run(1.0)
        page.wait_for("navlab.view.fitted")
        if args.setup:
            page.evaluate(args.setup)
        if args.cdp:
            page.call("Performance.enable")
        mb, gz = run.node("move_base"), run.node("gazebo")
        goals = list(bench.GOALS)
        handle: Any = mb.send_goal(*goals.pop(0))  # type: ignore[attr-defined]

        def metrics() -> dict[str, float]:
            return {m["name"]: m["value"] for m in page.call("Performance.getMetrics")["metrics"]} if args.cdp else {}

        m0, p0, f0 = metrics(), chromium_processes(), page.evaluate("navlab.stats.frames")
        th0 = {pid: threads(pid) for pid, (kind, _) in p0.items() if kind in ("renderer", "gpu-process")}
        t0, c0 = time.perf_counter(), time.process_time()
        t_end, spawned = run.executor.now_ns / 1e9 + args.sim, False
        while run.executor.now_ns / 1e9 < t_end - 1e-9:
            until = None if handle.done() and not goals else handle.done
            run.run(min(5.0, t_end - run.executor.now_ns / 1e9), until=until, quiet=True, chunk=5.0)
            if not spawned and run.executor.now_ns >= 20e9:
                gz.spawn_primitive("cylinder", "late", (0.15, 0.6), x=-1.0, y=-0.45)  # type: ignore[attr-defined]
                spawned = True
            if handle.done() and goals:
                handle = mb.send_goal(*goals.pop(0))  # type: ignore[attr-defined]
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        m1, p1, f1 = metrics(), chromium_processes(), page.evaluate("navlab.stats.frames")
        print(
            f"drive: {args.sim:.0f} simulated s in {wall:.2f} s wall (RTF {args.sim / wall:.1f}), navlab "
            f"{cpu / wall:.2f} cores, page {(f1 - f0) / wall:.1f} frames/s, {viewer.hub.bytes_sent / wall:.0f} B/s"
        )
        total = 0.0
        for pid, (kind, cpu1) in sorted(p1.items(), key=lambda kv: kv[1][0]):
            used = (cpu1 - p0.get(pid, (kind, 0.0))[1]) / wall
            total += used
            print(f"  {kind:28s} {used:.3f} cores")
            if pid in th0:
                th1 = threads(pid)
                busy = sorted(((th1[n] - th0[pid].get(n, 0.0)) / wall, n) for n in th1)
                print("    " + ", ".join(f"{n} {v:.3f}" for v, n in reversed(busy) if v >= 0.002))
        print(f"  chromium in all: {total:.3f} cores")
        for key in sorted(m1):
            if key.endswith("Duration"):
                print(f"  cdp {key:26s} {(m1[key] - m0.get(key, 0.0)) / wall:.4f} s/s (main thread)")
        print("  caches drawn anew:", page.evaluate("navlab.renders ? navlab.renders() : null"), f"in {f1 - f0} frames")
    finally:
        page.close()
        viewer.close()
        run.executor.stop()


if __name__ == "__main__":
    main()
