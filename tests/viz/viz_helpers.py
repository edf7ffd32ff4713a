"""Helpers of the viewer's browser tests: opening a page, reading canvas pixels, world <-> page coordinates."""

from __future__ import annotations

import json
from typing import Any

from navlab.viz import frames as fr


def open_page(browser: Any, url: str) -> Any:
    """A page on ``url`` whose JavaScript errors fail the test, once the viewer has its first state."""
    page = browser.new_page(viewport={"width": 1100, "height": 760})
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.goto(url)
    page.wait_for_function("() => window.navlab && window.navlab.store.state !== null", timeout=15000)
    page.js_errors = errors  # type: ignore[attr-defined]
    return page


def pixel(page: Any, x: float, y: float) -> tuple[int, int, int, int]:
    """RGBA of the canvas at CSS pixel (x, y) of the canvas (read where the canvas is drawn: the page's worker)."""
    return tuple(page.evaluate("([x, y]) => window.navlab.pixel(x, y)", [x, y]))


def to_screen(page: Any, x: float, y: float) -> tuple[float, float]:
    """Page coordinates of the fixed-frame point (x, y) m."""
    sx, sy = page.evaluate("([x, y]) => window.navlab.view.toScreen(x, y)", [x, y])
    box = page.locator("#view").bounding_box()
    return box["x"] + sx, box["y"] + sy


def canvas_xy(page: Any, x: float, y: float) -> tuple[float, float]:
    """Canvas coordinates (CSS px) of the fixed-frame point (x, y) m."""
    sx, sy = page.evaluate("([x, y]) => window.navlab.view.toScreen(x, y)", [x, y])
    return sx, sy


def headers(ws: Any, timeout: float = 5.0) -> list[dict[str, Any]]:
    """The JSON of the viewer WebSocket's next message: a text reply, or every frame's header of a batch."""
    msg = ws.recv(timeout=timeout)
    if isinstance(msg, str):
        return [json.loads(msg)]
    return [fr.unpack(f)[0] for f in fr.unbatch(msg)]


def next_state(ws: Any, timeout: float = 5.0) -> dict[str, Any]:
    """The next state the viewer sends (simulated time, tf, move_base, ...)."""
    for _ in range(50):
        for h in headers(ws, timeout):
            if h["k"] == "state":
                return h
    raise AssertionError("no state in 50 messages")
