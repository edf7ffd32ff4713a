"""``navlab bench view``: the viewer with the whole navigation stack, watched by a headless chromium.

The paper's obstacle experiment (room mapped empty, navigation in room_obstacles, a cylinder dropped in at
20 s, goals there and back) runs as fast as possible for the same simulated time twice without a viewer
and twice with the viewer and a page connected (Debian's chromium through Playwright, a dev dependency).
Figures: ``fps`` (frames the page drew per wall-clock s), ``bytes_per_s`` (what the server sent per s),
``sim_slowdown`` (1 - real-time factor with the page / without; the best of each pair), ``python_cpu_overhead``
(the navlab process's CPU time with the viewer / without, - 1: the viewer's own cost, the browser's excluded)
and the screenshot taken in the middle of the drive.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

from navlab.viz.errors import VizError

GOALS = [(4.3, 1.0, 0.0), (-3.5, -0.5, 3.14), (1.5, -2.5, 0.0)]
SIM_S = 40.0  # simulated s measured per drive
CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]  # fmt: skip


def _drive(map_yaml: str, *, seed: int, browser: Any = None, shot: Path | None = None) -> dict[str, float]:
    """One drive of SIM_S simulated s; with ``browser``, watched by a page. Wall time excludes the screenshot."""
    from navlab.experiments.session import start_run
    from navlab.viz.viewer import attach

    run = start_run("navigation", world="room_obstacles", map=map_yaml, seed=seed)
    viewer = page = None
    if browser is not None:
        viewer = attach(run.executor, port=0, speed=0.0)
        page = browser.new_page(viewport={"width": 1280, "height": 800})
        page.goto(viewer.url)
        page.wait_for_function("() => window.navlab && navlab.store.state", timeout=30000)
    mb, gz = run.node("move_base"), run.node("gazebo")
    run.run(1.0)
    if page is not None:
        page.wait_for_function("() => navlab.view.fitted", timeout=30000)
    goals = list(GOALS)
    handle = mb.send_goal(*goals.pop(0))  # type: ignore[attr-defined]
    wall = cpu = frames = sent = 0.0
    spawned = False
    t_end = run.executor.now_ns / 1e9 + SIM_S
    while run.executor.now_ns / 1e9 < t_end - 1e-9:
        before = page.evaluate("navlab.stats.frames") if page is not None else 0
        bytes0 = viewer.hub.bytes_sent if viewer is not None else 0
        t0, c0 = time.perf_counter(), time.process_time()
        run.run(min(5.0, t_end - run.executor.now_ns / 1e9), until=handle.done, quiet=True, chunk=5.0)
        wall += time.perf_counter() - t0
        cpu += time.process_time() - c0
        if page is not None and viewer is not None:
            frames += page.evaluate("navlab.stats.frames") - before
            sent += viewer.hub.bytes_sent - bytes0
        if not spawned and run.executor.now_ns >= 20e9:
            gz.spawn_primitive("cylinder", "late", (0.15, 0.6), x=-1.0, y=-0.45)  # type: ignore[attr-defined]
            spawned = True
        if page is not None and shot is not None and run.executor.now_ns >= 25e9 and not shot.exists():
            page.wait_for_timeout(300)
            page.screenshot(path=str(shot))
        if handle.done() and goals:
            handle = mb.send_goal(*goals.pop(0))  # type: ignore[attr-defined]
    if viewer is not None and page is not None:
        viewer.close()
        page.close()
    run.executor.stop()
    return {"wall_s": wall, "cpu_s": cpu, "sim_s": SIM_S, "frames": frames, "bytes": sent}


def run(args: Any) -> dict[str, Any]:
    """Run the benchmark; see the module docstring."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        raise VizError("navlab bench view needs playwright (a dev dependency: pip install playwright) and "
                       f"chromium at {CHROMIUM}") from None  # fmt: skip
    from navlab.viz.cli import _true_map

    seed = int(getattr(args, "seed", 0))
    folder = Path(tempfile.mkdtemp(prefix="navlab-bench-view-"))
    map_yaml = _true_map("room", (0.0, 0.0, 0.0), folder)
    shot = folder / "obstacle_experiment.png"
    _drive(map_yaml, seed=seed)  # warm-up: Numba's caches, imports
    base, seen = [], []
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            for k in range(2):
                base.append(_drive(map_yaml, seed=seed))
                seen.append(_drive(map_yaml, seed=seed, browser=browser, shot=shot if k == 0 else None))
        finally:
            browser.close()
    b = min(base, key=lambda r: r["wall_s"])
    v = min(seen, key=lambda r: r["wall_s"])
    rtf_base, rtf_view = SIM_S / b["wall_s"], SIM_S / v["wall_s"]
    return {
        "fps": round(v["frames"] / v["wall_s"], 1),
        "bytes_per_s": round(v["bytes"] / v["wall_s"]),
        "sim_slowdown": round(1.0 - rtf_view / rtf_base, 3),
        "python_cpu_overhead": round(min(r["cpu_s"] for r in seen) / min(r["cpu_s"] for r in base) - 1.0, 3),
        "rtf_without_viewer": round(rtf_base, 1),
        "rtf_with_viewer": round(rtf_view, 1),
        "screenshot": str(shot),
    }
