"""`navlab navigate --out DIR`: a labelled picture at each goal's end and one mid-drive, with a legend that names
what is drawn (robot, goal, a dropped-in model); the exit status says whether every goal succeeded."""

from __future__ import annotations

from pathlib import Path

import pytest

from navlab.cli import main
from navlab.experiments.navigate_run import run_navigation
from navlab.experiments.plots import navigation_figure
from navlab.sim import primitive_model


def test_arrival_and_mid_drive_pictures_with_a_legend(tmp_path: Path) -> None:
    late = primitive_model("cylinder", "late_cylinder", (0.15, 0.6), x=1.0, y=1.0)
    r = run_navigation([(1.5, 0.0, 0.0)], world="room_obstacles", spawn=[(2.0, late)], goal_timeout=20, snapshots=True)
    assert r.goals[0]["outcome"] == "succeeded" and len(r.arrivals) == len(r.snapshots) == 1
    end, mid = r.arrivals[0], r.snapshots[0]
    assert end["t"] > mid["t"] and end["dropped"][0][3] == "late_cylinder"
    fig = navigation_figure(r.grid, end, title="end", goal=r.goals[0]["goal"])
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert {"robot (truth)", "goal", "dropped in while driving", "driven path (truth)", "map: wall"} <= set(labels)


def test_cli_writes_both_pictures_and_exits_1_when_a_goal_is_missed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        [
            "navigate",
            "--world",
            "room_obstacles",
            "--goal",
            "1.5",
            "0",
            "0",
            "--goal",
            "4.3",
            "1.0",
            "0",
            "--timeout",
            "6",
            "--out",
            str(tmp_path / "nav"),
            "--quiet",
        ]
    )
    err = capsys.readouterr().err
    assert code == 1 and "navlab: 1 of 2 goals not reached (timeout)" in err
    names = sorted(p.name for p in (tmp_path / "nav").iterdir())
    assert names == ["goal_1.png", "goal_1_mid.png", "goal_2.png", "goal_2_mid.png"]
