"""The viewer draws a depth camera's image and point cloud (headless chromium): the paper's robot with its depth
camera in tables.world; the image sits in the canvas's top-right corner and the cloud's points on the map."""

from __future__ import annotations

import tempfile
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from viz_helpers import open_page, pixel, to_screen

from navlab import msgs
from navlab.experiments.session import Run, start_run
from navlab.mapping import save_true_map
from navlab.viz.sensor_frames import image_rgba
from navlab.viz.viewer import Viewer, attach


def test_image_rgba_shrinks_and_colours() -> None:
    depth = np.full((240, 320), 2.5, np.float32)
    depth[:, :10] = np.nan
    img = msgs.Image(
        header=msgs.header(0, "cam"),
        height=240,
        width=320,
        encoding="32FC1",
        is_bigendian=0,
        step=1280,
        data=depth.reshape(-1).view(np.uint8),
    )
    rgba = image_rgba(img)
    assert rgba.shape == (120, 160, 4) and rgba[0, 0, :3].tolist() == [0, 0, 0]  # NaN: black
    assert rgba[50, 80, :3].tolist() == [127, 127, 127] and (rgba[..., 3] == 255).all()  # 2.5 m of 5: mid grey
    bgr = np.zeros((4, 4, 3), np.uint8)
    bgr[..., 0] = 200  # blue in bgr8
    img = msgs.Image(
        header=msgs.header(0, "cam"), height=4, width=4, encoding="bgr8", is_bigendian=0, step=12, data=bgr.reshape(-1)
    )
    assert image_rgba(img)[0, 0].tolist() == [0, 0, 200, 255]


@pytest.fixture(scope="module")
def live() -> Iterator[tuple[Run, Viewer]]:
    with tempfile.TemporaryDirectory() as tmp:
        run = start_run(
            "navigation",
            world="tables",
            robot="mybot_depth",
            pose=(-1.2, 0.0, 0.0),
            map=str(save_true_map("tables", (-1.2, 0.0), Path(tmp) / "true_map.yaml")),
        )
    viewer = attach(run.executor, port=0, rate=2.0)
    thread = threading.Thread(target=lambda: run.run(3600.0, quiet=True), daemon=True)
    thread.start()
    yield run, viewer
    viewer.node.close()
    run.executor.stop()
    thread.join(10)
    viewer.close()


def test_page_shows_depth_image_and_cloud(live: tuple[Run, Viewer], chromium: Any, artifacts: Path) -> None:
    page = open_page(chromium, live[1].url)
    try:
        page.wait_for_function(
            "() => ['/camera/depth/image_raw', '/camera/depth/points'].every((t) => t in navlab.layers)", timeout=30000
        )
        page.wait_for_timeout(1500)
        page.screenshot(path=str(artifacts / "viewer_depth_camera.png"))
        width = page.evaluate("() => document.querySelector('canvas').clientWidth")
        # the images (160 x 120 px each) in the top right, in topic order: the colour image, then the depth image,
        # whose lower rows see the floor nearby (light grey: near is white)
        r, g, b, _ = pixel(page, width - 8 - 80, 8 + 120 + 20 + 100)
        assert r == g == b and r > 150, (r, g, b)
        colour = pixel(page, width - 8 - 80, 8 + 100)
        assert colour[:3] != (0x30, 0x30, 0x30)  # drawn, not the canvas background
        # the cloud's points where the camera looks: the floor and the pallet's near face (x = 0.1 m), low: blue/green
        x, y = to_screen(page, 0.1, 0.0)
        box = page.evaluate(
            "() => { const r = document.querySelector('canvas').getBoundingClientRect(); return [r.left, r.top]; }"
        )
        found = [pixel(page, x - box[0] + dx, y - box[1] + dy) for dx in range(-4, 5, 2) for dy in range(-40, 41, 4)]
        assert any(p[:3] in ((0x22, 0xCC, 0x88), (0x33, 0x66, 0xCC)) for p in found), found[:5]
        assert not page.js_errors, page.js_errors
    finally:
        page.close()
