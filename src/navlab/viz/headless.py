"""A headless chromium showing one page, as a user's browser would: for ``navlab bench view``.

The browser is driven through the DevTools protocol with nothing but ``Page.navigate``, ``Runtime.evaluate`` and
``Page.captureScreenshot``; no protocol domain is enabled, so the browser sends no events and instruments nothing.
An automation library (Playwright) enables the ``Network`` domain on every page, and chromium then copies each
WebSocket frame, base64-encoded, to the client, a cost no user's browser has: with the viewer's ~28 messages a
second, ``navlab bench view`` through Playwright measured chromium at 0.21-0.24 cores, this page 0.19-0.20.
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path
from typing import Any

from websockets.sync.client import connect

from navlab.viz.errors import VizError

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


class HeadlessPage:
    """A new headless chromium showing ``url``, a ``width`` × ``height`` CSS px viewport; :meth:`goto` shows another
    address in the same tab, :meth:`close` ends the browser."""

    def __init__(
        self, url: str = "about:blank", *, width: int = 1280, height: int = 800, executable: str = CHROMIUM
    ) -> None:
        self.dir = Path(tempfile.mkdtemp(prefix="navlab-chromium-"))
        cmd = [
            executable,
            "--headless",
            "--remote-debugging-port=0",
            f"--user-data-dir={self.dir}",
            f"--window-size={width},{height}",
            *CHROMIUM_ARGS,
            "about:blank",
        ]
        try:
            # its own process group: closing ends every chromium process it started, not only the first
            out = subprocess.DEVNULL
            self.proc = subprocess.Popen(cmd, stdout=out, stderr=out, start_new_session=True)
        except OSError as exc:
            shutil.rmtree(self.dir, ignore_errors=True)
            raise VizError(f"cannot start chromium at {executable}: {exc}") from None
        self._id = 0
        self._ws = contextlib.ExitStack()
        try:
            port = self._port(time.monotonic() + 30.0)
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as resp:
                targets = json.loads(resp.read())
            page = next(t for t in targets if t.get("type") == "page")
            self.ws = self._ws.enter_context(connect(page["webSocketDebuggerUrl"], max_size=None, open_timeout=10))
            # the page's viewport exactly (the window also holds the browser's own bar), as Playwright sets it
            metrics = {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False}
            self.call("Emulation.setDeviceMetricsOverride", **metrics)
            self.goto(url)
        except BaseException:
            self.close()
            raise

    def goto(self, url: str) -> None:
        """Show ``url`` (returns once the navigation started; see :meth:`wait_for`)."""
        self.call("Page.navigate", url=url)

    def _port(self, deadline: float) -> int:
        """The DevTools port chromium wrote into its profile folder once it listens."""
        path = self.dir / "DevToolsActivePort"
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise VizError(f"chromium exited with code {self.proc.returncode} before it listened")
            try:
                return int(path.read_text().split()[0])
            except (OSError, ValueError, IndexError):
                time.sleep(0.05)
        raise VizError("chromium did not open its DevTools port within 30 s")

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        """One DevTools command; its result."""
        self._id += 1
        self.ws.send(json.dumps({"id": self._id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv(timeout=60))
            if msg.get("id") == self._id:
                if "error" in msg:
                    raise VizError(f"chromium: {method}: {msg['error'].get('message')}")
                result: dict[str, Any] = msg["result"]
                return result

    def evaluate(self, expression: str) -> Any:
        """The value of a JavaScript expression in the page (a promise is awaited)."""
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            detail = r["exceptionDetails"]
            raise VizError(f"page: {detail.get('exception', {}).get('description') or detail.get('text')}")
        return r["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 30.0) -> None:
        """Until the expression is true in the page (polled every 50 ms)."""
        deadline = time.monotonic() + timeout
        while not self.evaluate(f"!!({expression})"):
            if time.monotonic() > deadline:
                raise VizError(f"page: not true within {timeout:g} s: {expression}")
            time.sleep(0.05)

    def screenshot(self, path: Path) -> None:
        """The page as a PNG file."""
        path.write_bytes(base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"]))

    def close(self) -> None:
        """End the browser and remove its profile folder."""
        self._ws.close()
        group = self.proc.pid  # the group's id is the id of the process that leads it
        for sig in (signal.SIGTERM, signal.SIGKILL):
            try:
                os.killpg(group, sig)
            except ProcessLookupError:
                break
            deadline = time.monotonic() + 10.0
            while time.monotonic() < deadline and _group_alive(group, self.proc):
                time.sleep(0.05)
            if not _group_alive(group, self.proc):
                break
        self.proc.wait()
        shutil.rmtree(self.dir, ignore_errors=True)


def _group_alive(group: int, leader: subprocess.Popen[bytes]) -> bool:
    """Whether a process of the group is left (the leader is reaped first, so it is not counted as a zombie)."""
    leader.poll()
    try:
        os.killpg(group, 0)
    except ProcessLookupError:
        return False
    return True
