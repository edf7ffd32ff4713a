"""Deprecated (one release): the exploration node moved to ``navlab.drivers.explore``."""

from navlab.lazy import moved_exports

__getattr__ = moved_exports(
    __name__,
    {
        "Explore": "navlab.drivers.explore",
    },
)
