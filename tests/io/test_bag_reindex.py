"""A recording killed with SIGKILL is recovered by `navlab bag reindex` (issue 14)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from navlab.cli import main
from navlab.io.rosbag import bag_topics, read_bag

RECORDER = """
import sys, time
import numpy as np
from navlab.io.rosbag import BagWriter
from navlab.msgs import TYPESTORE
scan_t = TYPESTORE.types["sensor_msgs/msg/LaserScan"]
header_t = TYPESTORE.types["std_msgs/msg/Header"]
time_t = TYPESTORE.types["builtin_interfaces/msg/Time"]
string_t = TYPESTORE.types["std_msgs/msg/String"]
bag = BagWriter(sys.argv[1])
for k in range(1500):  # about 4.5 MB of scans: several 1 MiB chunks reach the disk
    t = k * 25_000_000
    stamp = time_t(sec=t // 10**9, nanosec=t % 10**9)
    ranges = np.full(720, 1.0 + k % 7, dtype=np.float32)
    bag.write("/scan", scan_t(header_t(stamp, "laser"), -3.14, 3.14, 0.0087, 0.0, 0.025, 0.1, 30.0, ranges,
                              np.zeros(0, dtype=np.float32)), t)
    bag.write("/chatter", string_t(f"hello {k}"), t)
bag._writer.storage.bio.flush()  # what the OS had by the time of the kill
print("recording", flush=True)
time.sleep(600)
"""


def test_a_recording_killed_with_sigkill_is_reindexed(tmp_path: Path, capsys) -> None:
    out = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-c", RECORDER, str(out)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "recording"
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
    finally:
        if proc.poll() is None:
            proc.kill()
    partial = tmp_path / ".run.partial" / "run"
    assert not out.exists() and not (partial / "metadata.yaml").exists()  # killed: no bag, no metadata
    assert main(["bag", "reindex", str(out)]) == 0
    assert "reindexed" in capsys.readouterr().out
    topics = bag_topics(out)
    assert set(topics) == {"/scan", "/chatter"} and topics["/scan"][0] == "sensor_msgs/msg/LaserScan"
    assert 1000 <= topics["/scan"][1] <= 1500  # every complete chunk; the one in memory at the kill is lost
    times = [t for _, t, _ in read_bag(out, topics=["/scan"])]
    assert times == sorted(times) and times[0] == 0
    assert not (tmp_path / ".run.partial").exists()
    assert main(["bag", "reindex", str(tmp_path / "nothing")]) == 2


def _damaged_bag(folder: Path) -> Path:
    """A small recording in ``folder`` whose metadata is gone and whose MCAP file was cut short."""
    from navlab.io.rosbag import BagWriter
    from navlab.msgs import TYPESTORE

    string_t = TYPESTORE.types["std_msgs/msg/String"]
    with BagWriter(folder) as bag:
        for k in range(200):
            bag.write("/chatter", string_t(f"hello {k}"), k * 1000)
    (folder / "metadata.yaml").unlink()
    mcap = folder / f"{folder.name}.mcap"
    mcap.write_bytes(mcap.read_bytes()[:-300])
    return mcap


def test_reindex_never_removes_what_it_did_not_create(tmp_path: Path, capsys) -> None:
    """Issue 21: the user's other files and folders in DIR survive a reindex, and so does the damaged file."""
    folder = tmp_path / "run"
    mcap = _damaged_bag(folder)
    damaged = mcap.read_bytes()
    (folder / "notes.txt").write_text("my notes")
    (folder / "other_recording").mkdir()
    (folder / "other_recording" / "data.db3").write_bytes(b"\x00" * 10)
    (folder / "other.mcap.damaged").write_text("a name the kept copy must not take")
    assert main(["bag", "reindex", str(folder)]) == 0
    assert "kept the damaged file" in capsys.readouterr().out
    assert (folder / "notes.txt").read_text() == "my notes"
    assert (folder / "other_recording" / "data.db3").read_bytes() == b"\x00" * 10
    assert (folder / "other.mcap.damaged").read_text().startswith("a name")
    assert (folder / "run.mcap.damaged").read_bytes() == damaged
    assert bag_topics(folder)["/chatter"][0] == "std_msgs/msg/String"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]  # no staging folder left behind


def test_reindex_out_leaves_the_damaged_folder_as_it_was(tmp_path: Path) -> None:
    folder = tmp_path / "run"
    _damaged_bag(folder)
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    assert main(["bag", "reindex", str(folder), "--out", str(tmp_path / "fixed")]) == 0
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    assert bag_topics(tmp_path / "fixed")["/chatter"][1] > 0
    assert main(["bag", "reindex", str(folder), "--out", str(tmp_path / "fixed")]) == 2  # never over a folder


def test_a_new_recording_never_removes_a_killed_one(tmp_path: Path) -> None:
    from navlab.io import BagError
    from navlab.io.rosbag import BagWriter

    staging = tmp_path / ".run.partial" / "run"
    staging.mkdir(parents=True)
    (staging / "run.mcap").write_bytes(b"data of a killed run")
    with pytest.raises(BagError, match="navlab bag reindex"):
        BagWriter(tmp_path / "run")
    assert (staging / "run.mcap").read_bytes() == b"data of a killed run"
