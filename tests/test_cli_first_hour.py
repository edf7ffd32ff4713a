"""The errors a new user meets first: each is one line that leads with the problem (the location after), comes
fast, and where it can, before MuJoCo/Numba are imported."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from navlab.cli import main


def _one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def test_a_mistyped_verb_gets_did_you_mean(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["navigat", "--goal", "1", "0", "0"])
    assert exit_.value.code == 2
    assert _one_line(capsys) == "navlab: error: unknown verb 'navigat'; did you mean 'navigate'? (see `navlab --help`)"
    with pytest.raises(SystemExit):
        main(["topic", "eco", "/odom"])
    assert "unknown action 'eco'; did you mean 'echo'?" in _one_line(capsys)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["navigate", "--world", "rooom", "--goal", "1", "0", "0"],
            "navlab: error: world 'rooom': no such file here and no shipped world of that name; did you mean 'room'?",
        ),
        (["localize", "--world", "missing.world"], "navlab: error: world file not found: "),
        (["map", "--robot", "mybt"], "navlab: error: robot 'mybt': no such file here and no shipped robot"),
        (["map", "--teleop"], "navlab: error: navlab map --teleop reads keys from a terminal (stdin is not one)"),
        (["teleop", "--world", "room"], "navlab: error: navlab teleop reads keys from a terminal"),
    ],
)
def test_a_missing_world_or_robot_is_one_line_before_heavy_imports(argv: list[str], message: str, tmp_path) -> None:
    code = (
        "import sys, time; t = time.perf_counter(); from navlab.cli import main; rc = main(sys.argv[1:]); "
        "print(rc, time.perf_counter() - t, *[m for m in ('mujoco', 'numba', 'ray') if m in sys.modules])"
    )
    proc = subprocess.run(  # stdin no terminal: keyboard teleop refuses it before the simulator starts
        [sys.executable, "-c", code, *argv],
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=60,
    )
    rc, seconds, *heavy = proc.stdout.split()
    assert rc == "2" and proc.stderr.startswith(message) and proc.stderr.count("\n") == 1, proc.stderr
    assert heavy == [] and float(seconds) < 5.0


def test_an_unknown_set_name_leads_with_the_problem(capsys: pytest.CaptureFixture[str]) -> None:
    t0 = time.perf_counter()
    assert main(["localize", "--duration", "1", "--set", "laser_max_beamz=60", "--out", ""]) == 2
    line = _one_line(capsys)
    assert line.startswith("navlab: error: node /amcl: unknown parameter 'laser_max_beamz'")
    assert "did you mean 'laser_max_beams'?" in line and "--set" in line and "localization.launch.yaml" in line
    assert time.perf_counter() - t0 < 10


def test_launch_arguments_may_follow_options(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["launch", "talker_listener", "--duration", "0.5", "rate:=20", "--quiet"]) == 0
    assert "/chatter: 10 messages" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["launch", "talker_listener", "--duration", "0.5", "--bogus"])
    assert "unrecognized arguments: --bogus" in _one_line(capsys)


def test_experiment_list_shows_every_shipped_scenario(capsys: pytest.CaptureFixture[str]) -> None:
    from navlab import resources

    assert main(["experiment", "list"]) == 0
    out = capsys.readouterr().out
    names = sorted(f.stem for f in (resources.root() / "scenarios").glob("*.yaml"))
    assert len(names) >= 5 and all(f"\n{n}: world " in f"\n{out}" for n in names)
    assert "empty_room: world room, robot mybot, map true, 4 goals; 20 trials\n    The paper's first experiment" in out
    assert main(["experiment", "run"]) == 2  # no scenario named: one line that says where to find them
    line = _one_line(capsys)
    assert "which scenario?" in line and "`navlab experiment list`" in line


def test_map_save_with_nothing_running_says_where_a_map_comes_from(tmp_path) -> None:
    import os

    proc = subprocess.run(
        [sys.executable, "-m", "navlab.cli", "map", "save", "--out", "m"],
        env={**os.environ, "TMPDIR": str(tmp_path)},  # no other launch's socket
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith("navlab: error: no running navlab launch to save a /map from")
    assert "navlab map save --launch mapping" in proc.stderr and "navlab map --teleop" in proc.stderr
    assert not (tmp_path / "m").exists()
