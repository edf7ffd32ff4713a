"""Ceilings on parameters that size work or memory (issue 21): a clear error naming the key and the product,
never a MemoryError or a run that does not end; one wild pose in a log is rejected and counted."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from navlab.core import read_params
from navlab.core.limits import ceilings
from navlab.errors import NavlabError
from navlab.io.carmen import read_carmen
from navlab.localization import AmclParams
from navlab.mapping.gmapping import GMappingParams
from navlab.navigation import costmap_params
from navlab.navigation.controllers.mppi import MppiParams
from navlab.navigation.controllers.params import DWAPlannerParams, TrajectoryPlannerParams
from navlab.navigation.costmap.footprint import make_footprint


def _reader(cls: type) -> Any:
    """``read_params`` for ``cls``."""
    return lambda values: read_params(cls, values)


def _footprint(value: str) -> None:
    make_footprint(footprint=value)


def _amcl(values: dict[str, Any]) -> None:
    AmclParams(**values).validate()


@pytest.mark.parametrize(
    ("build", "values", "words"),
    [
        (
            costmap_params,
            {"width": 1e6, "height": 1e6, "resolution": 0.05},
            "width x height / resolution²: 400,000,000,000,000 cells",
        ),
        (costmap_params, {"resolution": 1e-7}, "cells, more than"),
        (costmap_params, {"update_frequency": 1e9}, "update_frequency: 1,000,000,000 Hz"),
        (_footprint, "[[1e6, 0], [0, 1], [-1, 0]]", "distance from the centre"),
        (_footprint, str([[k % 7 / 10, k / 1e4] for k in range(2000)]), "number of points"),
        (costmap_params, {"robot_radius": 1e9}, "robot_radius"),
        (_reader(DWAPlannerParams), {"vx_samples": 10**6, "vth_samples": 10**6}, "vx_samples x vth_samples x steps"),
        (_reader(DWAPlannerParams), {"sim_granularity": 1e-12}, "poses per cycle"),
        (_reader(DWAPlannerParams), {"controller_frequency": 1e9}, "controller_frequency"),
        (_reader(TrajectoryPlannerParams), {"vx_samples": 10**9}, "vx_samples x vtheta_samples"),
        (_reader(MppiParams), {"batch_size": 10**9}, "batch_size x time_steps x iteration_count: 56,000,000,000 poses"),
        (_reader(MppiParams), {"time_steps": 10**9}, "batch_size x time_steps"),
        (_amcl, {"max_particles": 10**9}, "max_particles"),
        (_reader(GMappingParams), {"particles": 10**9}, "particles"),
    ],
)
def test_sizes_beyond_the_ceilings_are_refused_naming_the_key(build: Any, values: dict[str, Any], words: str) -> None:
    with pytest.raises(NavlabError, match="ceiling") as info:
        build(values)
    assert words in str(info.value) and "\n" not in str(info.value)


def test_the_shipped_defaults_are_far_below_the_ceilings() -> None:
    costmap_params({"width": 100, "height": 100, "resolution": 0.02})  # a 25-million-cell-free office, fine
    read_params(DWAPlannerParams, {"vx_samples": 20, "vth_samples": 40, "sim_time": 3.0})
    read_params(MppiParams, {"batch_size": 2000, "time_steps": 100})
    assert ceilings()["grid_cells"].limit > 1e7


def _log(path: Path, wild: tuple[float, float] | None) -> Path:
    lines = []
    for k in range(30):
        x = 0.05 * k
        ox, oy = wild if wild is not None and k == 15 else (x, 0.0)
        ranges = " ".join("2.0" for _ in range(181))
        lines.append(f"FLASER 181 {ranges} {ox} {oy} 0.0 {ox} {oy} 0.0 {k * 0.2:.3f} host {k * 0.2:.3f}")
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("wild", [(1e5, -3e4), (2e3, 0.0)])
def test_a_wild_pose_in_a_log_is_rejected_and_counted(tmp_path: Path, wild: tuple[float, float]) -> None:
    log = read_carmen(_log(tmp_path / "wild.clf", wild))
    assert log.outlier_poses == 1 and len(log.scans) == 29
    assert "rejected an outlier pose" in log.skipped[0] and "wild.clf:16" in log.skipped[0]
    assert read_carmen(_log(tmp_path / "tame.clf", None)).outlier_poses == 0


def test_an_overflowing_pose_is_a_skipped_line(tmp_path: Path) -> None:
    log = read_carmen(_log(tmp_path / "wild.clf", (1e308, 0.0)))
    assert len(log.scans) == 29 and "beyond 1e+06 m" in log.skipped[0]
