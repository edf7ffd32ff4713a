"""VoxelLayer.add_sensor_cloud: a cloud read in the sensor's frame, as the costmap feeds hand it over, marks and
clears exactly what the same points moved into the costmap frame do."""

from __future__ import annotations

import numpy as np

from navlab.geometry import matrix_from_quat, quat_from_rpy
from navlab.grid import COST_LETHAL, Grid
from navlab.io.pointcloud import FLOAT32, pack_cloud, read_xyz
from navlab.navigation.costmap.params import ObservationSource
from navlab.navigation.costmap.voxel_layer import VoxelLayer


def _layer() -> VoxelLayer:
    source = ObservationSource(
        data_type="PointCloud2", obstacle_range=2.5, raytrace_range=3.0, min_obstacle_height=0.05
    )
    layer = VoxelLayer({"z_resolution": 0.05, "z_voxels": 8, "origin_z": -0.1}, name="voxel", sources={"cam": source})
    layer.match_size(Grid(np.zeros((80, 80), np.uint8), 0.05, (-2.0, -2.0, 0.0), "odom"))
    return layer


def test_a_cloud_in_the_sensor_frame_marks_and_clears_as_the_moved_cloud_does() -> None:
    rng = np.random.default_rng(4)
    # a camera's view: floor points (some below the columns' base, by noise), a box face, far points, NaNs
    n = 6000
    pts = np.column_stack([rng.uniform(0.3, 5.0, n), rng.uniform(-2.0, 2.0, n), rng.normal(-0.25, 0.01, n)])
    pts[:1500, 0], pts[:1500, 2] = 1.2, rng.uniform(-0.25, 0.1, 1500)  # a box's face 1.2 m ahead
    pts[::97] = np.nan
    cloud = pack_cloud(0, "cam", {a: (4 * k, FLOAT32, pts[:, k]) for k, a in enumerate("xyz")})
    rot, origin = matrix_from_quat(quat_from_rpy(0.01, 0.05, 0.7)), np.array([0.3, -0.2, 0.15])
    sensor_frame, costmap_frame = _layer(), _layer()
    view = read_xyz(cloud, copy=False)  # strided: the message's own bytes
    sensor_frame.add_sensor_cloud(origin, rot, view, source="cam")
    moved = read_xyz(cloud).astype(np.float64) @ rot.T + origin
    costmap_frame.add_cloud(origin, moved, source="cam")
    assert (sensor_frame.grid.data == COST_LETHAL).sum() > 20  # the box face is marked
    np.testing.assert_array_equal(sensor_frame.columns, costmap_frame.columns)
    np.testing.assert_array_equal(sensor_frame.grid.data, costmap_frame.grid.data)
