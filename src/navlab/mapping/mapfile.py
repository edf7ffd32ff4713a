"""map_server's map files: a YAML description plus an image (PGM written; PGM/PPM/PNG read).

Loading follows ROS 1 ``map_server`` (noetic image_loader) exactly: the image path is relative to the
YAML, the image's first row is the map's top row (rows flipped vs. grid rows), ``negate`` inverts grey
levels, ``p = (255 - grey) / 255``; trinary: p > occupied_thresh -> 100, p < free_thresh -> 0, else -1;
scale: the same, except that in-between values become ``1 + 98 * ratio`` (truncated; unknown where
alpha is 0), ratio = (p - free_thresh) / (occupied_thresh - free_thresh); raw: the grey level is the
cell value.

Saving writes what ``map_saver`` writes. Trinary: occupancy <= ``threshold_free`` % (default 25) ->
254, >= ``threshold_occupied`` % (default 65) -> 0, everything else (unknown, in-between) -> 205, with
``occupied_thresh: 0.65`` and ``free_thresh: 0.196`` in the YAML, so -1/0/100 reload exactly. Scale and
raw: the inverse of the loader, exact wherever the image format can hold the value. The map is cropped to
its known cells plus a margin by default (SLAM grids are larger than what they saw). Files are written
atomically.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import secrets
from pathlib import Path
from typing import Any

import numpy as np

from navlab.core import ParameterError, parse_yaml
from navlab.errors import closest
from navlab.grid import GridMap
from navlab.io import IoError, read_bytes_checked, read_text_checked, write_bytes_atomic, write_text_atomic
from navlab.mapping.errors import MappingError

MODES = ("trinary", "scale", "raw")
_KNOWN_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh", "mode")
_OPTIONAL_KEYS = ("load_time", "frame_id", "image_size")
MAX_IMAGE_BYTES = 1 << 30  # a map image file (bytes)
MAX_IMAGE_PIXELS = 400_000_000  # 20 km x 20 km at 1 mm... a map of more cells than this is refused
MAX_YAML_BYTES = 1 << 20


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
    if width * height > MAX_IMAGE_PIXELS:
        raise MappingError(
            f"{path}: image of {width} x {height} pixels; a map image may have at most {MAX_IMAGE_PIXELS}"
        )
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
        buf = read_bytes_checked(p, what="map image", max_bytes=MAX_IMAGE_BYTES)
    except IoError as exc:
        raise MappingError(str(exc)) from None
    if buf[:2] in (b"P2", b"P3", b"P5", b"P6"):
        return _read_pnm(p, buf), False
    if buf[:2] in (b"P1", b"P4"):
        raise MappingError(
            f"{p}: a PBM bitmap ({buf[:2].decode()}); expected a greyscale PGM (P2/P5), a PPM (P3/P6) or a PNG"
        )
    try:
        import io

        from PIL import Image, UnidentifiedImageError

        with Image.open(io.BytesIO(buf)) as img:
            if img.width * img.height > MAX_IMAGE_PIXELS:
                raise MappingError(
                    f"{p}: image of {img.width} x {img.height} pixels; a map image may have at "
                    f"most {MAX_IMAGE_PIXELS} (a decompression bomb?)"
                )
            has_alpha = img.mode in ("LA", "RGBA", "PA") or "transparency" in img.info
            grey_modes = ("L", "1", "I", "I;16", "F")
            if has_alpha:
                target = "LA" if img.mode in ("L", "LA") else "RGBA"
            else:
                target = "L" if img.mode in grey_modes else "RGB"
            arr = np.asarray(img.convert(target), dtype=np.uint8)
    except (UnidentifiedImageError, OSError, ValueError, Image.DecompressionBombError, SyntaxError) as exc:
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
    """Scale/raw modes: for cell values -1..100 (index value+1), the grey level the loader turns back into
    that value (the nearest one where none does exactly); 254 free, 0 occupied, 205 unknown as map_saver."""
    lut = np.zeros(102, dtype=np.uint8)
    if mode == "raw":
        lut[:] = np.arange(-1, 101) & 0xFF
        return lut
    greys = np.arange(256, dtype=np.uint8).reshape(1, 256, 1)
    back = (
        _pixels_to_values(
            greys, False, mode=mode, negate=False, occupied_thresh=occupied_thresh, free_thresh=free_thresh
        )
        .reshape(256)
        .astype(np.int64)
    )
    known = np.flatnonzero(back >= 0)
    lut[0] = 205
    for v in range(101):
        exact = np.flatnonzero(back == v)
        preferred = {0: 254, 100: 0}.get(v)
        if preferred is not None and preferred in exact:
            lut[v + 1] = preferred
        elif exact.size:
            lut[v + 1] = exact[len(exact) // 2]
        else:
            lut[v + 1] = known[np.argmin(np.abs(back[known] - v))]
    return lut


def trinary_grey(data: np.ndarray, *, threshold_occupied: int = 65, threshold_free: int = 25) -> np.ndarray:
    """map_saver's trinary grey levels (uint8, same shape) of occupancy values ``data`` (-1 or 0..100 %):
    0 <= v <= ``threshold_free`` -> 254 (free), v >= ``threshold_occupied`` -> 0 (occupied), else 205."""
    v = np.asarray(data).astype(np.int16)
    grey = np.full(v.shape, 205, dtype=np.uint8)
    grey[(v >= 0) & (v <= threshold_free)] = 254
    grey[v >= threshold_occupied] = 0
    return grey


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
        doc = parse_yaml(read_text_checked(path, what="map YAML file", max_bytes=MAX_YAML_BYTES), path)
    except IoError as exc:
        raise MappingError(str(exc)) from None
    except ParameterError as exc:
        raise MappingError(str(exc).replace("malformed YAML", "not valid YAML", 1)) from None
    if not isinstance(doc, dict):
        raise MappingError(f"{path}: expected a mapping with keys image, resolution, origin, ...")
    for key in doc:
        if key not in _KNOWN_KEYS and key not in _OPTIONAL_KEYS:
            close = closest(key, _KNOWN_KEYS)
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
        or not all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in origin)
    ):
        raise _key_error(path, "origin", "[x, y, yaw] (three finite numbers)", origin)
    size = doc.get("image_size")
    if size is not None and not (
        isinstance(size, list)
        and len(size) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in size)
    ):
        raise _key_error(path, "image_size", "[width, height] in pixels (written by navlab's map saver)", size)
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
        "image_size": None if size is None else (int(size[0]), int(size[1])),
    }


def load_map(yaml_path: str | os.PathLike[str], *, frame_id: str = "map") -> GridMap:
    """Load a map_server map (YAML + image) as a ``GridMap`` (grid row 0 = the image's bottom row)."""
    meta = read_map_yaml(yaml_path)
    pixels, has_alpha = read_image(meta["image"])
    if meta["image_size"] is not None and meta["image_size"] != (pixels.shape[1], pixels.shape[0]):
        w, h = meta["image_size"]
        raise MappingError(
            f"{yaml_path}: image {meta['image'].name} is {pixels.shape[1]} x {pixels.shape[0]} pixels but the YAML "
            f"records image_size [{w}, {h}]: the pair is not from one save (an interrupted save, or a copied image?)"
        )
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
    threshold_occupied: int = 65,
    threshold_free: int = 25,
    crop_margin_cells: int | None = 10,
) -> Path:
    """Write ``grid`` as map_saver does: ``yaml_path`` plus an image beside it; returns the image path.

    Trinary (default): cells <= ``threshold_free`` % are written free (254), >= ``threshold_occupied`` %
    occupied (0), the rest unknown (205): map_saver's ``--free``/``--occ``. ``occupied_thresh`` and
    ``free_thresh`` are the loader's thresholds written into the YAML (and, in scale mode, used to pick grey
    levels). ``image_name`` defaults to the YAML's stem + ``.pgm`` (``.png`` in scale mode, whose alpha
    channel keeps unknown cells unknown; a PGM in scale mode stores unknown as grey 205).
    ``crop_margin_cells``: save only the known cells plus this many cells around them (the origin moves
    with the crop, cells keep their position in the map frame); ``None`` saves the whole grid.
    """
    if mode not in MODES:
        raise MappingError(f"save_map: mode {mode!r}, expected one of {', '.join(MODES)}")
    if not 0.0 <= free_thresh < occupied_thresh <= 1.0:
        raise MappingError(
            f"save_map: thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1, got "
            f"free_thresh {free_thresh}, occupied_thresh {occupied_thresh}"
        )
    if mode == "trinary":
        if not 0 <= threshold_free < threshold_occupied <= 100:
            raise MappingError(
                f"save_map: threshold_free {threshold_free} and threshold_occupied {threshold_occupied}: "
                "expected percentages with 0 <= threshold_free < threshold_occupied <= 100"
            )
        # the loader must read 254 as free, 205 as unknown and 0 as occupied
        if not (1 / 255 < free_thresh <= 50 / 255 <= occupied_thresh < 1.0):
            raise MappingError(
                f"save_map: free_thresh {free_thresh}, occupied_thresh {occupied_thresh} would not reload the "
                "trinary grey levels 254/205/0 as free/unknown/occupied; expected "
                "0.004 < free_thresh <= 0.196 <= occupied_thresh < 1"
            )
    if crop_margin_cells is not None:
        if crop_margin_cells < 0:
            raise MappingError(f"save_map: crop_margin_cells {crop_margin_cells}, expected >= 0 (or None)")
        grid = grid.crop_to_known(int(crop_margin_cells))
    ypath = Path(yaml_path)
    try:
        ypath.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MappingError(f"save_map: cannot create directory {ypath.parent}: {exc.strerror or exc}") from None
    previous = _referenced_image(ypath)
    if image_name is None:
        image_name = _fresh_image_name(ypath, ".png" if mode == "scale" else ".pgm")
    ipath = Path(image_name) if Path(image_name).is_absolute() else ypath.parent / image_name
    data = grid.data.astype(np.int64)
    if mode == "trinary":
        grey = trinary_grey(data, threshold_occupied=threshold_occupied, threshold_free=threshold_free)
    else:
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
    write_bytes_atomic(ipath, payload)  # a new name (see _fresh_image_name): the old YAML still names the old image
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
        f"image_size: [{grid.width}, {grid.height}]\n"
    )
    write_text_atomic(ypath, text)  # the switch from the old pair to the new one
    if (
        previous is not None
        and previous != ipath.resolve()
        and previous.parent == ypath.parent.resolve()
        and re.fullmatch(rf"{re.escape(ypath.stem)}(\.[0-9a-f]{{8}})?\.(pgm|png)", previous.name)
    ):
        with contextlib.suppress(OSError):
            previous.unlink()  # the old pair's image, no longer named by any YAML this save wrote
    return ipath


