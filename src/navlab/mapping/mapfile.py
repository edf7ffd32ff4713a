"""map_server's map files: a YAML description plus an image (PGM written; PGM/PPM/PNG read).

Loading follows ROS 1 ``map_server`` (image_loader) exactly: the image path is relative to the YAML,
the image's first row is the map's top row (rows flipped vs. grid rows), ``negate`` inverts grey
levels, ``occ = (255 - grey) / 255``; trinary: occ > occupied_thresh -> 100, occ < free_thresh -> 0,
else -1; scale: in-between values map to ``1 + 98 * ratio`` (unknown where alpha is 0); raw: the
grey level is the cell value. Saving writes what ``map_saver`` writes: 254 free, 0 occupied,
205 unknown (trinary), and the inverse of the loader for scale/raw, so a save/load round trip is
exact wherever the image format can represent the value. Files are written atomically.
"""

from __future__ import annotations

import difflib
import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from navlab.grid import GridMap
from navlab.io.files import write_bytes_atomic, write_text_atomic
from navlab.mapping.errors import MappingError

MODES = ("trinary", "scale", "raw")
_KNOWN_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh", "mode")
_OPTIONAL_KEYS = ("load_time", "frame_id")


# --- image reading --------------------------------------------------------------------------------


def _pnm_tokens(buf: bytes, count: int, path: Path) -> tuple[list[int], int]:
    """Read ``count`` whitespace-separated integer header tokens (skipping # comments); return them and the offset."""
    tokens: list[int] = []
    pos = 2
    n = len(buf)
    while len(tokens) < count:
        while pos < n and buf[pos : pos + 1].isspace():
            pos += 1
        if pos < n and buf[pos : pos + 1] == b"#":
            while pos < n and buf[pos : pos + 1] not in (b"\n", b"\r"):
                pos += 1
            continue
        start = pos
        while pos < n and not buf[pos : pos + 1].isspace() and buf[pos : pos + 1] != b"#":
            pos += 1
        if start == pos:
            raise MappingError(f"{path}: truncated PNM header (expected width, height and maxval)")
        try:
            tokens.append(int(buf[start:pos]))
        except ValueError:
            raise MappingError(f"{path}: bad PNM header token {buf[start:pos]!r}, expected an integer") from None
    return tokens, pos


def _read_pnm(path: Path, buf: bytes) -> np.ndarray:
    """Pixels (height, width, channels) uint8 of a P2/P3/P5/P6 file."""
    magic = buf[:2]
    channels = 3 if magic in (b"P3", b"P6") else 1
    (width, height, maxval), pos = _pnm_tokens(buf, 3, path)
    if width <= 0 or height <= 0:
        raise MappingError(f"{path}: image size {width}x{height}, expected positive width and height")
    if not 0 < maxval < 65536:
        raise MappingError(f"{path}: PNM maxval {maxval}, expected 1..65535")
    count = width * height * channels
    if magic in (b"P5", b"P6"):
        pos += 1  # exactly one whitespace byte after maxval
        dtype = np.dtype(">u2") if maxval > 255 else np.dtype(np.uint8)
        raw = buf[pos : pos + count * dtype.itemsize]
        if len(raw) < count * dtype.itemsize:
            raise MappingError(
                f"{path}: truncated image data: {len(raw)} bytes for {width}x{height}, "
                f"expected {count * dtype.itemsize}"
            )
        values = np.frombuffer(raw, dtype=dtype).astype(np.int64)
    else:
        try:
            values = np.array(buf[pos:].split()[:count], dtype=np.int64)
        except ValueError:
            raise MappingError(f"{path}: non-integer pixel in ASCII PNM data") from None
        if values.size < count:
            raise MappingError(f"{path}: truncated image data: {values.size} of {count} pixel values")
    if maxval != 255:
        values = values * 255 // maxval
    return values.astype(np.uint8).reshape(height, width, channels)


def read_image(path: str | os.PathLike[str]) -> tuple[np.ndarray, bool]:
    """Pixels (height, width, channels) uint8 of a map image and whether its last channel is alpha.

    PGM/PPM (P2, P3, P5, P6) are read natively; other formats (PNG, BMP, ...) through Pillow.
    """
    p = Path(path)
    try:
        buf = p.read_bytes()
    except OSError as exc:
        raise MappingError(f"cannot read map image {p}: {exc.strerror or exc}") from None
    if buf[:2] in (b"P2", b"P3", b"P5", b"P6"):
        return _read_pnm(p, buf), False
    try:
        from PIL import Image, UnidentifiedImageError

        with Image.open(p) as img:
            has_alpha = img.mode in ("LA", "RGBA", "PA") or "transparency" in img.info
            grey_modes = ("L", "1", "I", "I;16", "F")
            if has_alpha:
                target = "LA" if img.mode in ("L", "LA") else "RGBA"
            else:
                target = "L" if img.mode in grey_modes else "RGB"
            img = img.convert(target)
            arr = np.asarray(img, dtype=np.uint8)
    except (UnidentifiedImageError, OSError) as exc:
        raise MappingError(f"{p}: not a readable image (PGM, PPM or PNG expected): {exc}") from None
    if arr.ndim == 2:
        arr = arr[:, :, None]
    return arr, has_alpha


