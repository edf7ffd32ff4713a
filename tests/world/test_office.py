"""The generated office floor: size, alike rooms off corridors that close two loops, a loadable .world, a
collision-free route through both loops."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy import ndimage

from navlab.world import WorldError, load_world, occupancy
from navlab.world.office import generate_office


def test_office_is_large_with_many_alike_rooms_and_two_loops(tmp_path):
    office = generate_office()
    assert office.width >= 25.0 and office.depth >= 20.0 and office.rooms >= 20
    world = load_world(office.write_world(tmp_path / "office.world"))
    res = 0.1
    occ = occupancy(world, res, (-0.5, -0.5, office.width + 0.5, office.depth + 0.5), static_only=True)
    free = ~occ
    labels, n = ndimage.label(free)
    inside = labels[int((office.corridor_a + 0.5) / res), int((office.start[0] + 0.5) / res)]
    # every room is reachable from the corridors: one free region inside the outer walls, one outside
    assert n == 2 and inside != labels[0, 0]
    # two loops: the free space reachable from the start has two holes (the blocks) -> Euler number -1
    region = labels == inside
    _, holes = ndimage.label(~region[1:-1, 1:-1] & ndimage.binary_fill_holes(region)[1:-1, 1:-1])
    assert holes == 2
    # one door per room
    assert len(office.doors) == office.rooms


def test_route_is_collision_free_and_closes_both_loops():
    office = generate_office()
    route = office.route()
    for a, b in itertools.pairwise(route):
        s = np.linspace(0.0, 1.0, 100)[:, None]
        pts = a + (b - a) * s
        for dx, dy in ((0, 0), (0.3, 0), (-0.3, 0), (0, 0.3), (0, -0.3)):
            assert not office.occupied(pts + np.array([dx, dy])).any(), (a, b)
    xw, xm, xe = office.corridor_x
    visited = {tuple(p) for p in np.round(route, 3)}
    # the corners of both loops are on the route
    for x in (xw, xm, xe):
        for y in (office.corridor_a, office.corridor_b):
            assert (round(x, 3), round(y, 3)) in visited


def test_office_rejects_impossible_sizes():
    with pytest.raises(WorldError, match="corridor"):
        generate_office(corridor=0.8)
    with pytest.raises(WorldError, match="rooms_per_block"):
        generate_office(rooms_per_block=0)
