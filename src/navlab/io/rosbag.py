"""rosbag2 recording (MCAP storage) and reading, through rosbags.

``Recorder`` listens to every message an executor publishes and writes the chosen topics,
stamped with simulated time. The bag is written inside a hidden staging folder beside it
(``<parent>/.<name>.partial/<name>``) and moved into place when closed, so a crashed run never leaves
a half-written bag under the asked name, and the finished bag's files and metadata carry its final
name (``<name>/<name>.mcap``) as ``ros2 bag record`` would write them.
"""

from __future__ import annotations

import fnmatch
import json
import shutil
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.rosbag2.errors import ReaderError, WriterError

from navlab.core.executor import Executor
from navlab.errors import NavlabError
from navlab.msgs import TYPESTORE, type_name

GRAPH_KEY = "navlab.graph"


class BagError(NavlabError):
    """A bag cannot be written or read."""


class Recorder:
    """Record topics of a running executor into a rosbag2 directory (MCAP storage).

    ``topics``: names or glob patterns (``/tf*``); empty means every topic.
    """

    def __init__(self, executor: Executor, path: str | Path, *, topics: Sequence[str] = ()) -> None:
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
        self._patterns = [t if t.startswith("/") else "/" + t for t in topics]
        self._connections: dict[str, Any] = {}
        self._executor = executor
        self.count = 0
        # Latched topics (/map, /tf_static) were published before recording began: record their last
        # message now, as `ros2 bag record` does for transient_local publishers.
        for name, topic in sorted(executor.topics.items()):
            for msg in topic.latched.values():
                self._on_message(name, msg, executor.now_ns)
        executor.add_listener(self._on_message)

    def _wanted(self, topic: str) -> bool:
        return not self._patterns or any(fnmatch.fnmatchcase(topic, p) for p in self._patterns)

    def _on_message(self, topic: str, msg: Any, t_ns: int) -> None:
        conn = self._connections.get(topic)
        if conn is None:
            if not self._wanted(topic):
                self._connections[topic] = False
                return
            conn = self._connections[topic] = self._writer.add_connection(
                topic, type_name(msg), typestore=TYPESTORE
            )
        if conn is False:
            return
        self._writer.write(conn, t_ns, TYPESTORE.serialize_cdr(msg, type_name(msg)))
        self.count += 1

    def close(self) -> Path:
        """Finish the bag (with the node/topic graph as custom data) and move it to its final name."""
        from navlab.core.graph import Graph

        self._executor.remove_listener(self._on_message)
        self._writer.set_custom_data(GRAPH_KEY, json.dumps(Graph.from_executor(self._executor).to_json()))
        self._writer.close()
        self._tmp.rename(self.path)
        self._staging.rmdir()
        return self.path

    def __enter__(self) -> Recorder:
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
