"""Pacing has one name, ``rate`` (as ``rosbag play --rate``): ``pace=`` of the launch functions and ``speed=`` of the
viewer still work this release, with a DeprecationWarning, and pace the run alike."""

from __future__ import annotations

import pytest

import navlab
from navlab.core.launch import start


def test_launch_takes_rate_and_the_old_pace_with_a_warning() -> None:
    session = start("talker_listener", rate=2.5)
    assert session.executor.rate == 2.5
    session.shutdown()
    with pytest.warns(DeprecationWarning, match=r"pace=\.\.\.\) is deprecated, use rate="):
        old = start("talker_listener", pace=2.5)
    assert old.executor.rate == 2.5
    old.shutdown()


def test_init_takes_rate_and_the_old_pace_with_a_warning() -> None:
    ctx = navlab.init(context=None, launch="talker_listener", rate=3.0)
    try:
        assert ctx.executor.rate == 3.0
    finally:
        navlab.shutdown(context=ctx)
    with pytest.warns(DeprecationWarning, match="navlab.init"):
        ctx = navlab.init(context=None, launch="talker_listener", pace=3.0)
    try:
        assert ctx.executor.rate == 3.0
    finally:
        navlab.shutdown(context=ctx)


def test_a_launch_argument_called_rate_goes_in_launch_args() -> None:
    session = start("talker_listener", rate=0.0, launch_args={"rate": 50.0})
    try:
        assert session.executor.rate == 0.0
        assert float(session.node("talker").get_parameter("rate")) == 50.0
    finally:
        session.shutdown()
