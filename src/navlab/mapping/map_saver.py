"""The ``map_saver`` node (map_server's ``map_saver -f NAME``): saves the first map it receives.

Parameters: ``map_file`` (the ``-f`` base name, default ``map``: writes ``NAME.yaml`` + ``NAME.pgm``),
``threshold_occupied`` (``--occ``, %, default 65) and ``threshold_free`` (``--free``, %, default 25).
Subscribes ``map`` (nav_msgs/OccupancyGrid); like ROS's map_saver it writes the whole grid once and
is then done (later maps are ignored).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from navlab import msgs
from navlab.core import Executor, Node
from navlab.grid import GridMap
from navlab.mapping.mapfile import save_map


class MapSaver(Node):
    """Write the first ``map`` message as map_saver does."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "map_saver",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.map_file = str(self.declare_parameter("map_file", "map"))
        self.occ = int(self.declare_parameter("threshold_occupied", 65))
        self.free = int(self.declare_parameter("threshold_free", 25))
        self.saved: Path | None = None
        self.create_subscription(msgs.OccupancyGrid, "map", self._on_map, 1)
        self.get_logger().info("Waiting for the map")

    def _on_map(self, msg: Any) -> None:
        if self.saved is not None:
            return
        yaml_path = Path(self.map_file).expanduser().with_suffix(".yaml")
        save_map(
            GridMap.from_msg(msg),
            yaml_path,
            image_name=yaml_path.with_suffix(".pgm").name,
            threshold_occupied=self.occ,
            threshold_free=self.free,
            crop_margin_cells=None,
        )
        self.saved = yaml_path
        self.get_logger().info(f"Done: wrote {yaml_path} and {yaml_path.with_suffix('.pgm').name}")
