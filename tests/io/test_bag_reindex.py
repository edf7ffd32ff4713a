"""A recording killed with SIGKILL is recovered by `navlab bag reindex` (issue 14)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

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
