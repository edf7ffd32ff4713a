"""Plugin seams, as Nav2 has them: small Protocols and registries keyed by the name a ROS user writes.

A parameter file picks an algorithm by its ROS plugin name (``base_global_planner: navfn/NavfnROS``,
``base_local_planner: dwa_local_planner/DWAPlannerROS``, a costmap ``plugins:`` entry's ``type:
costmap_2d::InflationLayer``, slam_gmapping's ``mode``, amcl's ``odom_model_type`` and
``laser_model_type``). The registry maps that name to ``"module:Class"``; :func:`load_plugin` imports
it on first use. Adding an algorithm is one new file and one line here. This module is a leaf: it
imports nothing of navlab but errors and types.

Every implementation is pure (numpy in, numpy out; no topics, no clock); its node holds parameters.
Units: metres, radians, seconds; poses ``(x, y, yaw)``; paths ``(N, 2)`` or ``(N, 3)`` arrays in the
costmap's frame.
"""

from __future__ import annotations

import difflib
import importlib
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from navlab.errors import NavlabError

if TYPE_CHECKING:
    from navlab.grid import Grid, GridMap


class PluginError(NavlabError):
    """An unknown plugin name, or a registered plugin that cannot be imported."""


# --- the seams ------------------------------------------------------------------------------------


@runtime_checkable
class SlamBackend(Protocol):
    """Online SLAM over laser scans: slam_gmapping's ``mode`` (``gmapping``, ``graph``).

    Built as ``cls(params, *, rng)``: ``params`` maps slam_gmapping parameter names to values (a mode's
    own parameters under its name, ``graph.voxel``); names left out take their defaults, which
    :meth:`parameters` lists for the node to declare. ``rng`` drives every random draw.
    """

    params: Any  # the mode's parameter object (e.g. ``GMappingParams``)

    @classmethod
    def parameters(cls) -> dict[str, Any]:
        """Every parameter name the mode reads, with its ROS default."""
        ...

    def add_scan(
        self,
        ranges: np.ndarray,
        angle_min: float,
        angle_increment: float,
        odom_laser: np.ndarray,
        *,
        range_max: float | None = None,
        stamp_ns: int | None = None,
    ) -> np.ndarray | None:
        """Process one scan (ranges m; inf/NaN = no return) taken with the laser at ``odom_laser`` (x, y, yaw
        in the odom frame) at ``stamp_ns`` (ns; None for a log's scans); returns the laser's pose in the map
        frame, or None when the scan only moved the estimate and did not update the map. ``range_max``:
        the sensor's (m), or None to take the ranges as they are."""
        ...

    def due(self, odom_laser: np.ndarray, stamp_ns: int) -> bool:
        """Whether a node should hand this scan to :meth:`add_scan` (slam_gmapping's linearUpdate,
        angularUpdate, temporalUpdate gating for modes that do not gate in ``add_scan`` themselves)."""
        ...

    def trajectory(self) -> np.ndarray:
        """Laser poses (M, 3) in the map frame now, one per scan for which ``add_scan`` returned a pose."""
        ...

    def current_map(self, *, frame_id: str = "map") -> GridMap | None:
        """The occupancy grid now, or None before the first scan."""
        ...

    def finish(self) -> np.ndarray:
        """Final laser poses (N, 3) in the map frame, one per ``add_scan`` call."""
        ...

    def stats(self) -> dict[str, int]:
        """Counters for a run's summary (updates, resamples, loop closures, ...)."""
        ...


class MotionModel(Protocol):
    """AMCL's ``odom_model_type``: move particles (N, 3; x, y m, yaw rad; map frame) in place by the
    odometry step from ``odom_old`` to ``odom_new`` (robot poses in the odom frame), with noise
    ``alphas`` = odom_alpha1..4 drawn from ``rng``."""

    def __call__(
        self,
        particles: np.ndarray,
        odom_old: tuple[float, float, float],
        odom_new: tuple[float, float, float],
        alphas: tuple[float, float, float, float],
        rng: np.random.Generator,
    ) -> None: ...


class LaserModel(Protocol):
    """AMCL's ``laser_model_type``: a score per particle for one scan (ROS amcl's ``1 + sum(pz**3)``).

    Built as ``cls(field, params)`` from the map's ``MapField`` and ``AmclParams``.
    """

    def weights(self, particles: np.ndarray, beams: Any, laser_pose: tuple[float, float, float]) -> np.ndarray:
        """Scores (N,) of particles (N, 3; map frame) for the chosen ``beams`` (``models.Beams``) of a laser
        at ``laser_pose`` (x, y, yaw in the robot base frame)."""
        ...


class CostmapLayer(Protocol):
    """A costmap_2d layer (``costmap_2d::StaticLayer``, ``ObstacleLayer``, ``InflationLayer``, ...).

    ``update_costs`` writes its costs (uint8, 0..254, 255 unknown) into ``master`` (a ``Grid``) over the
    whole grid; layers run in the order of the ``plugins:`` list.
    """

    def update_costs(self, master: Grid) -> None: ...


class GlobalPlanner(Protocol):
    """``base_global_planner``: a path from ``start`` to ``goal`` over a costmap, or None if there is none."""

    def make_plan(self, costmap: Grid, start: tuple[float, float, float], goal: tuple[float, float, float]
                  ) -> np.ndarray | None: ...  # fmt: skip


