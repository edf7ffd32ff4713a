"""demo_nodes_py's talker and listener: the smallest publisher and subscriber, used by examples and bench."""

from __future__ import annotations

from typing import Any

from navlab.core.errors import ParameterError
from navlab.core.executor import Executor
from navlab.core.node import Node
from navlab.msgs import String


class Talker(Node):
    """Publishes ``std_msgs/String`` "Hello World: N" on ``chatter`` at ``rate`` Hz."""

    def __init__(
        self, executor: Executor, *, name: str = "talker", parameters: dict[str, Any] | None = None, namespace: str = ""
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        rate = self.declare_parameter("rate", 1.0)
        if not isinstance(rate, int | float) or not 0 < rate < float("inf"):
            raise ParameterError(f"node {self.fully_qualified_name}: parameter 'rate': expected Hz > 0, got {rate!r}")
        self.count = 0
        self.pub = self.create_publisher(String, "chatter", 10)
        self.create_timer(1.0 / rate, self._tick)

    def _tick(self) -> None:
        self.count += 1
        self.pub.publish(String(data=f"Hello World: {self.count}"))


class Listener(Node):
    """Subscribes to ``chatter`` and keeps what it heard in ``self.heard``."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "listener",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.heard: list[str] = []
        self.create_subscription(String, "chatter", lambda m: self.heard.append(m.data), 10)
