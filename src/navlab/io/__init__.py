"""File formats and data: rosbag2 (``rosbag``), CARMEN logs (``carmen``), pose files (``poses``), atomic
writes (``files``) and where datasets live (``datasets``, the ``NAVLAB_DATA`` setting).

A leaf package: it imports nothing of navlab above errors, msgs, geometry and lazy. Names in ``_EXPORTS`` load
their module on first use (the rosbag2 reader loads rosbags, the CARMEN reader numpy).
"""

from typing import TYPE_CHECKING

from navlab.io.datasets import data_dir, dataset
from navlab.io.errors import BagError, DatasetNotFoundError, IoError
from navlab.lazy import lazy_exports

__all__ = [
    "FLOAT32",
    "GRAPH_KEY",
    "MAX_TEXT_BYTES",
    "UINT16",
    "BagError",
    "BagWriter",
    "CarmenLog",
    "DatasetNotFoundError",
    "IoError",
    "LaserScan2D",
    "OdomRecord",
    "atomic_path",
    "bag_graph",
    "bag_topics",
    "check_regular_file",
    "cloud_message",
    "data_dir",
    "data_file",
    "dataset",
    "machine_memory_bytes",
    "move_points",
    "pack_cloud",
    "point_field",
    "read_bag",
    "read_bytes_checked",
    "read_carmen",
    "read_poses",
    "read_table",
    "read_text_checked",
    "read_xyz",
    "reindex_bag",
    "save_figure_atomic",
    "skipped_summary",
    "write_bytes_atomic",
    "write_carmen",
    "write_poses",
    "write_text_atomic",
]

if TYPE_CHECKING:
    from navlab.io.carmen import CarmenLog, LaserScan2D, OdomRecord, read_carmen, skipped_summary, write_carmen
    from navlab.io.datasets import data_file
    from navlab.io.files import (
        MAX_TEXT_BYTES,
        atomic_path,
        check_regular_file,
        machine_memory_bytes,
        read_bytes_checked,
        read_text_checked,
        save_figure_atomic,
        write_bytes_atomic,
        write_text_atomic,
    )
    from navlab.io.pointcloud import FLOAT32, UINT16, cloud_message, move_points, pack_cloud, point_field, read_xyz
    from navlab.io.poses import read_poses, read_table, write_poses
    from navlab.io.rosbag import GRAPH_KEY, BagWriter, bag_graph, bag_topics, read_bag, reindex_bag

_EXPORTS = {
    "BagWriter": "navlab.io.rosbag",
    "CarmenLog": "navlab.io.carmen",
    "FLOAT32": "navlab.io.pointcloud",
    "GRAPH_KEY": "navlab.io.rosbag",
    "LaserScan2D": "navlab.io.carmen",
    "MAX_TEXT_BYTES": "navlab.io.files",
    "OdomRecord": "navlab.io.carmen",
    "UINT16": "navlab.io.pointcloud",
    "atomic_path": "navlab.io.files",
    "bag_graph": "navlab.io.rosbag",
    "bag_topics": "navlab.io.rosbag",
    "check_regular_file": "navlab.io.files",
    "cloud_message": "navlab.io.pointcloud",
    "data_file": "navlab.io.datasets",
    "machine_memory_bytes": "navlab.io.files",
    "move_points": "navlab.io.pointcloud",
    "pack_cloud": "navlab.io.pointcloud",
    "point_field": "navlab.io.pointcloud",
    "read_bag": "navlab.io.rosbag",
    "read_bytes_checked": "navlab.io.files",
    "read_carmen": "navlab.io.carmen",
    "read_poses": "navlab.io.poses",
    "read_table": "navlab.io.poses",
    "read_text_checked": "navlab.io.files",
    "read_xyz": "navlab.io.pointcloud",
    "reindex_bag": "navlab.io.rosbag",
    "save_figure_atomic": "navlab.io.files",
    "skipped_summary": "navlab.io.carmen",
    "write_bytes_atomic": "navlab.io.files",
    "write_carmen": "navlab.io.carmen",
    "write_poses": "navlab.io.poses",
    "write_text_atomic": "navlab.io.files",
}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
