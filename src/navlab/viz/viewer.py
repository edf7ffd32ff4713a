"""Attach the viewer to a running executor: the viewer node, the web server and, optionally, Foxglove.

``attach(executor)`` is what ``navlab view`` and every verb's ``--view`` call::

    viewer = attach(run.executor, port=8765)   # prints nothing, opens nothing
    print(viewer.url)
    run.run(60.0)                              # paced at real time; the page can pause, speed up, send goals
    viewer.close()
"""

from __future__ import annotations

import logging
import os
import sys
import webbrowser
from dataclasses import dataclass
from typing import Any

from navlab.core import Executor
from navlab.viz.hub import Hub
from navlab.viz.live import Pacer, ViewerNode
from navlab.viz.server import LOOPBACK, ViewerServer

_log = logging.getLogger("navlab.viz")


@dataclass
class Viewer:
    """A served viewer: its hub, its node on the executor, its server, and the Foxglove bridge if any."""

    hub: Hub
    node: ViewerNode
    server: ViewerServer
    foxglove: Any = None

    @property
    def url(self) -> str:
        """The page's address."""
        return self.server.url

    def close(self) -> None:
        """Stop serving and remove the viewer's node. Call it from the executor's thread or once it stopped
        running (a run in another thread: ``node.close()`` first, which releases a paused run)."""
        self.node.close()
        self.node.destroy_node()
        self.server.close()
        if self.foxglove is not None:
            self.foxglove.close()

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def attach(
    executor: Executor,
    *,
    host: str = "127.0.0.1",
    port: int = 8765,
    rate: float | None = None,
    foxglove_port: int | None = None,
    parameters: dict[str, Any] | None = None,
    speed: float | None = None,
) -> Viewer:
    """Start the viewer node on ``executor`` and serve the page on ``host:port`` (0: any free port).

    ``rate``: the pace (simulated s per wall-clock s; 0 = as fast as possible; default: the executor's
    rate, or real time; ``speed``, its old name, is deprecated). ``foxglove_port``: also serve Foxglove's
    WebSocket protocol there.
    """
    from navlab.deprecation import renamed

    rate = renamed(rate, speed, old="speed", new="rate", where="navlab.viz.attach")
    hub = Hub()
    pace = rate if rate is not None else (executor.rate or 1.0)
    node = ViewerNode(executor, hub=hub, pacer=Pacer(pace), parameters=parameters)
    server = ViewerServer(hub, host=host, port=port)
    try:
        server.start()
    except Exception:
        node.close()
        node.destroy_node()
        raise
    viewer = Viewer(hub, node, server)
    if foxglove_port is not None:
        from navlab.viz.foxglove_bridge import FoxgloveBridge

        viewer.foxglove = FoxgloveBridge(executor, host=host, port=foxglove_port)
    return viewer


def host_warning(host: str) -> str | None:
    """The warning printed when the server listens beyond this machine."""
    if host in LOOPBACK:
        return None
    return (
        f"warning: the viewer listens on {host}: anyone who can reach this machine can watch the run and "
        "send goals, teleop commands and obstacles (use --host 127.0.0.1 to keep it local)"
    )


def open_in_browser(url: str) -> bool:
    """Open ``url`` where a desktop is present (a display, macOS or Windows); returns whether it tried."""
    desktop = bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")) or sys.platform in (
        "darwin",
        "win32",
    )
    if not desktop:
        return False
    try:
        return webbrowser.open(url)
    except webbrowser.Error:
        return False
