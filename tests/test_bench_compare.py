"""``navlab bench compare OLD.json NEW.json``: every figure both hold, with its ratio new / old."""

from __future__ import annotations

import json

from navlab.cli import main


def test_compare_prints_the_ratio_of_every_shared_figure(tmp_path, capsys):
    old = {"nav": {"rtf": 25.0, "goals": 4}, "summary": {"nav_rtf": 25.0, "slam_peak_rss_mb": 3100.0}, "x": "text"}
    new = {"nav": {"rtf": 50.0, "goals": 4}, "summary": {"nav_rtf": 50.0, "slam_peak_rss_mb": 310.0, "start_s": 0.9}}
    (tmp_path / "old.json").write_text(json.dumps(old))
    (tmp_path / "new.json").write_text(json.dumps(new))
    assert main(["bench", "compare", str(tmp_path / "old.json"), str(tmp_path / "new.json")]) == 0
    rows = {line.split()[0]: line.split()[1:] for line in capsys.readouterr().out.splitlines()[1:]}
    assert rows["nav.rtf"] == ["25", "50", "2.000"]
    assert rows["summary.slam_peak_rss_mb"] == ["3100", "310", "0.100"]
    assert rows["nav.goals"][-1] == "1.000"
    assert "summary.start_s" not in rows and "x" not in rows  # only in one file; not a number


def test_compare_needs_two_readable_json_files(tmp_path, capsys):
    (tmp_path / "a.json").write_text("[1, 2]")
    assert main(["bench", "compare", str(tmp_path / "a.json")]) == 2
    assert "expected two files" in capsys.readouterr().err
    assert main(["bench", "compare", str(tmp_path / "a.json"), str(tmp_path / "missing.json")]) == 2
    err = capsys.readouterr().err
    assert "a.json: expected a JSON object" in err and err.count("\n") == 1
