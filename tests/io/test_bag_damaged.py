"""Damaged recordings (issue 21): every reader ends in one line, "DIR: damaged recording: ...; try `navlab bag
reindex`", never a traceback or a hang; pipes and devices are refused before anything opens them."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import pytest

from navlab.cli import main
from navlab.io.rosbag import BagWriter
from navlab.msgs import TYPESTORE


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    string_t = TYPESTORE.types["std_msgs/msg/String"]
    with BagWriter(tmp_path / "rec") as writer:
        for k in range(50):
            writer.write("/chatter", string_t(f"hello {k}"), k * 1000)
    return tmp_path / "rec"


def _flip_bytes(bag: Path) -> None:
    mcap = bag / "rec.mcap"
    data = bytearray(mcap.read_bytes())
    for k in range(60, len(data) - 60, 7):
        data[k] ^= 0x5A
    mcap.write_bytes(bytes(data))


def _fifo(bag: Path) -> None:
    (bag / "rec.mcap").unlink()
    os.mkfifo(bag / "rec.mcap")


def _bad_metadata(bag: Path) -> None:
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information: {version: 8, relative_file_paths: 7}\n")


def _outside(bag: Path) -> None:
    meta = bag / "metadata.yaml"
    meta.write_text(meta.read_text().replace("- rec.mcap", "- ../../../dev/zero"))


def _graph_garbage(bag: Path) -> None:
    meta = bag / "metadata.yaml"
    meta.write_text(meta.read_text() + "  custom_data: {navlab.graph: '[1, 2'}\n")


@pytest.mark.parametrize("damage", [_flip_bytes, _fifo, _bad_metadata, _outside, _graph_garbage])
@pytest.mark.parametrize(
    "argv",
    [
        ["topic", "echo", "/chatter", "--bag"],
        ["node", "list", "--bag"],
        ["topic", "list", "--bag"],
        ["graph", "--out", "g", "--bag"],
    ],
)
def test_damaged_recordings_end_in_one_line(
    bag: Path,
    damage: Callable[[Path], None],
    argv: list[str],
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    damage(bag)
    monkeypatch.chdir(bag.parent)
    code = main([*argv, str(bag)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert f"{bag}: damaged recording: " in err and err.endswith(f"try `navlab bag reindex {bag}`")


def test_a_fifo_named_as_a_recording_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    os.mkfifo(tmp_path / "rec.mcap")
    assert main(["topic", "echo", "/x", "--bag", str(tmp_path / "rec.mcap")]) == 2
    assert "expected a rosbag2 directory" in capsys.readouterr().err
    os.mkfifo(tmp_path / "folder.mcap.fifo")
    (tmp_path / "killed").mkdir()
    os.mkfifo(tmp_path / "killed" / "killed.mcap")
    assert main(["bag", "reindex", str(tmp_path / "killed")]) == 2
    assert "named pipe" in capsys.readouterr().err
