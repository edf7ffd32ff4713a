"""What the viewer writes in headless chromium: tf labels of frames at one place joined, nearby labels apart,
and long display names that keep the end telling them apart (the whole name as tooltip)."""

from __future__ import annotations

from typing import Any

from navlab.viz import Hub, ViewerServer

# every fillText on the page's own canvas (?worker=0: the page draws on its thread), as drawn
RECORD_TEXT = """
window.drawnTexts = [];
const fillText = CanvasRenderingContext2D.prototype.fillText;
CanvasRenderingContext2D.prototype.fillText = function (text, x, y, ...rest) {
  window.drawnTexts.push({ text: String(text), x, y, w: this.measureText(text).width });
  return fillText.call(this, text, x, y, ...rest);
};
"""
ODOM = "/husky_with_a_long_namespace/odometry/filtered"
TRUTH = "/husky_with_a_long_namespace/ground_truth/odom"


def test_tf_labels_at_one_place_are_joined_and_long_display_names_keep_their_ends(chromium: Any) -> None:
    hub = Hub()
    tf = {
        "map": [0.0, 0.0, 0.0],
        "odom": [0.0, 0.0, 0.0],  # one place: one label
        "base_link": [1.0, 0.5, 0.3],
        "imu_link": [1.0, 0.5, 0.3],
        "laser": [1.02, 0.5, 0.3],  # ~1 px apart
        "caster": [1.0, 0.35, 0.3],
    }  # 9 px below base_link: its own label, stacked clear of the other
    hub.set_state(
        {
            "t": 1.0,
            "t0": 0.0,
            "t1": 1.0,
            "rtf": 1.0,
            "paused": True,
            "speed": 1.0,
            "fixed": "map",
            "base": "base_link",
            "tf": tf,
            "move_base": None,
            "obstacles": [],
            "replay": False,
        }
    )
    for topic in (ODOM, TRUTH):
        hub.set_trace(topic, "map", [[0.0, 0.0], [1.0, 0.5]])
    with ViewerServer(hub, port=0) as server:
        page = chromium.new_page(viewport={"width": 1100, "height": 760})
        try:
            errors: list[str] = []
            page.on("pageerror", lambda exc: errors.append(str(exc)))
            page.add_init_script(RECORD_TEXT)
            page.goto(server.url + "?worker=0")
            page.wait_for_selector(f'input[data-layer="trace {TRUTH}"]')
            labels = page.eval_on_selector_all(
                "#layers label", "ls => ls.map(l => [l.querySelector('input').dataset.layer, l.textContent, l.title])"
            )
            shown = {layer: (text.strip(), title) for layer, text, title in labels}
            odom, truth = shown[f"trace {ODOM}"], shown[f"trace {TRUTH}"]
            assert odom[0] != truth[0] and odom[0].endswith("odometry/filtered") and truth[0].endswith("truth/odom")
            assert odom[0].startswith("…") and len(odom[0]) <= 28  # cut at the front, not to a shared prefix
            assert (odom[1], truth[1]) == (f"trace {ODOM}", f"trace {TRUTH}")  # the whole name as tooltip

            page.check('input[data-layer="tf"]')
            page.wait_for_function("() => drawnTexts.some(d => d.text.includes('base_link'))")
            drawn = page.evaluate("drawnTexts")
            names = set(tf)
            # the last frame drawn: each label once
            last = {d["text"]: d for d in drawn if set(d["text"].split(", ")) <= names}
            assert set(last) == {"map, odom", "base_link, imu_link, laser", "caster"}
            a, b = last["base_link, imu_link, laser"], last["caster"]
            assert abs(a["y"] - b["y"]) >= 11  # overlapping columns: stacked a line apart, not printed over each other
            assert not errors
        finally:
            page.close()
