"""Fixtures for sim tests: the paper's mybot and a walled room (built in sim_helpers)."""

from __future__ import annotations

import pytest
from sim_helpers import make_mybot, make_room

from navlab.description import RobotModel
from navlab.world import WorldModel


@pytest.fixture
def mybot() -> RobotModel:
    return make_mybot()


@pytest.fixture
def room() -> WorldModel:
    return make_room()
