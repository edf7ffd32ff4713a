"""Deprecated (one release): frontier exploration moved to ``navlab.drivers.frontiers`` (its costs and
planner are navigation's costmap layers and heap now)."""

from navlab.lazy import moved_exports

__getattr__ = moved_exports(
    __name__,
    {
        "Frontier": "navlab.drivers.frontiers",
        "FrontierSearch": "navlab.drivers.frontiers",
        "find_frontiers": "navlab.drivers.frontiers",
        "plan_to_frontier": "navlab.drivers.frontiers",
        "prepare_frontier_search": "navlab.drivers.frontiers",
        "nearest_traversable": "navlab.drivers.frontiers",
        "extract_path": "navlab.drivers.frontiers",
    },
)