# --- pixel <-> cell value ---------------------------------------------------------------------------


def _pixels_to_values(
    pixels: np.ndarray, has_alpha: bool, *, mode: str, negate: bool, occupied_thresh: float, free_thresh: float
) -> np.ndarray:
    """map_server's conversion of image pixels (h, w, c) to cell values (h, w) int8, in image row order."""
    n = pixels.shape[2]
    px = pixels.astype(np.float64)
    # ROS 1: trinary averages alpha in with colour; other modes drop the alpha channel from the mean.
    avg_channels = n if (mode == "trinary" or not has_alpha) else n - 1
    color_avg = px[:, :, :avg_channels].sum(axis=2) / avg_channels
    alpha = np.ones(color_avg.shape) if n == 1 else px[:, :, n - 1]
    if negate:
        color_avg = 255.0 - color_avg
    if mode == "raw":
        return np.floor(color_avg).astype(np.uint8).view(np.int8)
    occ = (255.0 - color_avg) / 255.0
    value = np.full(occ.shape, -1, dtype=np.int16)
    mid = ~((occ > occupied_thresh) | (occ < free_thresh))
    if mode == "scale":
        ratio = (occ - free_thresh) / (occupied_thresh - free_thresh)
        scaled = np.floor(1.0 + 98.0 * ratio).astype(np.int16)
        sel = mid & (alpha >= 1.0)
        value[sel] = scaled[sel]
    value[occ > occupied_thresh] = 100
    value[occ < free_thresh] = 0
    return value.astype(np.int8)


