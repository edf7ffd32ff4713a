"""End to end in headless chromium: the page draws the running navigation stack, and its tools drive it —
2D Nav Goal, 2D Pose Estimate, teleop keys, obstacles placed, moved and deleted, pause, the node graph."""

from __future__ import annotations

import math
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from viz_helpers import canvas_xy, open_page, pixel, to_screen

from navlab.experiments.session import Run, start_run
from navlab.mapping import save_true_map
from navlab.viz import Viewer, attach


@pytest.fixture(scope="module")
def live() -> Iterator[tuple[Run, Viewer]]:
    """The paper's navigation launch in room_obstacles, watched at 5x real time, its executor in a thread."""
    with tempfile.TemporaryDirectory() as tmp:
        truth = save_true_map("room_obstacles", (0, 0), Path(tmp) / "true_map.yaml")
        run = start_run("navigation", world="room_obstacles", map=str(truth))
    viewer = attach(run.executor, port=0, rate=5.0)
    thread = threading.Thread(target=lambda: run.run(3600.0, quiet=True), daemon=True)
    thread.start()
    yield run, viewer
    viewer.node.close()  # a paused run goes on
    run.executor.stop()
    thread.join(10)
    viewer.close()


@pytest.fixture(scope="module")
def page(live: tuple[Run, Viewer], chromium: Any) -> Iterator[Any]:
    p = open_page(chromium, live[1].url)
    p.wait_for_function("() => Object.keys(navlab.store.grids).length >= 2 && navlab.view.fitted", timeout=15000)
    yield p
    assert not p.js_errors, p.js_errors
    p.close()


def _wait(predicate: Any, timeout: float = 20.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.05)
    return False


def _true_pose(run: Run) -> tuple[float, float, float]:
    return run.sim.base_pose2d()


def test_page_draws_map_costmaps_and_robot(live: tuple[Run, Viewer], page: Any, artifacts: Path) -> None:
    run, viewer = live
    page.wait_for_function("() => navlab.stats.frames > 10 && Object.keys(navlab.store.scans).length > 0")
    page.screenshot(path=str(artifacts / "live_navigation.png"))
    grids = page.evaluate("Object.keys(navlab.store.grids)")
    assert {"/map", "/move_base/global_costmap/costmap", "/move_base/local_costmap/costmap"} <= set(grids)
    x, y, _ = _true_pose(run)
    # the robot's outline (yellow) around its true position
    sx, sy = canvas_xy(page, x, y)
    ring = [pixel(page, sx + dx, sy + dy) for dx, dy in [(12, 0), (-12, 0), (0, 12), (0, -12), (8, 8), (-8, -8)]]
    assert any(r > 200 and g > 200 and b < 80 for r, g, b, _a in ring), ring
    # free floor is white once the particle cloud is switched off; a wall is lethal (costmap purple over black)
    page.uncheck("input[data-layer='/particlecloud']")
    page.wait_for_timeout(100)
    free = pixel(page, *canvas_xy(page, -1.5, 0.0))
    assert min(free[:3]) > 200, free
    wx, wy = _wall_cell(viewer.hub.slots["/move_base/global_costmap/costmap"].msg)
    wall = pixel(page, *canvas_xy(page, wx, wy))
    assert wall[0] > 140 and wall[2] > 140 and wall[1] < 60, wall
    page.check("input[data-layer='/particlecloud']")
    assert page.evaluate("navlab.worker")  # chromium draws in a worker, on the canvas handed over


def test_page_draws_on_its_own_thread_without_a_worker(live: tuple[Run, Viewer], chromium: Any) -> None:
    """``?worker=0`` (and browsers that cannot hand a canvas to a worker) draw the same scene on the page's thread."""
    run, viewer = live
    p = open_page(chromium, viewer.url + "?worker=0")
    try:
        p.wait_for_function("() => navlab.view.fitted && navlab.stats.frames > 10", timeout=15000)
        assert not p.evaluate("navlab.worker")
        x, y, _ = _true_pose(run)
        sx, sy = canvas_xy(p, x, y)
        ring = [pixel(p, sx + dx, sy + dy) for dx, dy in [(12, 0), (-12, 0), (0, 12), (0, -12), (8, 8), (-8, -8)]]
        assert any(r > 200 and g > 200 and b < 80 for r, g, b, _a in ring), ring
        assert not p.js_errors, p.js_errors
    finally:
        p.close()


def _wall_cell(msg: Any) -> tuple[float, float]:
    """The centre (m) of a lethal cell whose neighbours are lethal too (inside a wall), far from the robot."""
    info = msg.info
    cells = np.asarray(msg.data).reshape(info.height, info.width)
    lethal = cells == 100
    inner = lethal[1:-1, 1:-1] & lethal[:-2, 1:-1] & lethal[2:, 1:-1] & lethal[1:-1, :-2] & lethal[1:-1, 2:]
    rows, cols = np.nonzero(inner)
    k = int(np.argmax(np.hypot(rows - info.height / 2, cols - info.width / 2)))
    res = info.resolution
    return info.origin.position.x + (cols[k] + 1.5) * res, info.origin.position.y + (rows[k] + 1.5) * res


