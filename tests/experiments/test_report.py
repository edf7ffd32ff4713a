"""navlab report DIR: a run, a sweep and a demo folder re-rendered as Markdown, PNGs and one HTML page."""

from __future__ import annotations

import base64
import json
import re
from pathlib import Path

import pytest

from navlab.cli import main
from navlab.experiments.scenario import scenario_from_dict
from navlab.experiments.sweep import run_sweep
from navlab.experiments.trials import run_experiment

TINY = {"name": "tiny", "world": "room", "goals": [[1.2, 0.3, 0.0]], "trials": 2, "seed": 1, "time_limit": 30}


def _self_contained(page: str) -> list[bytes]:
    """The page's images (decoded); fails if it links anything outside itself."""
    assert page.startswith("<!DOCTYPE html>") and page.rstrip().endswith("</html>")
    assert not re.search(r"(href|src)=\"(?!data:)", page), "an external link or file"
    images = re.findall(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"', page)
    return [base64.b64decode(i) for i in images]


def test_a_run_and_a_sweep_are_reported_as_markdown_pngs_and_one_html_page(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    run_experiment(scenario_from_dict(TINY), tmp_path / "run")
    assert main(["report", str(tmp_path / "run")]) == 0
    assert "run report" in capsys.readouterr().out
    md = (tmp_path / "run" / "report.md").read_text()
    assert "2 of 2 trials succeeded" in md and "![" in md and "| trial | seed | success |" in md
    pngs = _self_contained((tmp_path / "run" / "report.html").read_text())
    assert pngs == [(tmp_path / "run" / name).read_bytes() for name in ("trials.png", "paths.png")]
    assert "every trial's true path" in md

    run_sweep(scenario_from_dict({**TINY, "trials": 1}), {"controller": ["trajectory", "dwa"]}, tmp_path / "sweep")
    (tmp_path / "sweep" / "controller.png").unlink()  # re-rendered from the results
    assert main(["report", str(tmp_path / "sweep"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["kind"] == "sweep" and (tmp_path / "sweep" / "controller.png").stat().st_size > 10_000
    md = (tmp_path / "sweep" / "report.md").read_text()
    assert "| controller | success_rate |" in md and "| trajectory | 1 |" in md and "| dwa | 1 |" in md
    # the parameter's plot, then each combination's trajectories on the world's map (the run report's paths.png)
    combos = [tmp_path / "sweep" / f"controller={c}" for c in ("dwa", "trajectory")]
    pngs = _self_contained((tmp_path / "sweep" / "report.html").read_text())
    assert pngs[1:] == [(c / "paths.png").read_bytes() for c in combos] and len(pngs) == 3
    assert "## Paths per combination" in md and "(controller=dwa/paths.png)" in md
    assert "controller=trajectory: every trial's true path" in md


def test_a_demo_folder_is_reported_and_a_wrong_folder_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    demo = tmp_path / "demo"
    (demo / "navigate").mkdir(parents=True)
    for png in ("map.png", "navigate/goal_1.png"):
        plt.imsave(demo / png, [[0.0, 1.0], [1.0, 0.0]])
    goal = {
        "goal": [4.3, 1.0, 0.0],
        "outcome": "succeeded",
        "time_s": 20.1,
        "path_m": 5.0,
        "min_clearance_m": 0.3,
        "collisions": 0,
        "reason": "",
    }
    (demo / "report.json").write_text(
        json.dumps(
            {
                "out": str(demo),
                "mapping": {"precision": 0.97, "recall": 0.93, "picture": "x"},
                "localization": {"position_error_mean_m": 0.03},
                "navigation": {"goals": [goal], "collisions": 0},
                "wall_s": 80.0,
            }
        )
    )
    assert main(["report", str(demo)]) == 0
    md = (demo / "report.md").read_text()
    assert "| precision | 0.97 |" in md and "| (4.3, 1.0, 0.0) |" not in md and "succeeded" in md
    assert len(_self_contained((demo / "report.html").read_text())) == 2  # the map and the goal's picture
    assert main(["report", str(tmp_path / "nothing")]) == 2
    assert main(["report", str(tmp_path)]) == 2
    assert "not a results folder" in capsys.readouterr().err
