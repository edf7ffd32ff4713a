"""Start poses, goals and spawns are bounded (issue 21): overflowing coordinates, infinite sizes, negative times and
a model spawned onto the robot end in one clear line instead of an overflow or an unstable simulation."""

from __future__ import annotations

import contextlib

import pytest

from navlab.cli import main
from navlab.sim import SimError, parse_spawn_spec


@pytest.mark.parametrize(
    ("spec", "words"),
    [
        ("sphere:x=1,radius=inf", "radius=inf: expected a finite number within ±10000 m"),
        ("box:x=1,size=nan", "size=nan"),
        ("cylinder:x=1e308,radius=0.2", "x=1e308: expected a finite number within ±1e+06 m"),
        ("box:x=1,t=-5", "t=-5: expected a time >= 0 s"),
    ],
)
def test_spawn_specs_out_of_bounds_are_refused(spec: str, words: str) -> None:
    with pytest.raises(SimError, match="spawn spec") as info:
        parse_spawn_spec(spec)
    assert words in str(info.value)


@pytest.mark.parametrize("argv", [["--x", "1e308"], ["--yaw=-1e7"], ["--spawn", "cylinder:x=0,y=0,radius=0.3,t=0.1"]])
def test_sim_refuses_overflowing_starts_and_spawns_onto_the_robot(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    with contextlib.nullcontext() if argv[0] == "--spawn" else pytest.raises(SystemExit):
        code = main(["sim", "--duration", "0.3", "--quiet", *argv])
        assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and ("coordinate within" in err[0] or "would overlap robot 'mybot'" in err[0]), err


def test_navigate_refuses_a_goal_beyond_the_coordinate_ceiling(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["navigate", "--goal", "1e308", "0", "0"])
    assert "argument --goal: expected a coordinate within" in capsys.readouterr().err


def test_sensor_rates_above_the_physics_rate_update_once_per_step(tmp_path, capsys) -> None:
    """Gazebo updates a sensor at most once per physics step: rates of 1e9 Hz run, they do not hang."""
    import json
    import re
    import shutil

    from navlab import resources

    pkg = tmp_path / "mybot"
    shutil.copytree(resources.robot("mybot").parent, pkg)
    gz = pkg / "mybot.gazebo"
    gz.write_text(re.sub(r"<(updateRate|update_rate|updateRateHZ)>[^<]*</\1>", r"<\1>1e9</\1>", gz.read_text()))
    assert main(["sim", "--robot", str(pkg / "mybot.xacro"), "--duration", "0.1", "--quiet", "--json"]) == 0
    messages = json.loads(capsys.readouterr().out)["messages"]
    assert 40 <= messages["/mybot/laser/scan"] <= 51  # one per 2 ms step