def test_pause_holds_simulated_time_and_resume_releases_it(live: tuple[Run, Viewer], page: Any) -> None:
    run, _ = live
    page.click("#pause")
    assert _wait(lambda: page.evaluate("navlab.store.state.paused"))
    t0 = run.executor.now_ns
    time.sleep(0.4)
    assert run.executor.now_ns - t0 <= 20_000_000  # at most the tick in flight
    page.click("#pause")
    assert _wait(lambda: run.executor.now_ns - t0 > 200_000_000)


def test_teleop_keys_move_the_robot_and_k_stops_it(live: tuple[Run, Viewer], page: Any) -> None:
    run, _ = live
    x0, y0, yaw0 = _true_pose(run)
    page.locator("#view").focus()
    page.keyboard.press("i")  # teleop_twist_keyboard: forward at 0.5 m/s
    assert _wait(lambda: math.dist(_true_pose(run)[:2], (x0, y0)) > 0.15, timeout=10)
    page.keyboard.press("k")
    x1, y1, _ = _true_pose(run)
    heading = math.atan2(y1 - y0, x1 - x0)
    assert abs(math.remainder(heading - yaw0, math.tau)) < 0.3  # it went forward
    time.sleep(0.5)
    moved = math.dist(_true_pose(run)[:2], (x1, y1))
    time.sleep(0.5)
    assert math.dist(_true_pose(run)[:2], (x1, y1)) - moved < 0.02  # and stopped


def _assert_scan_on_walls(page: Any, costmap: Any) -> None:
    """The scan the page holds, placed at the pose it carries, falls on the costmap's lethal cells."""
    f = page.evaluate(
        "() => { const f = Object.values(navlab.store.scans)[0]; return {...f, data: Array.from(f.data)}; }"
    )
    r = np.array(f["data"])
    a = f["a0"] + f["da"] * np.arange(len(r))
    ok = (r >= f["rmin"]) & (r < f["rmax"])
    x, y, yaw = f["pose"]
    px, py = x + r[ok] * np.cos(a[ok] + yaw), y + r[ok] * np.sin(a[ok] + yaw)
    info = costmap.info
    cells = np.asarray(costmap.data).reshape(info.height, info.width)
    col = ((px - info.origin.position.x) / info.resolution).astype(int)
    row = ((py - info.origin.position.y) / info.resolution).astype(int)
    inside = (col >= 0) & (col < info.width) & (row >= 0) & (row < info.height)
    assert inside.mean() > 0.9
    on_wall = cells[row[inside], col[inside]] >= 99
    assert on_wall.mean() > 0.8, on_wall.mean()


def test_nav_goal_drag_sends_the_robot_there(live: tuple[Run, Viewer], page: Any, artifacts: Path) -> None:
    run, viewer = live
    goal = (-1.5, 0.0)
    page.click("[data-tool=goal]")
    gx, gy = to_screen(page, *goal)
    page.mouse.move(gx, gy)
    page.mouse.down()
    page.mouse.move(gx - 40, gy, steps=4)  # drag towards -x: heading pi
    page.mouse.up()
    mb = run.node("move_base")
    assert _wait(lambda: mb.handle is not None and tuple(mb.handle.goal[:2]) == pytest.approx(goal, abs=0.05), 5)
    assert mb.handle.frame_id == "map"
    assert abs(math.remainder(mb.handle.goal[2] - math.pi, math.tau)) < 0.1
    # the page gets navfn's plan (drawn blue) ending at the goal
    plan_end = """() => { const p = navlab.store.paths['/move_base/NavfnROS/plan'];
        return p && p.n > 2 ? [p.data[2 * p.n - 2], p.data[2 * p.n - 1]] : null; }"""
    page.wait_for_function(f"() => ({plan_end})() !== null", timeout=10000)
    assert page.evaluate(plan_end) == pytest.approx(goal, abs=0.1)
    page.screenshot(path=str(artifacts / "nav_goal_driving.png"))
    _assert_scan_on_walls(page, viewer.hub.slots["/move_base/global_costmap/costmap"].msg)  # placed while turning
    assert _wait(lambda: mb.handle.done(), timeout=40), mb.state
    assert mb.handle.state == "SUCCEEDED", mb.handle.reason
    assert math.dist(_true_pose(run)[:2], goal) < 0.3
    page.wait_for_function("() => (navlab.store.state.move_base.outcome || {}).state === 'SUCCEEDED'")
    assert "SUCCEEDED" in page.inner_text("#outcome")


