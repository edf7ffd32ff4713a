"""`navlab graph` of the navigation launch: every node and topic drawn, rqt_graph's shapes, no two boxes overlap
(read from the SVG's geometry), and a node and a topic of the same name (/collisions) kept apart."""

from __future__ import annotations

import itertools
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from navlab.cli import main
from navlab.mapping import save_map
from navlab.world import load_world, true_map

SVG = "{http://www.w3.org/2000/svg}"


def _shapes(svg: Path) -> dict[str, tuple[str, tuple[float, float, float, float]]]:
    """title -> (shape kind, bounding box x0 y0 x1 y1) of each Graphviz vertex in the SVG."""
    out = {}
    for g in ET.parse(svg).getroot().iter(f"{SVG}g"):
        if g.get("class") != "node":
            continue
        title = g.findtext(f"{SVG}title") or ""
        ell, poly = g.find(f"{SVG}ellipse"), g.find(f"{SVG}polygon")
        if ell is not None:
            cx, cy, rx, ry = (float(ell.get(k, 0)) for k in ("cx", "cy", "rx", "ry"))
            out[title] = ("ellipse", (cx - rx, cy - ry, cx + rx, cy + ry))
        else:
            assert poly is not None
            pts = [tuple(map(float, p.split(","))) for p in (poly.get("points") or "").split()]
            xs, ys = [p[0] for p in pts], [p[1] for p in pts]
            out[title] = ("box", (min(xs), min(ys), max(xs), max(ys)))
    return out


@pytest.fixture
def room_map(tmp_path: Path) -> Path:
    path = tmp_path / "room.yaml"
    save_map(true_map(load_world("room"), (0.0, 0.0)), path)
    return path


def test_navigation_graph_has_every_vertex_and_no_overlaps(room_map: Path, tmp_path: Path) -> None:
    assert (
        main(["graph", "--launch", "navigation", f"map:={room_map}", "--duration", "1", "--out", str(tmp_path / "g")])
        == 0
    )
    dot = (tmp_path / "g" / "graph.dot").read_text()
    shapes = _shapes(tmp_path / "g" / "graph.svg")
    nodes = re.findall(r'"n:([^"]+)" \[label', dot)
    topics = re.findall(r'"t:([^"]+)" \[label', dot)
    assert {"/move_base", "/amcl", "/map_server", "/diff_drive"} <= set(nodes)
    assert {f"n:{n}" for n in nodes} | {f"t:{t}" for t in topics} == set(shapes)
    assert all(shapes[f"n:{n}"][0] == "ellipse" for n in nodes) and all(shapes[f"t:{t}"][0] == "box" for t in topics)
    assert "n:/collisions" in shapes and "t:/collisions" in shapes  # the same name, two vertices, no self-loop
    # as in ROS: robot_state_publisher subscribes /joint_states; amcl and move_base read /tf (TransformListeners)
    assert '"n:/joint_state_publisher" -> "t:/joint_states"' in dot
    assert '"t:/joint_states" -> "n:/robot_state_publisher"' in dot
    assert '"t:/tf" -> "n:/amcl"' in dot and '"t:/tf" -> "n:/move_base"' in dot
    for (a, (_, ba)), (b, (_, bb)) in itertools.combinations(shapes.items(), 2):
        overlap = ba[0] < bb[2] and bb[0] < ba[2] and ba[1] < bb[3] and bb[1] < ba[3]
        assert not overlap, f"{a} overlaps {b}"
