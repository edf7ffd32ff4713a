"""`navlab topic echo` behaves as rostopic echo: YAML with --- separators (/tf too), -n N stops after N, a silent
topic ends within the run's duration with one line, and a reader that leaves (`| head`) is no error."""

from __future__ import annotations

import re
import subprocess
import sys
import time

import pytest

from navlab.cli import main


def test_count_stops_after_n_messages_with_separators(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["topic", "echo", "/chatter", "-n", "3", "--launch", "talker_listener", "--duration", "60"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n---\n") == 3
    assert out.splitlines()[0] == 'data: "Hello World: 1"'


def test_tf_is_yaml_like_every_other_message(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["topic", "echo", "/tf", "-n", "1", "--launch", "sim", "world:=room", "--duration", "2"]) == 0
    out = capsys.readouterr().out
    assert "{" not in out and out.startswith("transforms:\n  -\n    header:\n")
    assert '      frame_id: "odom"' in out and out.endswith("---\n")


def test_a_silent_topic_with_count_ends_with_the_run_and_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    t0 = time.perf_counter()
    code = main(["topic", "echo", "/silence", "-n", "1", "--launch", "talker_listener", "--duration", "3"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and time.perf_counter() - t0 < 10
    assert err[0] == "WARNING: topic [/silence] does not appear to be published yet"
    assert err[1].startswith("navlab: error: no topic '/silence' in this launch after 3 simulated s")


def test_fewer_messages_than_count_before_the_end_is_exit_1(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["topic", "echo", "/chatter", "-n", "1000", "--launch", "talker_listener", "--duration", "1"])
    out = capsys.readouterr()
    assert code == 1 and 0 < out.out.count("---") < 1000
    assert re.fullmatch(r"navlab: 1 simulated s passed after \d+ of 1000 messages on /chatter\n", out.err)


def test_piped_into_head_is_not_an_error() -> None:
    cmd = [
        sys.executable,
        "-m",
        "navlab.cli",
        "topic",
        "echo",
        "/chatter",
        "--launch",
        "talker_listener",
        "--duration",
        "5000",
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout is not None and proc.stderr is not None
    first = proc.stdout.readline()
    proc.stdout.close()  # what `| head -1` does after one line
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 0
    assert first.startswith(b"data:") and err == ""