def _value_to_grey_lut(*, mode: str, occupied_thresh: float, free_thresh: float) -> np.ndarray:
    """For cell values -1..100 (index value+1), the grey level the loader turns back into that value.

    Where no grey level maps back exactly, the nearest one is used. map_saver's levels are kept:
    254 free, 0 occupied, 205 unknown.
    """
    greys = np.arange(256, dtype=np.uint8).reshape(1, 256, 1)
    back = (
        _pixels_to_values(
            greys, False, mode=mode, negate=False, occupied_thresh=occupied_thresh, free_thresh=free_thresh
        )
        .reshape(256)
        .astype(np.int64)
    )
    lut = np.zeros(102, dtype=np.uint8)
    for v in range(-1, 101):
        if mode == "raw":
            lut[v + 1] = v & 0xFF
            continue
        exact = np.flatnonzero(back == v)
        if v == 0 and 254 in exact:
            lut[v + 1] = 254
        elif v == 100 and 0 in exact:
            lut[v + 1] = 0
        elif v == -1:
            lut[v + 1] = 205
        elif exact.size:
            lut[v + 1] = exact[len(exact) // 2]
        else:
            known = back >= 0
            lut[v + 1] = np.flatnonzero(known)[np.argmin(np.abs(back[known] - v))]
    return lut


# --- YAML ---------------------------------------------------------------------------------------------


def _key_error(path: Path, key: str, expected: str, got: Any = None) -> MappingError:
    tail = "" if got is None else f", got {got!r}"
    return MappingError(f"{path}: key '{key}': expected {expected}{tail}")


def _number(path: Path, doc: dict[str, Any], key: str, default: float | None = None) -> float:
    if key not in doc:
        if default is None:
            raise MappingError(f"{path}: missing key '{key}'")
        return default
    val = doc[key]
    if isinstance(val, bool) or not isinstance(val, int | float) or not math.isfinite(val):
        raise _key_error(path, key, "a number", val)
    return float(val)


def read_map_yaml(yaml_path: str | os.PathLike[str]) -> dict[str, Any]:
    """The validated contents of a map YAML: image (absolute Path), resolution, origin, negate, thresholds, mode."""
    path = Path(yaml_path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise MappingError(f"cannot read map file {path}: {exc.strerror or exc}") from None
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise MappingError(f"{path}: not valid YAML: {str(exc).splitlines()[0]}") from None
    if not isinstance(doc, dict):
        raise MappingError(f"{path}: expected a mapping with keys image, resolution, origin, ...")
    for key in doc:
        if key not in _KNOWN_KEYS and key not in _OPTIONAL_KEYS:
            close = difflib.get_close_matches(str(key), _KNOWN_KEYS, n=1)
            if close and close[0] not in doc:
                raise MappingError(f"{path}: unknown key '{key}'; did you mean '{close[0]}'?")
    if "image" not in doc:
        raise MappingError(f"{path}: missing key 'image' (the map image, relative to the YAML)")
    if not isinstance(doc["image"], str) or not doc["image"]:
        raise _key_error(path, "image", "a file name", doc["image"])
    image = Path(doc["image"])
    if not image.is_absolute():
        image = path.parent / image
    resolution = _number(path, doc, "resolution")
    if resolution <= 0:
        raise _key_error(path, "resolution", "a positive number of m/pixel", doc["resolution"])
    if "origin" not in doc:
        raise MappingError(f"{path}: missing key 'origin' ([x, y, yaw] of the lower-left pixel)")
    origin = doc["origin"]
    if (
        not isinstance(origin, list)
        or len(origin) != 3
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in origin)
    ):
        raise _key_error(path, "origin", "[x, y, yaw] (three numbers)", origin)
    negate = doc.get("negate", 0)
    if isinstance(negate, bool):
        negate = int(negate)
    if negate not in (0, 1):
        raise _key_error(path, "negate", "0 or 1", negate)
    occ = _number(path, doc, "occupied_thresh", 0.65)
    free = _number(path, doc, "free_thresh", 0.196)
    if not 0.0 <= free < occ <= 1.0:
        raise MappingError(
            f"{path}: thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1, got "
            f"free_thresh {free}, occupied_thresh {occ}"
        )
    mode = doc.get("mode", "trinary")
    if not isinstance(mode, str) or mode.lower() not in MODES:
        raise _key_error(path, "mode", "one of trinary, scale, raw", mode)
    return {
        "image": image,
        "resolution": resolution,
        "origin": (float(origin[0]), float(origin[1]), float(origin[2])),
        "negate": bool(negate),
        "occupied_thresh": occ,
        "free_thresh": free,
        "mode": mode.lower(),
    }


def load_map(yaml_path: str | os.PathLike[str], *, frame_id: str = "map") -> GridMap:
    """Load a map_server map (YAML + image) as a ``GridMap`` (grid row 0 = the image's bottom row)."""
    meta = read_map_yaml(yaml_path)
    pixels, has_alpha = read_image(meta["image"])
    values = _pixels_to_values(
        pixels,
        has_alpha,
        mode=meta["mode"],
        negate=meta["negate"],
        occupied_thresh=meta["occupied_thresh"],
        free_thresh=meta["free_thresh"],
    )
    return GridMap(np.ascontiguousarray(values[::-1]), meta["resolution"], meta["origin"], frame_id)


# --- writing --------------------------------------------------------------------------------------------


def _png_bytes(grey: np.ndarray, alpha: np.ndarray | None) -> bytes:
    import io

    from PIL import Image

    img = Image.fromarray(grey, "L") if alpha is None else Image.fromarray(np.dstack([grey, alpha]), "LA")
    out = io.BytesIO()
    img.save(out, format="PNG")
    return out.getvalue()


def save_map(
    grid: GridMap,
    yaml_path: str | os.PathLike[str],
    *,
    image_name: str | None = None,
    occupied_thresh: float = 0.65,
    free_thresh: float = 0.196,
    mode: str = "trinary",
    negate: bool = False,
) -> Path:
    """Write ``grid`` as map_saver does: ``yaml_path`` plus an image beside it; returns the image path.

    ``image_name`` defaults to the YAML's stem + ``.pgm`` (``.png`` in scale mode, whose alpha channel
    keeps unknown cells unknown; a PGM in scale mode stores unknown as grey 205).
    """
    if mode not in MODES:
        raise MappingError(f"save_map: mode {mode!r}, expected one of {', '.join(MODES)}")
    if not 0.0 <= free_thresh < occupied_thresh <= 1.0:
        raise MappingError("save_map: thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1")
    ypath = Path(yaml_path)
    try:
        ypath.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MappingError(f"save_map: cannot create directory {ypath.parent}: {exc.strerror or exc}") from None
    if image_name is None:
        image_name = ypath.stem + (".png" if mode == "scale" else ".pgm")
    ipath = Path(image_name) if Path(image_name).is_absolute() else ypath.parent / image_name
    data = grid.data.astype(np.int64)
    lut = _value_to_grey_lut(mode=mode, occupied_thresh=occupied_thresh, free_thresh=free_thresh)
    grey = lut[np.clip(data, -1, 100) + 1]
    grey = np.ascontiguousarray(grey[::-1])  # image row 0 is the top of the map
    if negate:
        grey = (255 - grey).astype(np.uint8)
    if ipath.suffix.lower() == ".png":
        alpha = None
        if mode == "scale":
            alpha = np.where(data[::-1] < 0, 0, 255).astype(np.uint8)
        payload = _png_bytes(grey, alpha)
    elif ipath.suffix.lower() == ".pgm":
        head = f"P5\n# CREATOR: navlab map_saver {grid.resolution:.3f} m/pix\n{grid.width} {grid.height}\n255\n"
        payload = head.encode("ascii") + grey.tobytes()
    else:
        raise MappingError(f"save_map: image {ipath.name}: expected a .pgm or .png file name")
    write_bytes_atomic(ipath, payload)
    ox, oy, oyaw = grid.origin
    image_field = image_name if not Path(image_name).is_absolute() else str(ipath)
    text = (
        f"image: {image_field}\n"
        f"resolution: {grid.resolution:.6f}\n"
        f"origin: [{ox:.6f}, {oy:.6f}, {oyaw:.6f}]\n"
        f"negate: {int(negate)}\n"
        f"occupied_thresh: {occupied_thresh:g}\n"
        f"free_thresh: {free_thresh:g}\n"
        f"mode: {mode}\n"
    )
    write_text_atomic(ypath, text)
    return ipath
