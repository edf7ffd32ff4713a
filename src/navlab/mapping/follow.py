"""Deprecated (one release): pure pursuit moved to ``navlab.navigation.controllers.pure_pursuit``."""

from navlab.lazy import moved_exports

__getattr__ = moved_exports(
    __name__,
    {
        "PurePursuit": "navlab.navigation.controllers.pure_pursuit",
        "PurePursuitParams": "navlab.navigation.controllers.pure_pursuit",
        "follow_path": "navlab.navigation.controllers.pure_pursuit",
    },
)
