"""The viewer: rviz in a browser page, served by navlab (``navlab view``, ``--view``), a bag replay, and a
Foxglove bridge. See docs/viewer.md.

``attach(executor)`` serves the page for a running executor; ``play_bag(path, hub)`` replays a recording.
Names are imported on first use, so ``navlab --help`` stays fast.
"""

from __future__ import annotations

import importlib
from typing import Any

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
}
__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'navlab.viz' has no attribute {name!r}")
