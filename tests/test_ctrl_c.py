"""Ctrl-C (SIGINT) and SIGTERM stop `navlab teleop` at once and give the terminal back, also when it runs as a
background job of a script (SIGINT inherited ignored: Python then installs no handler of its own); in
`navlab map --teleop` they end the drive and save the map."""

from __future__ import annotations

import signal
import termios
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from cli_terminal import Terminal


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_teleop_stops_on_a_signal_with_sigint_inherited_ignored(tmp_path: Path, sig: int) -> None:
    term = Terminal(["teleop", "--world", "room"], tmp_path, ignore_sigint=True)
    try:
        before = term.lflag()
        term.wait_for("sending linear.x", 120.0)  # driving: keys are read in cbreak mode
        assert not term.lflag() & termios.ICANON
        term.signal(sig)
        code = term.finish(15.0, after=signal.Signals(sig).name)
        assert code == 0, term.stderr
        assert "stopped at" in term.stdout and "Traceback" not in term.stderr
        assert term.lflag() == before  # the terminal's settings are back (line editing, echo)
    finally:
        term.close()


def test_map_teleop_saves_the_map_on_ctrl_c(tmp_path: Path) -> None:
    """gmapping + teleop, then Ctrl-C: the drive stops and the map so far is saved whole (map_saver's files,
    the picture, the trajectory) with walls where the world's walls are, and the verb says where it went."""
    from navlab.experiments import read_map_trajectory, score_map
    from navlab.mapping import load_map
    from navlab.world import load_world, true_occupancy

    term = Terminal(["map", "--teleop", "--world", "room", "--out", "m"], tmp_path)
    try:
        before = term.lflag()
        term.wait_for("CTRL-C: quit", 120.0, stream="stdout")  # teleop_twist_keyboard's help
        term.wait_for("sending linear.x", 60.0)  # its status line: the drive runs
        term.keys(b"i")  # forward at 0.5 m/s, in real time
        term.wait_for("sending linear.x +0.50", 60.0)
        time.sleep(4.0)
        term.keys(b"k")
        term.signal(signal.SIGINT)
        code = term.finish(60.0, after="SIGINT")
        assert code == 0, term.stderr
        assert term.lflag() == before
    finally:
        term.close()
    assert "saving the map" in term.stderr and "Traceback" not in term.stderr
    assert "stopped by Ctrl-C: saved m/map.yaml (+ map.pgm, map.png) after" in term.stdout
    out = tmp_path / "m"
    assert sorted(p.name for p in out.iterdir()) == ["map.pgm", "map.png", "map.yaml", "trajectory.txt"]  # no temp
    _est, truth = read_map_trajectory(out / "trajectory.txt")
    assert truth[-1, 0] - truth[0, 0] > 0.5, "the robot did not drive forward before Ctrl-C"
    grid = load_map(out / "map.yaml")
    score = score_map(grid, true_occupancy(load_world("room"), grid))  # mybot's odometry: map frame = world
    assert score["occupied_cells"] > 300 and score["precision"] > 0.9, score


def test_experiment_run_keeps_whole_trials_on_ctrl_c(tmp_path: Path) -> None:
    """Ctrl-C reaches the driver and its worker processes (a terminal signals the whole job): the finished
    trials stay in results.jsonl, whole, the workers leave no temporary folder, and the verb says so."""
    import json

    term = Terminal(["experiment", "run", "empty_room", "--trials", "6", "--workers", "2", "--out", "r"], tmp_path)
    results = tmp_path / "r" / "results.jsonl"
    try:
        deadline = time.monotonic() + 240.0
        while not (results.is_file() and results.read_text().count("\n") >= 1):
            if term.proc.poll() is not None or time.monotonic() > deadline:
                term._fail("no trial finished")
            time.sleep(0.2)
        term.signal(signal.SIGINT)
        code = term.finish(60.0, after="SIGINT")
    finally:
        term.close()
    lines = results.read_text().splitlines()
    assert code == 130 and 1 <= len(lines) < 6, term.stderr
    trials = [json.loads(line) for line in lines]  # each line one whole trial
    assert len({t["trial"] for t in trials}) == len(lines) and all("success" in t for t in trials)
    assert f"{len(lines)} finished trial" in term.stderr and "the same command resumes" in term.stderr
    assert "Traceback" not in term.stderr and "leaked" not in term.stderr, term.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r"]  # no trial's temporary folder left (TMPDIR here)


def test_slam_interrupted_writes_nothing_and_says_so(tmp_path: Path, dataset: Callable[[str], Path]) -> None:
    """SIGTERM (as Ctrl-C) in the middle of offline SLAM on CSAIL (~14 s of CPU): nothing half-written."""
    term = Terminal(["slam", "--log", str(dataset("mit-csail/mit-csail.clf")), "--out", "o"], tmp_path)
    try:
        time.sleep(4.0)
        assert term.proc.poll() is None, "navlab slam ended before it was interrupted"
        term.signal(signal.SIGTERM)
        code = term.finish(30.0, after="SIGTERM")
    finally:
        term.close()
    assert code == 130 and "navlab: interrupted; SLAM had not finished: nothing written to o" in term.stderr
    assert not (tmp_path / "o").exists()


def test_sim_ends_on_a_signal_as_at_its_duration_with_the_recording_whole(tmp_path: Path) -> None:
    """`navlab sim` in real time, SIGINT (a script's background job: SIGINT inherited ignored): the run ends,
    the summary is printed and the rosbag2 recording is closed whole, as at the end of --duration."""
    from navlab.io import bag_topics

    term = Terminal(["sim", "--duration", "600", "--rate", "1", "--record", "bag"], tmp_path, ignore_sigint=True)
    try:
        deadline = time.monotonic() + 120.0
        while not any(tmp_path.glob("**/*.mcap")):  # the recording is staged: the run has started
            if term.proc.poll() is not None or time.monotonic() > deadline:
                term._fail("no recording started")
            time.sleep(0.2)
        time.sleep(2.0)
        term.signal(signal.SIGINT)
        code = term.finish(30.0, after="SIGINT")
    finally:
        term.close()
    assert code == 0 and "stopping the simulation" in term.stderr, term.stderr
    assert "record: bag" in term.stdout and "sim_s: " in term.stdout
    assert bag_topics(tmp_path / "bag")["/odom"][1] > 10  # whole: indexed, readable, /odom at 20+ Hz


def test_the_first_signal_ends_a_graceful_run_between_events_the_second_interrupts(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from navlab.cli.runs import stop_signals
    from navlab.core import Context, Executor, Node, run_for

    ex = Executor(seed=0)
    ticks: list[int] = []

    def tick() -> None:
        ticks.append(ex.now_ns)
        if len(ticks) == 5:
            signal.raise_signal(signal.SIGINT)  # Ctrl-C inside a callback: the callback still ends whole

    Node("ticker", context=Context(ex)).create_timer(0.1, tick)
    with stop_signals() as stop:
        with pytest.raises(KeyboardInterrupt):  # not graceful yet: Ctrl-C interrupts where it is
            signal.raise_signal(signal.SIGTERM)
        stop.graceful(ex, "stopping the ticker")
        run_for(ex, 100.0, quiet=True)
        assert stop.requested and ex.stopped and 5 <= len(ticks) <= 6 and ex.now_ns < 1e9
        assert "stopping the ticker" in capsys.readouterr().err
        with pytest.raises(KeyboardInterrupt):  # the second one quits
            signal.raise_signal(signal.SIGINT)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # the previous handler is back
