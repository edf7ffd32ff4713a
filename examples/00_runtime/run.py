"""00 — the runtime: two nodes, a topic, a timer, simulated time, a recording.

Run:  python examples/00_runtime/run.py
"""

from pathlib import Path
from tempfile import mkdtemp

import navlab
from navlab import msgs
from navlab.core import Node, Recorder
from navlab.io import read_bag


class Counter(Node):
    """Publishes a growing number on /count at 5 Hz of simulated time."""

    def __init__(self) -> None:
        super().__init__("counter")  # rclpy's constructor: joins the executor navlab.init() made
        self.n = 0
        self.pub = self.create_publisher(msgs.Float64, "count")
        self.create_timer(0.2, self.tick)

    def tick(self) -> None:
        self.n += 1
        self.pub.publish(msgs.Float64(data=float(self.n)))


ctx = navlab.init(seed=0, rate=0.0)  # rclpy.init(); rate=0: as fast as the CPU allows, 1.0 would be real time
ex = ctx.executor
Counter()
printer = Node("printer")
printer.create_subscription(msgs.Float64, "count", lambda m: printer.get_logger().warning("heard %s", m.data))
bag = Path(mkdtemp()) / "count_bag"
with Recorder(ex, bag):
    ex.run(1.0)  # one simulated second: five messages
print("recorded:", [(topic, t / 1e9, m.data) for topic, t, m in read_bag(bag)])
