"""map_server YAML + image files: round trips for every mode and negate, ROS conventions, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from navlab import msgs
from navlab.mapping import GridMap, MappingError, load_map, save_map


def _grid(rng: np.random.Generator, values: np.ndarray, h: int = 7, w: int = 11) -> GridMap:
    data = rng.choice(values, size=(h, w)).astype(np.int8)
    return GridMap(data, 0.05, (-1.25, 2.5, 0.3))


@pytest.mark.parametrize("negate", [False, True])
def test_trinary_round_trip(tmp_path, negate):
    grid = _grid(np.random.default_rng(1), np.array([-1, 0, 100]))
    save_map(grid, tmp_path / "map.yaml", negate=negate)
    back = load_map(tmp_path / "map.yaml")
    np.testing.assert_array_equal(back.data, grid.data)
    assert back.resolution == pytest.approx(0.05)
    assert back.origin == pytest.approx(grid.origin)


@pytest.mark.parametrize("negate", [False, True])
def test_raw_round_trip_every_value(tmp_path, negate):
    values = np.arange(-1, 101)
    grid = GridMap(values.reshape(6, 17).astype(np.int8), 0.1, (0.0, 0.0, 0.0))
    save_map(grid, tmp_path / "raw.yaml", mode="raw", negate=negate)
    back = load_map(tmp_path / "raw.yaml")
    np.testing.assert_array_equal(back.data, grid.data)


@pytest.mark.parametrize("negate", [False, True])
@pytest.mark.parametrize("suffix", [".png", ".pgm"])
def test_scale_round_trip(tmp_path, negate, suffix):
    values = np.arange(-1, 101)
    grid = GridMap(values.reshape(6, 17).astype(np.int8), 0.1, (1.0, 2.0, 0.0))
    save_map(grid, tmp_path / "s.yaml", mode="scale", negate=negate, image_name="s" + suffix)
    back = load_map(tmp_path / "s.yaml").data.astype(int)
    known = grid.data >= 0
    # free/occupied exact; in-between within one percent (8-bit grey cannot hold every percent)
    np.testing.assert_array_equal(back[grid.data == 0], 0)
    np.testing.assert_array_equal(back[grid.data == 100], 100)
    assert np.abs(back[known] - grid.data[known]).max() <= 1
    if suffix == ".png":  # alpha keeps unknown unknown
        np.testing.assert_array_equal(back[~known], -1)


def test_map_saver_grey_levels_and_row_flip(tmp_path):
    data = np.array([[0, 100, -1], [-1, -1, 100]], dtype=np.int8)  # row 0 = bottom
    save_map(GridMap(data, 0.05), tmp_path / "m.yaml")
    raw = (tmp_path / "m.pgm").read_bytes()
    assert raw.startswith(b"P5\n")
    pixels = np.frombuffer(raw[-6:], dtype=np.uint8).reshape(2, 3)
    # image row 0 is the top of the map = grid row 1
    np.testing.assert_array_equal(pixels, [[205, 205, 0], [254, 0, 205]])
    text = (tmp_path / "m.yaml").read_text()
    assert "image: m.pgm" in text and "occupied_thresh: 0.65" in text and "free_thresh: 0.196" in text


def test_load_handwritten_ascii_pgm_with_thresholds(tmp_path):
    # An ASCII PGM with comments, a non-default maxval; image relative to the YAML in a subfolder.
    (tmp_path / "img").mkdir()
    (tmp_path / "img" / "a.pgm").write_text("P2\n# a comment\n3 2\n# another\n15\n15 0 7\n14 1 8\n")
    (tmp_path / "a.yaml").write_text(
        "image: img/a.pgm\nresolution: 0.5\norigin: [1.0, -2.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    grid = load_map(tmp_path / "a.yaml")
    # grey = v*255//15: 255 0 119 / 238 17 136 -> occ 0, 1, .53 / .067, .93, .47
    np.testing.assert_array_equal(grid.data, [[0, 100, -1], [0, 100, -1]])
    assert grid.world_to_cell(np.array([[1.2, -1.2]])).tolist() == [[0, 1]]


def test_negate_inverts_meaning(tmp_path):
    (tmp_path / "n.pgm").write_bytes(b"P5 2 1 255 " + bytes([0, 254]))
    (tmp_path / "n.yaml").write_text("image: n.pgm\nresolution: 1\norigin: [0, 0, 0]\nnegate: 1\n")
    np.testing.assert_array_equal(load_map(tmp_path / "n.yaml").data, [[0, 100]])


def test_grid_cells_and_msg_round_trip():
    grid = GridMap(np.zeros((4, 6), np.int8), 0.5, (1.0, 2.0, np.pi / 2))
    # with yaw 90°, the grid's +x axis points along the map's +y
    assert grid.world_to_cell(np.array([[0.9, 2.6]])).tolist() == [[1, 0]]
    centre = grid.cell_to_world(np.array([[1, 0]]))
    np.testing.assert_allclose(centre, [[0.75, 2.75]])
    back = GridMap.from_msg(grid.to_msg(5_000_000_000))
    np.testing.assert_array_equal(back.data, grid.data)
    assert back.origin == pytest.approx(grid.origin)
    msg = grid.to_msg(7)
    assert msgs.type_name(msg) == "nav_msgs/msg/OccupancyGrid" and msg.info.width == 6 and msg.info.height == 4


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("image: m.pgm\nresolution: 0.05\n", "origin"),
        ("image: m.pgm\nresolution: -1\norigin: [0, 0, 0]\n", "resolution"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0]\n", "origin"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 2\n", "negate"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nmode: fancy\n", "mode"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\noccupied_tresh: 0.6\n", "did you mean"),
        ("image: m.pgm\nresolution: [0.05\n", "not valid YAML"),
        ("resolution: 0.05\norigin: [0, 0, 0]\n", "image"),
        ("image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n", "missing.pgm"),
    ],
)
def test_malformed_yaml_names_file_and_key(tmp_path, text, needle):
    (tmp_path / "m.pgm").write_bytes(b"P5\n1 1\n255\n\x00")
    (tmp_path / "bad.yaml").write_text(text)
    with pytest.raises(MappingError) as err:
        load_map(tmp_path / "bad.yaml")
    assert needle in str(err.value) and ("bad.yaml" in str(err.value) or "missing.pgm" in str(err.value))


@pytest.mark.parametrize(
    ("payload", "needle"),
    [
        (b"P5\n4 4\n255\n\x00\x00", "truncated image data"),
        (b"P5\n4 x\n255\n", "bad PNM header"),
        (b"GIF89a-not-really", "not a readable image"),
    ],
)
def test_malformed_pgm(tmp_path, payload, needle):
    (tmp_path / "m.pgm").write_bytes(payload)
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(MappingError, match=needle) as err:
        load_map(tmp_path / "m.yaml")
    assert "m.pgm" in str(err.value)


def test_atomic_write_leaves_no_temp_files(tmp_path):
    save_map(GridMap(np.zeros((3, 3), np.int8), 0.1), tmp_path / "x.yaml")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.pgm", "x.yaml"]


def test_save_creates_missing_directories(tmp_path):
    grid = GridMap(np.zeros((2, 2), np.int8), 0.1)
    save_map(grid, tmp_path / "a" / "b" / "m.yaml")
    np.testing.assert_array_equal(load_map(tmp_path / "a" / "b" / "m.yaml").data, grid.data)


def _pgm_pixels(path) -> np.ndarray:
    """Pixels of a P5 file written by save_map (header: magic, comment, size, maxval)."""
    raw = path.read_bytes()
    lines = raw.split(b"\n", 4)
    w, h = map(int, lines[2].split())
    return np.frombuffer(lines[4], dtype=np.uint8).reshape(h, w)


def test_trinary_writes_only_map_saver_levels_for_any_occupancy(tmp_path):
    # a SLAM map holds every percentage; map_saver writes 254 (<= 25 %), 0 (>= 65 %), 205 (the rest)
    values = np.arange(-1, 101, dtype=np.int8)
    save_map(GridMap(values.reshape(1, -1), 0.05), tmp_path / "m.yaml")
    pixels = _pgm_pixels(tmp_path / "m.pgm")[0]
    assert set(np.unique(pixels).tolist()) == {0, 205, 254}
    np.testing.assert_array_equal(pixels[values == -1], 205)
    np.testing.assert_array_equal(pixels[(values >= 0) & (values <= 25)], 254)
    np.testing.assert_array_equal(pixels[(values > 25) & (values < 65)], 205)
    np.testing.assert_array_equal(pixels[values >= 65], 0)
    back = load_map(tmp_path / "m.yaml").data[0]
    expected = np.where(values < 0, -1, np.where(values <= 25, 0, np.where(values >= 65, 100, -1)))
    np.testing.assert_array_equal(back, expected)


def test_trinary_thresholds_are_map_saver_occ_and_free(tmp_path):
    values = np.array([[10, 30, 50, 70]], dtype=np.int8)
    save_map(GridMap(values, 0.05), tmp_path / "m.yaml", threshold_free=30, threshold_occupied=50)
    np.testing.assert_array_equal(_pgm_pixels(tmp_path / "m.pgm")[0], [254, 254, 0, 0])


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"threshold_free": 70, "threshold_occupied": 65}, "threshold_free 70"),
        ({"free_thresh": 0.25}, "free_thresh 0.25"),
        ({"occupied_thresh": 1.0}, "occupied_thresh 1.0"),
        ({"crop_margin_cells": -1}, "crop_margin_cells -1"),
    ],
)
def test_save_refuses_thresholds_that_break_the_round_trip(tmp_path, kwargs, needle):
    with pytest.raises(MappingError, match=needle):
        save_map(GridMap(np.zeros((2, 2), np.int8), 0.05), tmp_path / "m.yaml", **kwargs)


def test_saved_map_is_cropped_to_known_cells_plus_margin(tmp_path):
    # a SLAM-sized allocation (400 x 300 cells) of which a 40 x 20 block is known
    data = np.full((300, 400), -1, np.int8)
    data[100:120, 200:240] = 0
    data[100, 200:240] = 100
    grid = GridMap(data, 0.05, (-10.0, -7.5, 0.0))
    save_map(grid, tmp_path / "m.yaml")
    back = load_map(tmp_path / "m.yaml")
    assert (back.width, back.height) == (40 + 20, 20 + 20)
    assert back.origin == pytest.approx((-10.0 + 190 * 0.05, -7.5 + 90 * 0.05, 0.0))
    # every cell keeps its place in the map frame
    centres = grid.centers(np.ones_like(data, bool))
    np.testing.assert_array_equal(back.value_at(centres), grid.value_at(centres))
    save_map(grid, tmp_path / "full.yaml", crop_margin_cells=None)
    assert load_map(tmp_path / "full.yaml").data.shape == (300, 400)


def test_crop_stops_at_the_grid_edge_and_keeps_a_rotated_origin(tmp_path):
    data = np.full((30, 50), -1, np.int8)
    data[0:5, 45:50] = 0  # known cells in a corner: the margin is clipped there
    grid = GridMap(data, 0.1, (1.0, 2.0, 0.5))
    save_map(grid, tmp_path / "m.yaml", crop_margin_cells=3)
    back = load_map(tmp_path / "m.yaml")
    assert (back.width, back.height) == (5 + 3, 5 + 3)
    centres = grid.centers(np.ones_like(data, bool))
    np.testing.assert_array_equal(back.value_at(centres), grid.value_at(centres))


def test_scale_loader_is_map_server_formula(tmp_path):
    # p = (255 - grey) / 255; in between: 1 + 98 * (p - free) / (occ - free), truncated
    greys = np.array([255, 254, 200, 150, 100, 89, 0], np.uint8)
    (tmp_path / "s.pgm").write_bytes(b"P5\n7 1\n255\n" + greys.tobytes())
    (tmp_path / "s.yaml").write_text("image: s.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nmode: scale\n")
    p = (255.0 - greys) / 255.0
    mid = np.floor(1 + 98 * (p - 0.196) / (0.65 - 0.196)).astype(int)
    expected = np.where(p > 0.65, 100, np.where(p < 0.196, 0, mid))
    np.testing.assert_array_equal(load_map(tmp_path / "s.yaml").data[0], expected)
    assert expected.tolist()[2:5] == [5, 47, 89]  # by hand: p = .216, .412, .608


def test_raw_loader_is_the_pixel_value(tmp_path):
    (tmp_path / "r.pgm").write_bytes(b"P5\n4 1\n255\n" + bytes([0, 37, 100, 255]))
    (tmp_path / "r.yaml").write_text("image: r.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nmode: raw\n")
    np.testing.assert_array_equal(load_map(tmp_path / "r.yaml").data[0], [0, 37, 100, -1])
