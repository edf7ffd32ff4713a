"""``navlab bench view``: the viewer with the whole navigation stack, watched by a headless chromium.

The paper's obstacle experiment (room mapped empty, navigation in room_obstacles, a cylinder dropped in at
20 s, goals there and back) runs as fast as possible for the same simulated time twice without a viewer
and twice with the viewer and a page connected (Debian's headless chromium, driven as a user's browser: see
:mod:`navlab.viz.headless`).
Drives alternate (without, with, with, without, ...: a shared machine's load drifts) ``ROUNDS`` times each.
Figures: ``fps`` (frames the page drew per wall-clock s), ``bytes_per_s`` (what the server sent per s),
``sim_slowdown`` (1 - real-time factor with the page / without, the median of each), ``python_cpu_overhead``
(the navlab process's CPU time with the viewer / without, - 1: the viewer's own Python cost),
``browser_cpu`` (chromium's CPU s per wall-clock s of the drive: cores the page takes from the simulation;
Linux only, else null), ``load`` (the machine's 1-min load average at the start and the end: on a loaded
machine the wall-clock figures are noisy, the CPU ones much less) and the screenshot taken in the middle of
the drive.
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

from navlab.bench.experiments import NAV_GOALS
from navlab.viz import CHROMIUM, HeadlessPage, VizError

GOALS = NAV_GOALS[:3]  # the demo's three
SIM_S = 40.0  # simulated s measured per drive
ROUNDS = 3  # drives with and without the page each


def _drive(
    map_yaml: str, *, seed: int, page: HeadlessPage | None = None, shot: Path | None = None, setup: str = ""
) -> dict[str, float]:
    """One drive of SIM_S simulated s; with ``page``, watched by it (the browser's tab opens the viewer, and a
    blank page after the drive; ``setup``: JavaScript run in it once it drew the map, e.g.
    ``navlab.settings.maxFps = 20``). Wall time excludes the screenshot."""
    from navlab.experiments import start_run
    from navlab.viz import attach

    run = start_run("navigation", world="room_obstacles", map=map_yaml, seed=seed)
    viewer = None
    try:
        if page is not None:
            viewer = attach(run.executor, port=0, rate=0.0)
            page.goto(viewer.url)
            page.wait_for("window.navlab && navlab.store.state")
        run.run(1.0)
        if page is not None:
            page.wait_for("navlab.view.fitted")
            if setup:
                page.evaluate(setup)
        return _measure(run, viewer, page, shot)
    finally:
        if page is not None:
            page.goto("about:blank")
        if viewer is not None:
            viewer.close()
        run.executor.stop()


def _measure(run: Any, viewer: Any, page: HeadlessPage | None, shot: Path | None) -> dict[str, float]:
    """The drive itself: goals one after the other, the cylinder dropped in at 20 s, in chunks of 5 simulated s."""
    mb, gz = run.node("move_base"), run.node("gazebo")
    goals = list(GOALS)
    handle = mb.send_goal(*goals.pop(0))
    wall = cpu = frames = sent = browser_cpu = 0.0
    spawned = False
    t_end = run.executor.now_ns / 1e9 + SIM_S
    while run.executor.now_ns / 1e9 < t_end - 1e-9:
        before = page.evaluate("navlab.stats.frames") if page is not None else 0
        bytes0 = viewer.hub.bytes_sent if viewer is not None else 0
        browser0 = _browser_cpu() if page is not None else None
        t0, c0 = time.perf_counter(), time.process_time()
        run.run(min(5.0, t_end - run.executor.now_ns / 1e9), until=handle.done, quiet=True, chunk=5.0)
        wall += time.perf_counter() - t0
        cpu += time.process_time() - c0
        if page is not None and browser0 is not None:
            browser_cpu += (_browser_cpu() or 0.0) - browser0
        if page is not None and viewer is not None:
            frames += page.evaluate("navlab.stats.frames") - before
            sent += viewer.hub.bytes_sent - bytes0
        if not spawned and run.executor.now_ns >= 20e9:
            gz.spawn_primitive("cylinder", "late", (0.15, 0.6), x=-1.0, y=-0.45)
            spawned = True
        if page is not None and shot is not None and run.executor.now_ns >= 25e9 and not shot.exists():
            time.sleep(0.3)
            page.screenshot(shot)
        if handle.done() and goals:
            handle = mb.send_goal(*goals.pop(0))
    return {"wall_s": wall, "cpu_s": cpu, "sim_s": SIM_S, "frames": frames, "bytes": sent, "browser_cpu_s": browser_cpu}


def _browser_cpu() -> float | None:
    """CPU s (user + system) used so far by this process's chromium descendants (Linux /proc), else None."""
    if not os.path.isdir("/proc/self/task"):
        return None
    tick = os.sysconf("SC_CLK_TCK")
    children: dict[int, list[int]] = {}
    info: dict[int, tuple[str, float]] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                text = f.read()
        except OSError:
            continue
        name, rest = text[text.index("(") + 1 : text.rindex(")")], text[text.rindex(")") + 2 :].split()
        children.setdefault(int(rest[1]), []).append(int(entry))
        info[int(entry)] = (name, (int(rest[11]) + int(rest[12])) / tick)
    total, stack = 0.0, [os.getpid()]
    while stack:
        for pid in children.get(stack.pop(), []):
            stack.append(pid)
            name, cpu = info[pid]
            if "chrom" in name:
                total += cpu
    return total


