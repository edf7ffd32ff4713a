"""The viewer's wire format and input checks: what the page decodes is what the node had."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from navlab import msgs
from navlab.grid import GridMap
from navlab.viz import frames as fr
from navlab.viz.hub import ClientStream, Hub
from navlab.viz.inputs import check_input
from navlab.viz.live import INITIALPOSE_COV


def _grid_msg(data: np.ndarray, origin: tuple[float, float, float] = (-1.0, -2.0, 0.0)) -> object:
    return GridMap(data.astype(np.int8), 0.05, origin, "map").to_msg(0)


def test_grid_frame_round_trip_keeps_cells_geometry_and_unknown() -> None:
    data = np.zeros((40, 70), dtype=np.int8)
    data[3, 5], data[39, 69], data[0, 0] = 100, -1, 42
    header, payload = fr.unpack(fr.grid_frame("/map", _grid_msg(data)))
    assert header["k"] == "grid" and (header["w"], header["h"]) == (70, 40)
    assert header["res"] == pytest.approx(0.05) and (header["ox"], header["oy"]) == (-1.0, -2.0)
    cells = np.frombuffer(payload, dtype=np.uint8).reshape(40, 70)
    assert cells[3, 5] == 100 and cells[39, 69] == 255 and cells[0, 0] == 42


def test_costmap_sends_only_changed_tiles_then_whole_when_geometry_changes() -> None:
    differ = fr.GridDiffer(tile=32)
    data = np.zeros((100, 100), dtype=np.int8)
    assert fr.unpack(differ.frame("/c", _grid_msg(data)))[0]["k"] == "grid"
    assert differ.frame("/c", _grid_msg(data)) is None  # nothing changed: nothing sent
    data[50, 70] = 100
    header, payload = fr.unpack(differ.frame("/c", _grid_msg(data)))
    assert header["k"] == "tiles" and header["tiles"] == [[64, 32, 32, 32]]
    tile = np.frombuffer(payload, dtype=np.uint8).reshape(32, 32)
    assert tile[50 - 32, 70 - 64] == 100 and tile.sum() == 100
    data[99, 99] = 50  # an edge tile is cut to the grid
    header, _ = fr.unpack(differ.frame("/c", _grid_msg(data)))
    assert header["tiles"] == [[96, 96, 4, 4]]
    header, _ = fr.unpack(differ.frame("/c", _grid_msg(data, origin=(0.5, 0.0, 0.0))))  # the window rolled
    assert header["k"] == "grid"


def test_a_batch_carries_frames_and_json_each_at_a_multiple_of_4_bytes() -> None:
    grid = fr.grid_frame("/map", _grid_msg(np.ones((3, 5), dtype=np.int8)))  # 15 cells: not a multiple of 4
    path = fr.path_frame("/plan", "map", np.array([[1.0, 2.0], [3.0, 4.0]]))
    message = fr.batch([json.dumps({"k": "state", "t": 1.5}), grid, path])
    frames = fr.unbatch(message)
    assert frames[1:] == [grid, path] and fr.unpack(frames[0]) == ({"k": "state", "t": 1.5}, b"")
    offsets = [message.index(f) for f in frames]
    assert all(off % 4 == 0 for off in offsets) and len(message) % 4 == 0
    assert fr.unbatch(fr.batch([])) == []


def test_scan_frame_carries_float32_ranges_and_angles() -> None:
    scan = msgs.LaserScan(
        header=msgs.header(0, "laser"),
        angle_min=-1.5,
        angle_max=1.5,
        angle_increment=0.01,
        time_increment=0.0,
        scan_time=0.0,
        range_min=0.1,
        range_max=10.0,
        ranges=np.array([1.0, np.inf, 2.5], dtype=np.float32),
        intensities=np.zeros(0, np.float32),
    )
    header, payload = fr.unpack(fr.scan_frame("/scan", scan))
    assert header["frame"] == "laser" and header["n"] == 3 and header["a0"] == pytest.approx(-1.5)
    ranges = np.frombuffer(payload, dtype=np.float32)
    assert ranges[0] == 1.0 and math.isinf(ranges[1]) and ranges[2] == 2.5


def test_a_page_gets_the_newest_placed_scan_while_a_newer_one_waits_for_its_pose() -> None:
    """Faster than real time a new scan replaces the slot between two snapshots: pages still get scans."""
    hub = Hub()

    def scan(t_ns: int, r: float) -> object:
        return msgs.LaserScan(
            header=msgs.header(t_ns, "laser"),
            angle_min=0.0,
            angle_max=0.0,
            angle_increment=0.01,
            time_increment=0.0,
            scan_time=0.0,
            range_min=0.1,
            range_max=10.0,
            ranges=np.array([r], dtype=np.float32),
            intensities=np.zeros(0, np.float32),
        )

    hub.put("/scan", "scan", scan(1_000_000, 1.0))
    hub.place_scans("map", lambda frame, t_ns: [t_ns / 1e9, 0.0, 0.0])
    hub.put("/scan", "scan", scan(2_000_000, 2.0))  # not placed yet
    stream = ClientStream(hub)
    sent = [fr.unpack(f) for f in stream.frames(now=1.0) if isinstance(f, bytes)]
    assert len(sent) == 1
    header, payload = sent[0]
    assert header["pose"] == [0.001, 0.0, 0.0] and np.frombuffer(payload, np.float32)[0] == 1.0
    assert stream.frames(now=2.0) == []  # the same placed scan is not sent twice
    hub.place_scans("map", lambda frame, t_ns: [t_ns / 1e9, 0.0, 0.0])
    ((header, payload),) = (fr.unpack(f) for f in stream.frames(now=3.0) if isinstance(f, bytes))
    assert header["pose"] == [0.002, 0.0, 0.0] and np.frombuffer(payload, np.float32)[0] == 2.0


def test_pose_array_yaw_from_quaternions() -> None:
    arr = msgs.PoseArray(
        header=msgs.header(0, "map"), poses=[msgs.pose_from_2d(1.0, 2.0, 0.5), msgs.pose_from_2d(-1.0, 0.0, -3.0)]
    )
    xyyaw = fr.pose_array_xyyaw(arr)
    assert xyyaw == pytest.approx(np.array([[1.0, 2.0, 0.5], [-1.0, 0.0, -3.0]]))


def test_inputs_are_checked_and_bad_ones_named() -> None:
    assert check_input({"op": "goal", "x": 1, "y": 2.5, "yaw": 0.1, "frame": "map"})[1]["x"] == 1.0
    assert check_input({"op": "spawn", "kind": "cylinder", "x": 0, "y": 0})[1]["dims"] == [0.2, 0.5]
    for bad, word in [
        ([1, 2], "JSON object"),
        ({"op": "rm -rf"}, "unknown op"),
        ({"op": "goal", "x": "1", "y": 0, "yaw": 0}, "'x'"),
        ({"op": "goal", "x": float("nan"), "y": 0, "yaw": 0}, "finite"),
        ({"op": "spawn", "kind": "house", "x": 0, "y": 0}, "kind"),
        ({"op": "key", "key": "ii"}, "key"),
        ({"op": "delete", "name": "../x"}, "name"),
        ({"op": "goal", "x": 0, "y": 0, "yaw": 0, "frame": "<script>"}, "frame"),
        ({"op": "speed", "value": -1}, "value"),
    ]:
        with pytest.raises(ValueError, match=word):
            check_input(bad)


def test_initialpose_covariance_is_rviz_s() -> None:
    cov = msgs.covariance(INITIALPOSE_COV).reshape(6, 6)
    assert cov[0, 0] == cov[1, 1] == 0.25 and cov[5, 5] == pytest.approx(0.06853891945200942)
