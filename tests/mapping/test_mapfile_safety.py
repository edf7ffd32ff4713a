"""Map files (issue 14): a save is all-or-nothing, a mismatched pair and hostile images are refused."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from navlab.grid import GridMap
from navlab.mapping import MappingError, load_map, mapfile, save_map


def _grid(width: int, height: int, wall: int) -> GridMap:
    data = np.zeros((height, width), dtype=np.int8)
    data[:, wall] = 100
    return GridMap(data, 0.05, (-1.0, -2.0, 0.0), "map")


def test_a_save_killed_before_the_yaml_is_replaced_leaves_the_old_pair(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    old, new = _grid(30, 20, 3), _grid(30, 20, 17)  # same size: only the pixels tell them apart
    yaml_path = tmp_path / "map.yaml"
    save_map(old, yaml_path, crop_margin_cells=None)

    def killed(*_args: object, **_kwargs: object) -> None:
        raise KeyboardInterrupt  # the process dies after the image was written, before the YAML

    monkeypatch.setattr(mapfile, "write_text_atomic", killed)
    with pytest.raises(KeyboardInterrupt):
        save_map(new, yaml_path, crop_margin_cells=None)
    monkeypatch.undo()
    np.testing.assert_array_equal(load_map(yaml_path).data, old.data)  # wholly old, not old YAML + new image

    image = save_map(new, yaml_path, crop_margin_cells=None)  # a complete save: wholly new, old image gone
    np.testing.assert_array_equal(load_map(yaml_path).data, new.data)
    leftovers = sorted(p.name for p in tmp_path.iterdir() if p.suffix == ".pgm")
    assert image.name in leftovers and len(leftovers) <= 2  # the new image and at most the orphan of the kill


def test_an_image_that_does_not_match_the_recorded_size_is_refused(tmp_path: Path) -> None:
    save_map(_grid(30, 20, 3), tmp_path / "a.yaml", crop_margin_cells=None)
    save_map(_grid(40, 20, 3), tmp_path / "b.yaml", crop_margin_cells=None)
    (tmp_path / "b.pgm").replace(tmp_path / "a.pgm")  # a copied image from another map
    with pytest.raises(
        MappingError,
        match=r"a\.yaml: image a\.pgm is 40 x 20 pixels but the YAML records "
        r"image_size \[30, 20\]",
    ):
        load_map(tmp_path / "a.yaml")
    # a ROS map_saver YAML has no image_size: loaded as ROS loads it
    text = (tmp_path / "a.yaml").read_text().replace("image_size: [30, 20]\n", "")
    (tmp_path / "a.yaml").write_text(text)
    assert load_map(tmp_path / "a.yaml").data.shape == (20, 40)


@pytest.mark.parametrize(
    ("kind", "message"),
    [
        ("p4", r"a PBM bitmap \(P4\)"),
        ("bomb", r"60000 x 60000 pixels; a map image may have at most"),
        ("fifo", r"is a named pipe"),
        ("device", r"is a device"),
        ("directory", r"is a directory"),
    ],
)
def test_hostile_images_are_refused_quickly(tmp_path: Path, kind: str, message: str) -> None:
    save_map(_grid(30, 20, 3), tmp_path / "m.yaml", crop_margin_cells=None)
    pgm = tmp_path / "m.pgm"
    body = pgm.read_bytes()
    text = (tmp_path / "m.yaml").read_text().replace("image_size: [30, 20]\n", "")
    (tmp_path / "m.yaml").write_text(text)
    pgm.unlink()
    if kind == "p4":
        pgm.write_bytes(b"P4" + body[2:])
    elif kind == "bomb":
        pgm.write_bytes(b"P5\n60000 60000\n255\n" + body[-600:])
    elif kind == "fifo":
        os.mkfifo(pgm)
    elif kind == "device":
        pgm.symlink_to("/dev/zero")
    else:
        pgm.mkdir()
    with pytest.raises(MappingError, match=r"m\.pgm.*" + message):
        load_map(tmp_path / "m.yaml")


def test_map_yaml_origin_must_be_finite_and_binary_yaml_names_its_line(tmp_path: Path) -> None:
    save_map(_grid(30, 20, 3), tmp_path / "m.yaml", crop_margin_cells=None)
    text = (tmp_path / "m.yaml").read_text()
    (tmp_path / "m.yaml").write_text(text.replace("origin: [-1.000000", "origin: [.nan"))
    with pytest.raises(MappingError, match=r"m\.yaml: key 'origin': expected \[x, y, yaw\] \(three finite"):
        load_map(tmp_path / "m.yaml")
    (tmp_path / "m.yaml").write_bytes(text.encode().replace(b"negate", b"\xffnegate"))
    with pytest.raises(MappingError, match=r"m\.yaml:4: byte 0xff is not UTF-8"):
        load_map(tmp_path / "m.yaml")
