"""AMCL in the MuJoCo simulation of the paper's robot in room_obstacles.world (true map)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from navlab.cli import main
from navlab.experiments.localize_run import run_localization
from navlab.localization import LocalizationError
from navlab.mapping import save_map
from navlab.world import load_world, true_map


def test_tracking_on_a_saved_map_along_a_60_s_route(tmp_path: Path) -> None:
    grid = true_map(load_world("room_obstacles"), (0.0, 0.0))
    save_map(grid, tmp_path / "room.yaml")
    res = run_localization("room_obstacles", tmp_path / "room.yaml", duration=60.0, seed=0)
    s = res.summary
    assert s["position_error_mean_m"] <= 0.05
    assert s["yaw_error_mean_deg"] <= 2.0
    assert s["position_error_max_m"] < 0.15
    assert s["updates"] > 50  # it drove ~17 m and AMCL kept updating
    travelled = sum(math.dist(a[:2], b[:2]) for a, b in zip(res.truth[:-1], res.truth[1:], strict=True))
    assert travelled > 12.0


def test_global_localization_converges_within_20_s_of_motion() -> None:
    res = run_localization(
        "room_obstacles",
        global_localization=True,
        duration=22.0,
        seed=0,
        amcl_params={"odom_model_type": "diff-corrected"},
    )
    s = res.summary
    assert np.nanmax(res.error[:40]) > 0.5  # it really started lost
    assert s["converged_s"] is not None and s["converged_s"] <= 20.0
    assert s["position_error_final_m"] <= 0.10


def test_kidnapped_robot_recovers_within_30_s_with_recovery_alphas() -> None:
    alphas = {"recovery_alpha_slow": 0.05, "recovery_alpha_fast": 0.5}
    res = run_localization("room_obstacles", duration=50.0, seed=0, kidnap_at=20.0, amcl_params=alphas)
    s = res.summary
    assert s["kidnap_distance_m"] >= 3.0
    assert s["position_error_mean_m"] <= 0.05  # tracking before the kidnapping
    k = int(s["kidnap_s"] * 10)
    assert res.error[k + 2] > 1.0  # lost right after it
    assert s["recovered_after_s"] is not None and s["recovered_after_s"] <= 30.0
    # the same run without recovery stays lost
    res0 = run_localization("room_obstacles", duration=50.0, seed=0, kidnap_at=20.0)
    assert res0.summary["recovered_after_s"] is None and res0.summary["position_error_final_m"] > 1.0


def test_localize_cli_prints_json_and_saves_a_picture(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert (
        main(
            [
                "localize",
                "--duration",
                "4",
                "--json",
                "--quiet",
                "--out",
                str(tmp_path / "loc"),
                "--set",
                "laser_max_beams=60",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert out["mode"] == "tracking" and out["position_error_mean_m"] < 0.05 and out["updates"] >= 3
    assert (tmp_path / "loc" / "localize.png").stat().st_size > 10_000 and out["png"].endswith("loc/localize.png")


def test_localize_out_as_a_file_is_deprecated_but_works(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    png = tmp_path / "old.png"
    assert main(["localize", "--duration", "1", "--quiet", "--out", str(png)]) == 0
    err = capsys.readouterr().err
    assert png.is_file() and err.startswith("navlab: DeprecationWarning: --out ") and err.count("\n") == 1
    assert main(["localize", "--initial", "50", "0", "0", "--duration", "1", "--out", ""]) == 2
    assert "outside the map" in capsys.readouterr().err
    bad = tmp_path / "amcl.yaml"
    bad.write_text("amcl:\n  ros__parameters:\n    min_particle: 200\n")
    assert main(["localize", "--params", str(bad), "--duration", "1", "--out", ""]) == 2
    assert "did you mean 'min_particles'" in capsys.readouterr().err
    with pytest.raises(LocalizationError, match="not finite"):
        run_localization(initial=(math.nan, 0.0, 0.0), duration=1.0)


def test_same_seed_same_run() -> None:
    a = run_localization("room_obstacles", global_localization=True, duration=4.0, seed=3)
    b = run_localization("room_obstacles", global_localization=True, duration=4.0, seed=3)
    assert np.array_equal(a.estimate, b.estimate, equal_nan=True)
    assert np.array_equal(a.truth, b.truth)
