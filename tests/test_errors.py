"""Every exception navlab defines derives from NavlabError, so one ``except NavlabError`` catches them."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import warnings

import pytest

import navlab
from navlab import msgs
from navlab.deprecation import NavlabDeprecationWarning
from navlab.errors import NavlabError
from navlab.sim import SimError
from navlab.sim.diffdrive import EncoderOdometry, wheel_speeds


def _navlab_modules() -> list[str]:
    return sorted(m.name for m in pkgutil.walk_packages(navlab.__path__, "navlab."))


def test_every_public_exception_class_derives_from_navlab_error():
    offenders = []
    for name in _navlab_modules():
        with warnings.catch_warnings():  # an old module path kept for one release warns on import (it defines nothing)
            warnings.simplefilter("ignore", NavlabDeprecationWarning)
            module = importlib.import_module(name)
        for attr, obj in vars(module).items():
            if (
                inspect.isclass(obj)
                and issubclass(obj, BaseException)
                and obj.__module__ == name
                and not attr.startswith("_")
                and not issubclass(obj, NavlabError)
            ):
                offenders.append(f"{name}.{attr}({', '.join(b.__name__ for b in obj.__bases__)})")
    assert offenders == []


def test_unknown_message_type_is_a_navlab_error_and_still_a_lookup_error():
    with pytest.raises(NavlabError, match="did you mean geometry_msgs/msg/Twist"):
        msgs.get_type("geometry_msgs/Twst")
    assert issubclass(msgs.MessageTypeError, LookupError)


@pytest.mark.parametrize(("separation", "diameter"), [(0.0, 0.1), (0.4, -0.1), (float("nan"), 0.1)])
def test_bad_diff_drive_geometry_is_a_sim_error(separation, diameter):
    with pytest.raises(SimError, match=r"wheel separation .* m and wheel diameter .* m: expected finite numbers > 0"):
        wheel_speeds(0.2, 0.0, separation, diameter)
    with pytest.raises(NavlabError):
        EncoderOdometry(separation, diameter)