def test_added_obstacle_appears_in_scan_and_local_costmap(live: tuple[Run, Viewer], page: Any, artifacts: Path) -> None:
    run, viewer = live
    page.click("#pause")  # place it with the world held still
    assert _wait(lambda: page.evaluate("navlab.store.state.paused"))
    x, y, yaw = _true_pose(run)
    ox, oy = x + 1.0 * math.cos(yaw), y + 1.0 * math.sin(yaw)
    scan_ahead = _range_ahead(page)
    t_paused = run.executor.now_ns
    page.click("[data-tool=box]")
    page.mouse.click(*to_screen(page, ox, oy))
    # placed while paused: the executor steps to its next event (10 simulated ms at most) to apply it
    assert _wait(lambda: any(m.startswith("viewer_box") for m in run.sim.model_names()), 5)
    page.wait_for_function("() => navlab.store.state.obstacles.length === 1")
    assert run.executor.now_ns - t_paused <= 30_000_000
    name = next(m for m in run.sim.model_names() if m.startswith("viewer_box"))
    page.click("#pause")
    # the lidar sees it: ~1 m ahead minus half the 0.4 m box minus the laser's offset
    assert _wait(lambda: _range_ahead(page) < min(0.95, scan_ahead - 0.2), 10), (scan_ahead, _range_ahead(page))
    # and the local costmap marks its face lethal: purple (costmap 100) where the scan hits it (scan dots hidden)
    page.uncheck("input[data-layer='/mybot/laser/scan']")
    page.uncheck("input[data-layer='/particlecloud']")
    fx, fy = canvas_xy(page, ox - 0.2 * math.cos(yaw), oy - 0.2 * math.sin(yaw))
    near = [(fx + dx, fy + dy) for dx in range(-4, 5, 2) for dy in range(-4, 5, 2)]
    assert _wait(lambda: any(_is_lethal(pixel(page, *p)) for p in near), 10)
    page.check("input[data-layer='/mybot/laser/scan']")
    page.check("input[data-layer='/particlecloud']")
    page.screenshot(path=str(artifacts / "obstacle_added.png"))
    # drag it 0.6 m sideways, then delete it
    page.click("[data-tool=pan]")
    sx, sy = to_screen(page, ox, oy)
    page.mouse.move(sx, sy)
    page.mouse.down()
    nx, ny = ox - 0.6 * math.sin(yaw), oy + 0.6 * math.cos(yaw)
    page.mouse.move(*to_screen(page, nx, ny), steps=5)
    page.mouse.up()
    placed = lambda: [viewer.node.obstacles.get(name, {}).get(k) for k in "xy"]  # noqa: E731
    assert _wait(lambda: placed() == pytest.approx([nx, ny], abs=0.05), 5)
    assert run.sim.model_pose(name).position[:2] == pytest.approx([nx, ny], abs=0.05)
    page.click("[data-tool=delete]")
    page.mouse.click(*to_screen(page, nx, ny))
    assert _wait(lambda: name not in run.sim.model_names(), 5)
    page.wait_for_function("() => navlab.store.state.obstacles.length === 0")


def _range_ahead(page: Any) -> float:
    """The nearest return within 5 degrees of straight ahead in the scan the page holds."""
    return float(
        page.evaluate("""() => {
        const f = Object.values(navlab.store.scans)[0];
        let best = Infinity;
        for (let i = 0; i < f.data.length; i++) {
            const a = f.a0 + i * f.da, r = f.data[i];
            if (Math.abs(a) < 0.09 && r >= f.rmin && r < f.rmax) best = Math.min(best, r);
        }
        return best;
    }""")
    )


def _is_lethal(rgba: tuple[int, int, int, int]) -> bool:
    r, g, b, _ = rgba
    return r > 200 and b > 200 and g < 140


def test_pose_estimate_drag_publishes_initialpose_to_amcl(live: tuple[Run, Viewer], page: Any) -> None:
    run, _ = live
    amcl = run.node("amcl")
    x, y, _ = _true_pose(run)
    target = (x + 0.3, y - 0.2)
    page.click("[data-tool=pose]")
    sx, sy = to_screen(page, *target)
    page.mouse.move(sx, sy)
    page.mouse.down()
    page.mouse.move(sx, sy - 40, steps=4)  # heading +y
    page.mouse.up()

    def reset_there() -> bool:
        est = amcl.filter.estimate if amcl.filter is not None else None
        return (
            est is not None
            and math.dist(est[:2], target) < 0.25
            and abs(math.remainder(est[2] - math.pi / 2, math.tau)) < 0.4
        )

    assert _wait(reset_there, 5)
    spread = np.asarray(amcl.filter.particles)[:, :2].std(axis=0)
    assert 0.2 < spread.mean() < 0.8  # rviz's 0.25 m² variance: particles spread ~0.5 m


def test_node_graph_panel_shows_the_runtime_graph(page: Any, artifacts: Path) -> None:
    page.click("#graphbtn")
    page.wait_for_selector("#graphbody svg g[data-name='/move_base']", timeout=10000)
    names = set(page.eval_on_selector_all("#graphbody svg g", "gs => gs.map(g => g.dataset.name)"))
    assert {"/amcl", "/gazebo", "/move_base", "/map_server", "/cmd_vel", "/navlab_viewer"} <= names
    assert "Hz" in page.inner_text("#graphbody")
    page.screenshot(path=str(artifacts / "node_graph.png"))
    page.click("#graphbtn")