class Controller(Protocol):
    """``base_local_planner``: velocity commands that follow a global plan around what the costmap shows."""

    def set_plan(self, path: np.ndarray) -> None:
        """The global plan to follow: (N, 2) or (N, 3) in the controller's frame."""
        ...

    def compute_velocity(
        self, pose: tuple[float, float, float], velocity: tuple[float, float], costmap: Grid | None
    ) -> tuple[float, float]:
        """(v m/s, w rad/s) for the robot at ``pose`` moving at ``velocity`` (v, w)."""
        ...

    def is_goal_reached(self, pose: tuple[float, float, float], velocity: tuple[float, float]) -> bool: ...


# --- the registries --------------------------------------------------------------------------------

# kind -> {ROS plugin name: "module:attribute"}
REGISTRY: dict[str, dict[str, str]] = {
    "slam_backend": {
        "gmapping": "navlab.mapping.backends:GMappingBackend",
        "graph": "navlab.mapping.backends:GraphBackend",
    },
    "motion_model": {
        "diff": "navlab.localization.models:sample_motion_diff",
        "diff-corrected": "navlab.localization.models:sample_motion_diff_corrected",
        "nav2_amcl::DifferentialMotionModel": "navlab.localization.models:sample_motion_diff_corrected",
        "differential": "navlab.localization.models:sample_motion_diff_corrected",
    },  # ROS 1 amcl's omni models (omni, omni-corrected; Nav2 OmniMotionModel) are not provided
    "laser_model": {
        "likelihood_field": "navlab.localization.models:LikelihoodFieldModel",
        "beam": "navlab.localization.models:BeamModel",
    },
    "costmap_layer": {
        "navlab::ClearanceLayer": "navlab.mapping.explore:ClearanceLayer",
        "costmap_2d::StaticLayer": "navlab.navigation.costmap.layers:StaticLayer",
        "costmap_2d::ObstacleLayer": "navlab.navigation.costmap.layers:ObstacleLayer",
        "costmap_2d::InflationLayer": "navlab.navigation.costmap.layers:InflationLayer",
        "nav2_costmap_2d::StaticLayer": "navlab.navigation.costmap.layers:StaticLayer",
        "nav2_costmap_2d::ObstacleLayer": "navlab.navigation.costmap.layers:ObstacleLayer",
        "nav2_costmap_2d::InflationLayer": "navlab.navigation.costmap.layers:InflationLayer",
        "costmap_2d::VoxelLayer": "navlab.navigation.costmap.voxel_layer:VoxelLayer",
        "nav2_costmap_2d::VoxelLayer": "navlab.navigation.costmap.voxel_layer:VoxelLayer",
        "range_sensor_layer::RangeSensorLayer": "navlab.navigation.costmap.range_sensor_layer:RangeSensorLayer",
        "nav2_costmap_2d::RangeSensorLayer": "navlab.navigation.costmap.range_sensor_layer:RangeSensorLayer",
    },
    "global_planner": {
        "navlab/GridDijkstra": "navlab.mapping.explore:GridDijkstraPlanner",
        "navfn/NavfnROS": "navlab.navigation.planners.navfn:NavfnPlanner",
        "nav2_navfn_planner/NavfnPlanner": "navlab.navigation.planners.navfn:NavfnPlanner",
        "global_planner/GlobalPlanner": "navlab.navigation.planners.navfn:GlobalPlanner",
        "nav2_theta_star_planner/ThetaStarPlanner": "navlab.navigation.planners.theta_star:ThetaStarPlanner",
    },
    "recovery": {
        "clear_costmap_recovery/ClearCostmapRecovery": "navlab.navigation.recovery:ClearCostmapRecovery",
        "rotate_recovery/RotateRecovery": "navlab.navigation.recovery:RotateRecovery",
        "nav2_behaviors/BackUp": "navlab.navigation.recovery:BackUpRecovery",
    },
    "controller": {
        "navlab/PurePursuit": "navlab.mapping.follow:PurePursuit",
        "base_local_planner/TrajectoryPlannerROS": "navlab.navigation.controllers.trajectory:TrajectoryPlannerROS",
        "dwa_local_planner/DWAPlannerROS": "navlab.navigation.controllers.dwa:DWAPlannerROS",
        "nav2_mppi_controller::MPPIController": "navlab.navigation.controllers.mppi:MPPIController",
        "nav2_dwb_controller/DWBLocalPlanner": "navlab.navigation.controllers.dwa:DWBLocalPlanner",
    },
}


def plugin_names(kind: str) -> list[str]:
    """The registered names of a kind of plugin."""
    if kind not in REGISTRY:
        raise PluginError(f"unknown kind of plugin {kind!r} (kinds: {', '.join(REGISTRY)})")
    return list(REGISTRY[kind])


def load_plugin(kind: str, name: str, *, param: str | None = None) -> Any:
    """The class or function registered as ``name`` for ``kind``; an unknown name says "did you mean".

    ``param`` names the parameter the user set (for the error message), e.g. ``base_global_planner``.
    """
    table = REGISTRY.get(kind)
    if table is None:
        raise PluginError(f"unknown kind of plugin {kind!r} (kinds: {', '.join(REGISTRY)})")
    target = table.get(name)
    if target is None:
        close = difflib.get_close_matches(name, list(table), n=1, cutoff=0.5)
        hint = f"did you mean {close[0]!r}? " if close else ""
        what = f"{param} {name!r}" if param else f"{kind} {name!r}"
        raise PluginError(f"unknown {what} ({hint}known: {', '.join(table)})")
    module, _, attr = target.partition(":")
    try:
        return getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError) as exc:
        raise PluginError(f"{kind} {name!r}: cannot load {target} ({exc})") from None
