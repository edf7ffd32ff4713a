"""The ``map_server`` node: publishes a map_server YAML + image map, latched, like ROS 1 map_server.

Parameters: ``yaml_filename`` (the map YAML; Nav2's name, ROS 1 passes it on the command line) and
``frame_id`` (default ``map``). Publishes ``map`` (nav_msgs/OccupancyGrid) and ``map_metadata``
(nav_msgs/MapMetaData), both latched, once at start; service ``static_map`` returns the grid.
"""

from __future__ import annotations

from typing import Any

from navlab import msgs
from navlab.core import Executor, Node
from navlab.mapping.errors import MappingError
from navlab.mapping.mapfile import load_map


class MapServer(Node):
    """Serve one map file on the latched ``map`` topic."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "map_server",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.yaml_filename = self.declare_parameter("yaml_filename", "", aliases=("map", "map_file"))
        self.frame_id = self.declare_parameter("frame_id", "map")
        self.check_parameters()
        if not self.yaml_filename:
            raise MappingError(
                f"node {self.fully_qualified_name}: parameter 'yaml_filename' (the map YAML) is required"
            )
        self.grid = load_map(self.yaml_filename, frame_id=self.frame_id)
        self.map_pub = self.create_publisher(msgs.OccupancyGrid, "map", 1, latched=True)
        self.meta_pub = self.create_publisher(msgs.MapMetaData, "map_metadata", 1, latched=True)
        self.create_service("static_map", self._srv_static_map)
        stamp = self.get_clock().now_ns()
        self.msg = self.grid.to_msg(stamp)
        self.map_pub.publish(self.msg)
        self.meta_pub.publish(self.msg.info)
        self.get_logger().info(
            f"serving {self.yaml_filename}: {self.grid.width} x {self.grid.height} cells at "
            f"{self.grid.resolution:.3f} m/cell"
        )

    def _srv_static_map(self, request: Any = None) -> Any:
        """nav_msgs/GetMap: the served grid."""
        return self.msg
