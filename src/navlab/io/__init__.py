"""File formats and data: rosbag2 (``rosbag``), CARMEN logs (``carmen``), pose files (``poses``), atomic
writes (``files``) and where datasets live (``datasets``, the ``NAVLAB_DATA`` setting).

A leaf package: it imports nothing of navlab above errors, msgs and geometry.
"""

from navlab.io.datasets import data_dir, dataset
from navlab.io.errors import BagError, DatasetNotFoundError, IoError

__all__ = ["BagError", "DatasetNotFoundError", "IoError", "data_dir", "dataset"]
