"""The bench's headless page: a chromium of its own, driven with plain DevTools commands, a viewport of the asked
size, JavaScript values and errors, screenshots, and nothing left behind when closed."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from navlab.viz import Hub, ViewerServer, VizError
from navlab.viz.headless import CHROMIUM, HeadlessPage

pytestmark = pytest.mark.skipif(not os.path.exists(CHROMIUM), reason=f"needs chromium at {CHROMIUM}")


def test_headless_page_shows_the_viewer_and_closes_cleanly(tmp_path: Path) -> None:
    hub = Hub()
    hub.set_state({"t": 2.5, "tf": {}, "fixed": "map", "base": "chassis"})
    with ViewerServer(hub, port=0) as srv:
        page = HeadlessPage(width=900, height=600)
        try:
            page.goto(f"http://127.0.0.1:{srv.port}/")
            page.wait_for("window.navlab && navlab.store.state")
            assert page.evaluate("[innerWidth, innerHeight, navlab.store.state.t]") == [900, 600, 2.5]
            assert page.evaluate("Promise.resolve(6 * 7)") == 42  # promises are awaited
            with pytest.raises(VizError, match="nope"):
                page.evaluate("(() => { throw new Error('nope'); })()")
            with pytest.raises(VizError, match="within"):
                page.wait_for("false", timeout=0.2)
            page.screenshot(tmp_path / "shot.png")
            assert (tmp_path / "shot.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        finally:
            page.close()
    assert page.proc.poll() is not None and not page.dir.exists()
    with pytest.raises(ProcessLookupError):
        os.killpg(page.proc.pid, 0)  # no chromium process of its group is left


def test_headless_page_names_a_missing_browser() -> None:
    with pytest.raises(VizError, match="cannot start chromium"):
        HeadlessPage(executable="/nonexistent/chromium")