def _referenced_image(ypath: Path) -> Path | None:
    """The image an existing map YAML names (resolved), or None (no YAML, or one that cannot be read)."""
    try:
        return Path(read_map_yaml(ypath)["image"]).resolve()
    except (MappingError, OSError):
        return None


def _fresh_image_name(ypath: Path, suffix: str) -> str:
    """``<stem><suffix>`` unless a file of that name exists, else ``<stem>.<8 hex digits><suffix>``.

    Saving over an existing pair writes the new image under a name no YAML uses yet and replaces the
    YAML last, so a save interrupted at any point leaves the old pair or the new one, never a mix.
    """
    plain = f"{ypath.stem}{suffix}"
    if not (ypath.parent / plain).exists():
        return plain
    while True:
        name = f"{ypath.stem}.{secrets.token_hex(4)}{suffix}"
        if not (ypath.parent / name).exists():
            return name


def save_true_map(world: str, start_xy: tuple[float, float], yaml_path: str | os.PathLike[str]) -> Path:
    """Save the true map of ``world`` (a shipped name or a .world file; obstacles 100, free space reachable from
    ``start_xy`` 0, world frame = map frame, 5 cm) as a map_server map at ``yaml_path``; returns the YAML's path."""
    from navlab.world import load_world, true_map

    path = Path(yaml_path)
    save_map(true_map(load_world(world), (float(start_xy[0]), float(start_xy[1]))), path)
    return path
