"""The viewer: rviz in a browser page, served by navlab (``navlab view``, ``--view``), a bag replay, and a
Foxglove bridge. See docs/viewer.md.

``attach(executor)`` serves the page for a running executor; ``play_bag(path, hub)`` replays a recording.
Names are imported on first use, so ``navlab --help`` stays fast.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.viz.errors import VizError
    from navlab.viz.foxglove_bridge import FoxgloveBridge
    from navlab.viz.headless import CHROMIUM, HeadlessPage
    from navlab.viz.hub import Hub
    from navlab.viz.live import ViewerNode
    from navlab.viz.pacer import Pacer
    from navlab.viz.replay import load_recording, play_bag
    from navlab.viz.server import ViewerServer
    from navlab.viz.viewer import Viewer, attach, host_warning, open_in_browser


_EXPORTS = {
    "attach": "navlab.viz.viewer",
    "Viewer": "navlab.viz.viewer",
    "ViewerNode": "navlab.viz.live",
    "Pacer": "navlab.viz.pacer",
    "Hub": "navlab.viz.hub",
    "ViewerServer": "navlab.viz.server",
    "play_bag": "navlab.viz.replay",
    "load_recording": "navlab.viz.replay",
    "FoxgloveBridge": "navlab.viz.foxglove_bridge",
    "VizError": "navlab.viz.errors",
    "CHROMIUM": "navlab.viz.headless",
    "HeadlessPage": "navlab.viz.headless",
    "host_warning": "navlab.viz.viewer",
    "open_in_browser": "navlab.viz.viewer",
}
__all__ = [
    "CHROMIUM",
    "FoxgloveBridge",
    "HeadlessPage",
    "Hub",
    "Pacer",
    "Viewer",
    "ViewerNode",
    "ViewerServer",
    "VizError",
    "attach",
    "host_warning",
    "load_recording",
    "open_in_browser",
    "play_bag",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
