"""The viewer's frames for camera images and point clouds (pure functions over messages and arrays).

``image``: an ``RGBA`` ``uint8`` payload of a ``sensor_msgs/Image`` shrunk to at most ``IMAGE_MAX_W`` pixels wide
(rgb8, bgr8, mono8; a 32FC1 depth image as grey, near white to far black over ``DEPTH_RANGE_M``, NaN black).
``cloud``: ``float32`` x, y, z triples of at most ``CLOUD_MAX`` points of a ``PointCloud2``, already moved into the
fixed frame by the producer (the page draws them seen from above, coloured by height).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from navlab.io import move_points, read_xyz
from navlab.viz.frames import pack

IMAGE_MAX_W = 160
CLOUD_MAX = 4000
DEPTH_RANGE_M = 5.0


def image_rgba(msg: Any) -> np.ndarray:
    """A ``sensor_msgs/Image`` as an RGBA ``uint8`` array (h, w, 4), shrunk to at most ``IMAGE_MAX_W`` wide."""
    h, w, enc = int(msg.height), int(msg.width), str(msg.encoding)
    raw = np.asarray(msg.data, dtype=np.uint8)
    step = max(1, -(-w // IMAGE_MAX_W))
    if enc == "32FC1":
        depth = raw[: h * w * 4].view("<f4").reshape(h, w)[::step, ::step]
        grey = np.where(np.isfinite(depth), 255 * (1 - np.clip(depth / DEPTH_RANGE_M, 0, 1)), 0).astype(np.uint8)
        rgb = np.repeat(grey[..., None], 3, axis=2)
    elif enc in ("rgb8", "bgr8"):
        rgb = raw[: h * w * 3].reshape(h, w, 3)[::step, ::step]
        rgb = rgb[..., ::-1] if enc == "bgr8" else rgb
    elif enc == "mono8":
        rgb = np.repeat(raw[: h * w].reshape(h, w)[::step, ::step, None], 3, axis=2)
    else:
        raise ValueError(f"image encoding {enc!r} is not drawn (rgb8, bgr8, mono8, 32FC1)")
    out = np.full((*rgb.shape[:2], 4), 255, dtype=np.uint8)
    out[..., :3] = rgb
    return out


def image_frame(topic: str, msg: Any) -> bytes | None:
    """The ``image`` frame of a camera image (None for an encoding the viewer does not draw)."""
    try:
        rgba = image_rgba(msg)
    except ValueError:
        return None
    h, w = rgba.shape[:2]
    return pack({"k": "image", "topic": topic, "w": w, "h": h}, np.ascontiguousarray(rgba).tobytes())


def cloud_in_fixed(msg: Any, fixed_T_frame: tuple[float, ...] | None, rng: np.random.Generator) -> np.ndarray | None:
    """At most ``CLOUD_MAX`` finite points (N, 3) of a cloud moved by ``fixed_T_frame`` (x, y, z, qx, qy, qz, qw)."""
    if fixed_T_frame is None:
        return None
    from navlab.geometry import matrix_from_quat

    pts = read_xyz(msg)
    pts = pts[np.isfinite(pts.sum(axis=1))]
    if len(pts) > CLOUD_MAX:
        pts = pts[rng.choice(len(pts), CLOUD_MAX, replace=False)]
    return move_points(pts, matrix_from_quat(fixed_T_frame[3:]), fixed_T_frame[:3])


def cloud_frame(topic: str, frame: str, xyz: np.ndarray) -> bytes:
    """The ``cloud`` frame: points (N, 3) in ``frame`` as ``float32`` triples."""
    p = np.ascontiguousarray(np.asarray(xyz, dtype=np.float32).reshape(-1, 3))
    return pack({"k": "cloud", "topic": topic, "frame": frame, "n": len(p)}, p.tobytes())
