"""Faults the user did not see (issue 14): scans without readings are counted and said, an empty world is
an error for localization and an empty map for mapping."""

from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np
import pytest

from navlab import msgs
from navlab.cli import main
from navlab.core import Context, Executor, Node
from navlab.localization.amcl_node import Amcl
from navlab.mapping.slam_node import SlamGMapping

EMPTY_WORLD = """<?xml version="1.0"?>
<sdf version="1.6"><world name="empty"><include><uri>model://ground_plane</uri></include></world></sdf>
"""


def _scans(ex: Executor, ranges: np.ndarray, seconds: float) -> None:
    pub = Node("fake_laser", context=Context(ex)).create_publisher(msgs.LaserScan, "scan", 5)

    def send() -> None:
        pub.publish(
            msgs.LaserScan(
                header=msgs.header(ex.now_ns, "laser"),
                angle_min=-1.0,
                angle_max=1.0,
                angle_increment=2.0 / (len(ranges) - 1),
                time_increment=0.0,
                scan_time=0.0,
                range_min=0.1,
                range_max=10.0,
                ranges=ranges.astype(np.float32),
                intensities=np.zeros(0, np.float32),
            )
        )

    Node("laser_timer", context=Context(ex)).create_timer(0.1, send)
    ex.run(seconds)


@pytest.mark.parametrize("node_class", [Amcl, SlamGMapping])
def test_scans_without_readings_are_counted_and_logged_at_a_throttled_rate(node_class: type, caplog) -> None:
    ex = Executor(seed=0)
    node = node_class(ex, parameters={})
    bad = np.array([np.inf, np.nan, 50.0, 0.01] * 30)  # beyond range_max, not a number, below range_min
    with caplog.at_level(logging.WARNING):
        _scans(ex, bad, 25.0)
    assert node.scans_invalid >= 240 and node.scans_invalid == node.scans_received
    said = [r for r in caplog.records if "has no valid reading" in r.getMessage()]
    assert 2 <= len(said) <= 3  # once per 10 simulated s, not 250 times


def test_localize_in_an_empty_world_is_an_error(tmp_path: Path, capsys) -> None:
    world = tmp_path / "empty.world"
    world.write_text(EMPTY_WORLD)
    png = str(tmp_path / "l.png")
    assert main(["localize", "--world", str(world), "--duration", "2", "--quiet", "--out", png]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "empty.world: nothing stands at the lidar's height" in err[0]


def test_mapping_an_empty_world_reports_an_empty_map(tmp_path: Path, capsys) -> None:
    world = tmp_path / "empty.world"
    world.write_text(EMPTY_WORLD)
    assert main(["map", "--world", str(world), "--duration", "8", "--quiet", "--json", "--out", str(tmp_path)]) == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert out["map_empty"] is True and out["finished"] is False and out["scans_invalid"] > 0
    assert "the map is empty" in out["warning"]


@pytest.mark.parametrize(
    ("ranges", "invalid"),
    [
        ([5.0, np.inf, np.nan], False),  # the first beam valid
        ([np.inf, np.nan, 10.0, 9.99], False),  # only the last: 10.0 is range_max itself, not a reading
        ([10.0, 0.05, np.nan, np.inf], True),  # none in [range_min, range_max)
    ],
)
def test_a_scan_is_valid_when_any_beam_is_in_range(ranges: list[float], invalid: bool) -> None:
    ex = Executor(seed=0)
    node = Amcl(ex, parameters={})
    _scans(ex, np.array(ranges * 10), 0.5)
    assert node.scans_received == 5 and node.scans_invalid == (5 if invalid else 0)
