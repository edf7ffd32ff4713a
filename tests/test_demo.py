"""``navlab demo``, the README's first command: the paper's pipeline end to end, headless."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from navlab.cli import main


def test_demo_maps_localizes_and_navigates(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--out", str(tmp_path / "demo"), "--no-render", "--quiet", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    m, loc, nav = out["mapping"], out["localization"], out["navigation"]
    assert m["precision"] >= 0.9 and m["recall"] >= 0.9 and m["finished"], m
    assert loc["position_error_mean_m"] <= 0.1, loc
    assert [g["outcome"] for g in nav["goals"]] == ["succeeded"] * 3 and nav["collisions"] == 0, nav
    for path in [m["map"], m["picture"], loc["picture"], *(g["picture"] for g in nav["goals"])]:
        assert Path(path).stat().st_size > 0, path
    report = tmp_path / "demo"
    assert json.loads((report / "report.json").read_text())["navigation"]["goals"] == nav["goals"]
    assert "| [4.3, 1, 0] | succeeded |" in (report / "report.md").read_text()
    page = (report / "report.html").read_text()  # one self-contained page: the map and every goal inlined
    assert page.count("data:image/png;base64,") >= 4 and 'src="http' not in page
    assert (report / "map.png").is_file() and (report / "recording" / "metadata.yaml").is_file()
