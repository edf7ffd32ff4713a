"""move_base's configuration: its parameters and their defaults (as ROS 1's move_base), their checks, the
parameter namespace of a plugin, and the recovery behaviours built from ``recovery_behaviors``."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from navlab.core import check_ceiling
from navlab.navigation.errors import NavigationError
from navlab.navigation.recovery import ClearCostmapRecovery
from navlab.plugins import PluginContext, load_plugin, make_plugin

MOVE_BASE_DEFAULTS: Mapping[str, Any] = MappingProxyType(
    {
        "base_global_planner": "navfn/NavfnROS",
        "base_local_planner": "base_local_planner/TrajectoryPlannerROS",
        "controller_frequency": 20.0,
        "planner_frequency": 0.0,
        "planner_patience": 5.0,
        "controller_patience": 15.0,
        "max_planning_retries": -1,
        "conservative_reset_dist": 3.0,
        "recovery_behavior_enabled": True,
        "clearing_rotation_allowed": True,
        "shutdown_costmaps": False,
        "oscillation_timeout": 0.0,
        "oscillation_distance": 0.5,
        "make_plan_clear_costmap": True,
        "make_plan_add_unreachable_goal": True,
        # navlab: while the progress checker sees no progress since the last recovery, moving
        # oscillation_distance does not restart recovery_behaviors, so they escalate (as Nav2's tree does)
        "escalate_recoveries": False,
    }
)


def short_name(plugin: str) -> str:
    """The parameter namespace of a plugin: ``navfn/NavfnROS`` -> ``NavfnROS``."""
    return plugin.replace("::", "/").rsplit("/", 1)[-1]


def check_move_base_params(p: dict[str, Any]) -> None:
    """Raise :class:`NavigationError` for a rate, patience or distance out of its range."""
    for key in ("controller_frequency", "planner_patience", "controller_patience", "oscillation_distance"):
        if not (math.isfinite(p[key]) and p[key] > 0):
            raise NavigationError(f"move_base parameter {key}: expected > 0, got {p[key]}")
    for key in ("planner_frequency", "oscillation_timeout", "conservative_reset_dist"):
        if not (math.isfinite(p[key]) and p[key] >= 0):
            raise NavigationError(f"move_base parameter {key}: expected >= 0, got {p[key]}")
    for key in ("controller_frequency", "planner_frequency"):
        check_ceiling(NavigationError, "move_base", key, p[key], "rate")


def make_recoveries(
    raw: Any,
    namespace: Callable[[str], dict[str, Any]],
    *,
    conservative_reset_dist: float,
    circumscribed_radius: float,
    rng: np.random.Generator,
) -> list[tuple[str, Any]]:
    """The (name, behaviour) pairs of ``recovery_behaviors`` (a list of ``{name, type}``), each configured from
    ``namespace(name)``; a costmap reset gets ``reset_distance`` as ROS 1 move_base sets it (unless the file does)."""
    if not isinstance(raw, list) or not all(isinstance(r, dict) and {"name", "type"} <= set(r) for r in raw):
        raise NavigationError(f"move_base parameter recovery_behaviors: expected a list of {{name, type}}, got {raw!r}")
    out = []
    for k, spec in enumerate(raw):
        name, kind = str(spec["name"]), str(spec["type"])
        params = namespace(name)
        if load_plugin("recovery", kind, param=f"recovery_behaviors[{k}] type") is ClearCostmapRecovery:
            default = conservative_reset_dist if name == "conservative_reset" else (4.0 * circumscribed_radius)
            params = {"reset_distance": default, **params}
        out.append((name, make_plugin("recovery", kind, params, context=PluginContext(name=name, rng=rng))))
    return out
