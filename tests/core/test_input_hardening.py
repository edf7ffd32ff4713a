"""Hostile and careless inputs to parameter and launch files get one clear error naming the file (issue 14)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from navlab.core import LaunchError, ParameterError
from navlab.core.launch import start
from navlab.core.params import read_yaml

BOMB = "\n".join(
    ["a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    + [f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 10) + "]" for k in range(1, 10)]
)


def _write(tmp_path: Path, name: str, data: str | bytes) -> Path:
    p = tmp_path / name
    p.write_bytes(data if isinstance(data, bytes) else data.encode())
    return p


def test_alias_bomb_is_refused_but_small_aliases_and_merge_keys_load(tmp_path: Path) -> None:
    with pytest.raises(ParameterError, match=r"bomb\.yaml:\d+:\d+: .*alias"):
        read_yaml(_write(tmp_path, "bomb.yaml", BOMB))
    ok = read_yaml(_write(tmp_path, "ok.yaml", "base: &b {x: 1}\nuse: {<<: *b, y: 2}\n"))
    assert ok["use"] == {"x": 1, "y": 2}


def test_deep_nesting_binary_and_pipes_are_errors_not_tracebacks(tmp_path: Path) -> None:
    with pytest.raises(ParameterError, match=r"deep\.yaml:1:\d+: .*nested deeper"):
        read_yaml(_write(tmp_path, "deep.yaml", "x: " + "[" * 5000 + "]" * 5000))
    with pytest.raises(ParameterError, match=r"bin\.yaml:2: byte 0xff is not UTF-8"):
        read_yaml(_write(tmp_path, "bin.yaml", b"a: 1\nb: \xff\xfe\n"))
    os.mkfifo(tmp_path / "pipe.yaml")
    with pytest.raises(ParameterError, match=r"pipe\.yaml: is a named pipe"):
        read_yaml(tmp_path / "pipe.yaml")  # would block forever if opened for reading
    with pytest.raises(ParameterError, match=r"nul\.yaml:1:\d+: malformed YAML"):
        read_yaml(_write(tmp_path, "nul.yaml", "a: 1\x00\n"))


@pytest.mark.parametrize(
    ("entries", "message"),
    [
        ("- let: {value: x}", r"entry 1 \(let\): missing 'name'"),
        ("- let: {name: x}", r"entry 1 \(let\): a let needs a 'value'"),
        ("- include: {arg: []}", r"entry 1 \(include\): missing 'file'"),
        ("- node: {exec: talker, remap: [{to: x}]}", r"remap\[0\] needs 'from' and 'to'"),
        ("- node: {exec: talker, if: maybe}", r"'if' is 'maybe'; expected true or false"),
        ("- node: {exec: talker, name: '$(env NAVLAB_TEST_SURELY_UNSET)'}", r"NAVLAB_TEST_SURELY_UNSET.*not set"),
        ("- node: {exec: 'os:getcwd'}", r"os:getcwd is not a navlab Node class"),
        ("- node: {exec: talker, param: [{name: rate, value: 0}]}", r"rate.*expected Hz > 0.*'talker'"),
        ("- node: {exec: talker, param: [{name: rate, value: .nan}]}", r"'rate': expected a number, got nan.*'talker'"),
    ],
)
def test_malformed_launch_entries_name_the_file_and_entry(tmp_path: Path, entries: str, message: str) -> None:
    launch = _write(tmp_path, "bad.launch.yaml", "launch:\n" + entries + "\n")
    with pytest.raises((LaunchError, ParameterError), match=message) as err:  # the problem, and where it is
        start(str(launch))
    assert "bad.launch.yaml" in str(err.value)


def test_env_with_default_and_boolean_conditions_still_work(tmp_path: Path) -> None:
    launch = _write(
        tmp_path,
        "ok.launch.yaml",
        (
            "launch:\n- node: {exec: talker, name: \"$(env NAVLAB_TEST_SURELY_UNSET talky)\", if: 'True'}\n"
            "- node: {exec: listener, unless: '1'}\n"
        ),
    )
    session = start(str(launch))
    assert list(session.nodes) == ["/talky"]


def test_node_parameter_errors_name_the_launch_and_parameter_file(tmp_path: Path) -> None:
    _write(tmp_path, "talk.yaml", "rate: true\n")
    launch = _write(tmp_path, "p.launch.yaml", "launch:\n- node: {exec: talker, param: [{from: talk.yaml}]}\n")
    with pytest.raises(
        ParameterError,
        match=r"^parameter 'rate': expected a number.* \(in .*p\.launch\.yaml: entry 1 "
        r"\(node\) 'talker' \(parameters from talk\.yaml\)\)$",
    ):
        start(str(launch))


def test_an_unwritable_output_is_one_line_and_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from navlab.cli import main

    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    code = main(["graph", "--launch", "talker_listener", "--duration", "0.2", "--out", str(blocker / "sub" / "g")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("navlab: error: ") and "file" in err[0]
