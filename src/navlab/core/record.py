"""Recording a running executor into a rosbag2 (MCAP), as ``ros2 bag record`` does next to a ROS launch.

The file side (staging folder, rename into place, reading back) is ``navlab.io.rosbag``; this module
only listens to the executor, picks topics and stores the node/topic graph when the bag is closed.
"""

from __future__ import annotations

import fnmatch
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from navlab.core.executor import Executor
from navlab.core.graph import Graph
from navlab.io import GRAPH_KEY, BagWriter


class Recorder:
    """Record topics of a running executor into a rosbag2 directory (MCAP storage), stamped with
    simulated time (ns).

    ``topics``: names or glob patterns (``/tf*``); empty means every topic. Latched topics (``/map``,
    ``/tf_static``) published before the recorder started are recorded with their last message, as
    ``ros2 bag record`` does for transient_local publishers. ``close()`` stores the node/topic graph
    in the bag's metadata and moves the bag to ``path``.
    """

    def __init__(self, executor: Executor, path: str | Path, *, topics: Sequence[str] = ()) -> None:
        self._bag = BagWriter(path)
        self.path = self._bag.path
        self._patterns = [t if t.startswith("/") else "/" + t for t in topics]
        self._wanted_cache: dict[str, bool] = {}
        self._executor = executor
        for name, topic in sorted(executor.topics.items()):
            for msg in topic.latched.values():
                self._on_message(name, msg, executor.now_ns)
        executor.add_listener(self._on_message)

    @property
    def count(self) -> int:
        """Messages written so far."""
        return self._bag.count

    def _wanted(self, topic: str) -> bool:
        wanted = self._wanted_cache.get(topic)
        if wanted is None:
            wanted = not self._patterns or any(fnmatch.fnmatchcase(topic, p) for p in self._patterns)
            self._wanted_cache[topic] = wanted
        return wanted

    def _on_message(self, topic: str, msg: Any, t_ns: int) -> None:
        if self._wanted(topic):
            self._bag.write(topic, msg, t_ns)

    def close(self) -> Path:
        """Stop listening, store the node/topic graph, finish the bag and move it to its final name."""
        if self._bag.closed:
            return self.path
        self._executor.remove_listener(self._on_message)
        self._bag.set_custom_data(GRAPH_KEY, json.dumps(Graph.from_executor(self._executor).to_json()))
        return self._bag.close()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
