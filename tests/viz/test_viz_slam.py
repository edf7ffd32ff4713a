"""The page's map follows SLAM's growing map while mapping (what the page is sent, from the hub's streams)."""

from __future__ import annotations

import numpy as np

from navlab.experiments.session import start_run
from navlab.viz import attach
from navlab.viz import frames as fr
from navlab.viz.hub import ClientStream


def _known_cells(stream: ClientStream, now: float) -> int:
    for frame in stream.frames(now):
        if isinstance(frame, bytes):
            header, payload = fr.unpack(frame)
            if header["topic"] == "/map" and header["k"] == "grid":  # a new ClientStream: the whole map
                cells = np.frombuffer(payload, dtype=np.uint8)
                return int((cells != 255).sum())
    raise AssertionError("no /map frame")


def test_slam_map_grows_on_the_page() -> None:
    run = start_run("mapping", world="room", explore="true")
    viewer = attach(run.executor, port=0, rate=0.0)
    try:
        run.run(3.0)
        early = _known_cells(ClientStream(viewer.hub), 100.0)
        run.run(12.0)
        later = _known_cells(ClientStream(viewer.hub), 200.0)
        assert later > early + 1000, (early, later)  # more of the room known
        assert viewer.hub.state["fixed"] == "map" and "/map" in viewer.hub.graph["topics"]  # type: ignore[index]
    finally:
        viewer.close()