def _load() -> float | None:
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None


def run(args: Any) -> dict[str, Any]:
    """Run the benchmark; see the module docstring."""
    from navlab.mapping import save_true_map

    if not Path(CHROMIUM).exists():
        raise VizError(f"navlab bench view needs chromium at {CHROMIUM}")
    seed = int(getattr(args, "seed", 0))
    folder = Path(tempfile.mkdtemp(prefix="navlab-bench-view-"))
    map_yaml = str(save_true_map("room", (0.0, 0.0), folder / "true_map.yaml"))
    shot = folder / "obstacle_experiment.png"
    rounds = int(getattr(args, "rounds", ROUNDS) or ROUNDS)
    _drive(map_yaml, seed=seed)  # warm-up: Numba's caches, imports
    base: list[dict[str, float]] = []
    seen: list[dict[str, float]] = []
    load0 = _load()
    page = HeadlessPage(width=1280, height=800)  # one browser, as a user's: its start-up is not measured
    try:
        for k in range(rounds):
            if k % 2 == 0:
                base.append(_drive(map_yaml, seed=seed))
            seen.append(_drive(map_yaml, seed=seed, page=page, shot=shot if k == 0 else None))
            if k % 2 == 1:
                base.append(_drive(map_yaml, seed=seed))
    finally:
        page.close()

    def med(rows: list[dict[str, float]], key: str) -> float:
        return statistics.median(r[key] for r in rows)

    wall_base, wall_view = med(base, "wall_s"), med(seen, "wall_s")
    cores = statistics.median(r["browser_cpu_s"] / r["wall_s"] for r in seen)
    return {
        "fps": round(statistics.median(r["frames"] / r["wall_s"] for r in seen), 1),
        "bytes_per_s": round(statistics.median(r["bytes"] / r["wall_s"] for r in seen)),
        "sim_slowdown": round(1.0 - wall_base / wall_view, 3),
        "python_cpu_overhead": round(med(seen, "cpu_s") / med(base, "cpu_s") - 1.0, 3),
        "browser_cpu": None if _browser_cpu() is None else round(cores, 2),
        "rtf_without_viewer": round(SIM_S / wall_base, 1),
        "rtf_with_viewer": round(SIM_S / wall_view, 1),
        "rounds": rounds,
        "load": [load0, _load()],
        "screenshot": str(shot),
    }
