"""``sensor_msgs/PointCloud2``: packing points into its byte layout and reading fields back (little-endian).

The layouts are the ones the gazebo_ros plugins publish: the depth camera's organised ``x y z rgb`` cloud
(``PointCloud2Modifier::setPointCloud2FieldsByString(2, "xyz", "rgb")``: 32-byte points, rgb at offset 16) and
the Velodyne plugin's ``x y z intensity ring`` (32-byte points, intensity at 16, ring uint16 at 20).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from navlab import msgs
from navlab.io.errors import IoError

INT8, UINT8, INT16, UINT16, INT32, UINT32, FLOAT32, FLOAT64 = range(1, 9)  # sensor_msgs/PointField datatypes
_DTYPES = {
    INT8: "i1",
    UINT8: "u1",
    INT16: "<i2",
    UINT16: "<u2",
    INT32: "<i4",
    UINT32: "<u4",
    FLOAT32: "<f4",
    FLOAT64: "<f8",
}
POINT_STEP = 32


def point_field(name: str, offset: int, datatype: int) -> Any:
    """A ``sensor_msgs/PointField`` of one value."""
    return msgs.PointField(name=name, offset=offset, datatype=datatype, count=1)


def pack_cloud(
    stamp_ns: int,
    frame_id: str,
    columns: dict[str, tuple[int, int, np.ndarray]],
    *,
    height: int = 1,
    width: int | None = None,
) -> Any:
    """A PointCloud2 of 32-byte points from ``columns``: name -> (offset, datatype, values (N,)); ``height`` x
    ``width`` organised (default one row). ``is_dense`` is false when any x is NaN."""
    n = len(next(iter(columns.values()))[2])
    buf = np.zeros((n, POINT_STEP), dtype=np.uint8)
    words = buf.view("<f4")  # (n, 8): 4-byte fields at offsets that are multiples of 4 are written as words
    fields = []
    for name, (offset, datatype, values) in columns.items():
        dt = np.dtype(_DTYPES[datatype])
        if datatype == FLOAT32 and offset % 4 == 0:
            words[:, offset // 4] = values
        else:
            buf[:, offset : offset + dt.itemsize] = np.ascontiguousarray(values, dtype=dt).view(np.uint8).reshape(n, -1)
        fields.append(point_field(name, offset, datatype))
    xs = columns.get("x")
    dense = xs is None or not np.isnan(np.asarray(xs[2], dtype=np.float32)).any()
    return cloud_message(stamp_ns, frame_id, buf, fields, height=height, width=width, dense=dense)


def cloud_message(
    stamp_ns: int, frame_id: str, buf: np.ndarray, fields: list[Any], *, height: int, width: int | None, dense: bool
) -> Any:
    """A PointCloud2 over ``buf`` (n x 32 bytes, any dtype: its bytes are the points) with ``fields``
    (``PointField`` messages), ``height`` x ``width`` organised (``width`` None: n // height)."""
    data = buf.reshape(-1).view(np.uint8)
    n = len(data) // POINT_STEP
    w = n // height if width is None else width
    return msgs.PointCloud2(
        header=msgs.header(stamp_ns, frame_id),
        height=height,
        width=w,
        fields=fields,
        is_bigendian=False,
        point_step=POINT_STEP,
        row_step=POINT_STEP * w,
        data=data,
        is_dense=bool(dense),
    )


def read_field(msg: Any, name: str) -> np.ndarray:
    """The values (N,) of field ``name`` of a PointCloud2 (N = height x width)."""
    for f in msg.fields:
        if f.name == name:
            if msg.is_bigendian:
                raise IoError(f"PointCloud2 field {name!r}: big-endian clouds are not supported")
            dt = np.dtype(_DTYPES.get(int(f.datatype), "u1"))
            n = int(msg.height) * int(msg.width)
            raw = np.asarray(msg.data, dtype=np.uint8)[: n * int(msg.point_step)].reshape(n, int(msg.point_step))
            return raw[:, int(f.offset) : int(f.offset) + dt.itemsize].copy().view(dt).reshape(n)
    names = ", ".join(f.name for f in msg.fields) or "none"
    raise IoError(f"PointCloud2 has no field {name!r} (fields: {names})")


def read_xyz(msg: Any, *, copy: bool = True) -> np.ndarray:
    """Points (N, 3) float32 of a PointCloud2's x, y, z fields (NaNs kept). With ``copy=False`` the usual layout
    (float32 x y z at offsets 0 4 8, little-endian) comes back as a read-only strided view of the message's data."""
    offsets = {f.name: (int(f.offset), int(f.datatype)) for f in msg.fields}
    step = int(msg.point_step)
    if (
        (offsets.get("x"), offsets.get("y"), offsets.get("z")) == ((0, FLOAT32), (4, FLOAT32), (8, FLOAT32))
        and step % 4 == 0
        and not msg.is_bigendian
    ):  # the usual layout: one strided view, no per-field copies
        n = int(msg.height) * int(msg.width)
        flat = np.asarray(msg.data, dtype=np.uint8)[: n * step].view("<f4").reshape(n, step // 4)
        if not copy:
            view = flat[:, :3]
            view.flags.writeable = False
            return view
        return flat[:, :3].astype(np.float32)
    return np.stack([read_field(msg, k).astype(np.float32) for k in ("x", "y", "z")], axis=1)


@numba.njit(cache=True)
def _move(points: np.ndarray, rot: np.ndarray, t: np.ndarray, out: np.ndarray) -> None:
    for i in range(points.shape[0]):
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        for k in range(3):
            out[i, k] = x * rot[k, 0] + y * rot[k, 1] + z * rot[k, 2] + t[k]


def move_points(points: np.ndarray, rot: np.ndarray, t: np.ndarray | tuple[float, ...]) -> np.ndarray:
    """``rot @ p + t`` for every point (N, 3; any strides), float32, in one compiled pass (numpy's matmul hands an
    (N, 3) x (3, 3) product to a threaded BLAS, 20x slower on a busy machine)."""
    p = np.asarray(points, dtype=np.float32)  # (a float32 view stays a view)
    out = np.empty((p.shape[0], 3), dtype=np.float32)
    _move(p, np.asarray(rot, dtype=np.float32), np.asarray(t, dtype=np.float32), out)
    return out
