"""rosbag2 (MCAP storage) writing and reading, through rosbags; plain file I/O, no executor.

``BagWriter`` writes messages into a bag inside a hidden staging folder beside it
(``<parent>/.<name>.partial/<name>``) and moves it into place when closed, so a crashed run never
leaves a half-written bag under the asked name, and the finished bag's files and metadata carry its
final name (``<name>/<name>.mcap``) as ``ros2 bag record`` would write them. Recording a running
executor is ``navlab.core.record.Recorder``, built on it.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.rosbag2.errors import ReaderError, WriterError

from navlab.io.errors import BagError
from navlab.msgs import TYPESTORE, type_name

__all__ = ["GRAPH_KEY", "BagError", "BagWriter", "bag_graph", "bag_topics", "read_bag"]

GRAPH_KEY = "navlab.graph"  # custom-data key of the node/topic graph a navlab recording stores


class BagWriter:
    """Write navlab (rosbags typestore) messages into a new rosbag2 directory with MCAP storage.

    ``write(topic, msg, t_ns)`` adds a connection on a topic's first message; ``t_ns`` is the receive
    time in integer nanoseconds. ``close()`` finishes the bag and renames it to ``path``.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        if self.path.exists():
            raise BagError(f"{self.path}: already exists; choose a new directory for the recording")
        self._staging = self.path.parent / f".{self.path.name}.partial"
        self._tmp = self._staging / self.path.name
        try:
            if self._staging.exists():  # left behind by a crashed run
                shutil.rmtree(self._staging)
            self._staging.mkdir(parents=True)
            self._writer = Writer(self._tmp, version=8, storage_plugin=StoragePlugin.MCAP)
            self._writer.open()
        except (OSError, WriterError) as exc:
            raise BagError(f"{self.path}: cannot start the recording ({exc})") from None
        self._connections: dict[str, Any] = {}
        self.count = 0
        self.closed = False

    def write(self, topic: str, msg: Any, t_ns: int) -> None:
        """Append ``msg`` on ``topic`` at ``t_ns`` (ns); the topic's type is taken from its first message."""
        conn = self._connections.get(topic)
        if conn is None:
            conn = self._connections[topic] = self._writer.add_connection(topic, type_name(msg), typestore=TYPESTORE)
        self._writer.write(conn, t_ns, TYPESTORE.serialize_cdr(msg, type_name(msg)))
        self.count += 1

    def set_custom_data(self, key: str, value: str) -> None:
        """Store ``key: value`` in the bag's metadata (``custom_data``)."""
        self._writer.set_custom_data(key, value)

    def close(self) -> Path:
        """Finish the bag and move it to its final name; returns that path."""
        if not self.closed:
            self.closed = True
            self._writer.close()
            self._tmp.rename(self.path)
            self._staging.rmdir()
        return self.path

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_bag(path: str | Path, *, topics: Sequence[str] = ()) -> Iterator[tuple[str, int, Any]]:
    """Yield ``(topic, t_ns, msg)`` from a rosbag2 directory, deserialised to navlab messages."""
    try:
        with Reader(Path(path)) as reader:
            conns = [c for c in reader.connections if not topics or c.topic in topics]
            for conn, t_ns, raw in reader.messages(connections=conns):
                yield conn.topic, t_ns, TYPESTORE.deserialize_cdr(raw, conn.msgtype)
    except (ReaderError, FileNotFoundError) as exc:
        raise BagError(f"{path}: cannot read as a rosbag2 directory ({exc})") from None


def bag_topics(path: str | Path) -> dict[str, tuple[str, int]]:
    """``{topic: (type, message count)}`` of a rosbag2 directory."""
    try:
        with Reader(Path(path)) as reader:
            return {c.topic: (c.msgtype, c.msgcount) for c in reader.connections}
    except (ReaderError, FileNotFoundError) as exc:
        raise BagError(f"{path}: cannot read as a rosbag2 directory ({exc})") from None


def bag_graph(path: str | Path) -> dict[str, Any] | None:
    """The node/topic graph a navlab recording stored in its metadata (None for other bags)."""
    import yaml

    meta = Path(path) / "metadata.yaml"
    try:
        info = yaml.safe_load(meta.read_text())["rosbag2_bagfile_information"]
    except (OSError, KeyError, TypeError, yaml.YAMLError) as exc:
        raise BagError(f"{meta}: cannot read bag metadata ({exc})") from None
    raw = (info.get("custom_data") or {}).get(GRAPH_KEY)
    return json.loads(raw) if raw else None
