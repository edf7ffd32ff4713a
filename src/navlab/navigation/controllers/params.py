"""Parameters of base_local_planner's TrajectoryPlannerROS and dwa_local_planner's DWAPlannerROS.

ROS 1 names and defaults (the ROS wiki's tables). Older and newer ROS 1 spellings are both read:
``backup_vel`` / ``escape_vel``, ``max_trans_vel`` / ``max_vel_trans``, ``max_rot_vel`` /
``max_vel_theta``, ``min_rot_vel`` / ``min_vel_theta`` (DWA: the least |w|), ``acc_lim_th`` /
``acc_lim_theta``, ``rot_stopped_vel`` / ``theta_stopped_vel``, and the scoring weights
``pdist_scale`` / ``path_distance_bias``, ``gdist_scale`` / ``goal_distance_bias`` in both namespaces.
``controller_frequency`` is move_base's (the planners search it upward); it sets ``sim_period``.
Units: m, rad, s, m/s, rad/s, m/s², rad/s².

Read but without effect, because navlab's controllers command a differential base (v, w):
``holonomic_robot``, ``y_vels``, ``acc_lim_y``, ``max_vel_y``, ``min_vel_y``, ``vy_samples``; and, as in
ROS noetic's dwa_local_planner, ``stop_time_buffer``, ``scaling_speed``, ``max_scaling_factor`` (the
footprint is not scaled with speed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

from navlab.core import ParamSpec, check_ceiling
from navlab.navigation.controllers.common import bad
from navlab.navigation.errors import NavigationError

TP = "TrajectoryPlannerROS"
DWA = "DWAPlannerROS"
_VIEW_ONLY = frozenset(
    {
        "publish_cost_grid_pc",
        "publish_traj_pc",
        "publish_cost_grid",
        "global_frame_id",
        "restore_defaults",
        "plugin",
        "use_sim_time",
    }
)


class _Periodic:
    """What both planners' parameters derive from ``controller_frequency``."""

    controller_frequency: float

    @property
    def sim_period(self) -> float:
        """1 / controller_frequency (s)."""
        return 1.0 / self.controller_frequency


@dataclass
class TrajectoryPlannerParams(_Periodic):
    """base_local_planner/TrajectoryPlannerROS (ROS 1 names and defaults)."""

    acc_lim_x: float = 2.5
    acc_lim_y: float = 2.5
    acc_lim_theta: float = 3.2
    max_vel_x: float = 0.5
    min_vel_x: float = 0.1
    max_vel_theta: float = 1.0
    min_vel_theta: float = -1.0
    min_in_place_vel_theta: float = 0.4
    escape_vel: float = -0.1
    holonomic_robot: bool = True
    y_vels: list[float] = field(default_factory=lambda: [-0.3, -0.1, 0.1, 0.3])
    sim_time: float = 1.0
    sim_granularity: float = 0.025
    angular_sim_granularity: float = -1.0  # <= 0: sim_granularity (ROS's default)
    vx_samples: int = 3
    vtheta_samples: int = 20
    controller_frequency: float = 20.0
    pdist_scale: float = 0.6
    gdist_scale: float = 0.8
    occdist_scale: float = 0.01
    heading_lookahead: float = 0.325
    heading_scoring: bool = False
    heading_scoring_timestep: float = 0.8
    simple_attractor: bool = False
    dwa: bool = True
    meter_scoring: bool = False
    oscillation_reset_dist: float = 0.05
    escape_reset_dist: float = 0.10
    escape_reset_theta: float = math.pi / 4.0
    xy_goal_tolerance: float = 0.1
    yaw_goal_tolerance: float = 0.05
    latch_xy_goal_tolerance: bool = False
    prune_plan: bool = True
    PARAMS: ClassVar[ParamSpec]

    def validate(self) -> None:
        """Raise ``NavigationError`` naming the first bad parameter."""
        ang = self.angular_sim_granularity if self.angular_sim_granularity > 0 else self.sim_granularity
        steps = (
            max(
                max(abs(self.max_vel_x), abs(self.escape_vel)) * self.sim_time / self.sim_granularity,
                max(abs(self.max_vel_theta), abs(self.min_vel_theta)) / ang,
            )
            + 1
        )
        _sized(TP, self, steps, "vx_samples", "vtheta_samples")
        _ordered(TP, self, "min_vel_x", "max_vel_x")
        _ordered(TP, self, "min_vel_theta", "max_vel_theta")
        if self.escape_vel > 0.0:
            raise bad(TP, "escape_vel", self.escape_vel, "<= 0 (a backward speed)")
        if self.simple_attractor:
            raise bad(TP, "simple_attractor", True, "false (navlab scores trajectories by path and goal distance)")


@dataclass
class DWAPlannerParams(_Periodic):
    """dwa_local_planner/DWAPlannerROS (ROS 1 names and defaults; ``min_vel_theta`` is the least |w|)."""

    acc_lim_x: float = 2.5
    acc_lim_y: float = 2.5
    acc_lim_theta: float = 3.2
    acc_lim_trans: float = 0.1
    max_vel_trans: float = 0.55
    min_vel_trans: float = 0.1
    max_vel_x: float = 0.55
    min_vel_x: float = 0.0
    max_vel_y: float = 0.1
    min_vel_y: float = -0.1
    max_vel_theta: float = 1.0
    min_vel_theta: float = 0.4
    trans_stopped_vel: float = 0.1
    theta_stopped_vel: float = 0.1
    sim_time: float = 1.7
    sim_granularity: float = 0.025
    angular_sim_granularity: float = 0.1
    vx_samples: int = 3
    vy_samples: int = 10
    vth_samples: int = 20
    controller_frequency: float = 20.0
    path_distance_bias: float = 32.0
    goal_distance_bias: float = 24.0
    occdist_scale: float = 0.01
    twirling_scale: float = 0.0
    forward_point_distance: float = 0.325
    stop_time_buffer: float = 0.2
    scaling_speed: float = 0.25
    max_scaling_factor: float = 0.2
    oscillation_reset_dist: float = 0.05
    oscillation_reset_angle: float = 0.2
    xy_goal_tolerance: float = 0.1
    yaw_goal_tolerance: float = 0.05
    latch_xy_goal_tolerance: bool = False
    prune_plan: bool = True
    use_dwa: bool = True
    cheat_factor: float = 1.0
    PARAMS: ClassVar[ParamSpec]

    def validate(self) -> None:
        """Raise ``NavigationError`` naming the first bad parameter."""
        steps = (
            self.sim_time
            * max(
                max(abs(self.max_vel_x), abs(self.min_vel_x), self.max_vel_trans) / self.sim_granularity,
                self.max_vel_theta / self.angular_sim_granularity,
            )
            + 1
        )
        _sized(DWA, self, steps, "vx_samples", "vth_samples")
        _ordered(DWA, self, "min_vel_x", "max_vel_x")
        _ordered(DWA, self, "min_vel_trans", "max_vel_trans")
        _ordered(DWA, self, "min_vel_theta", "max_vel_theta")


def _sized(what: str, obj: Any, steps: float, *sample_keys: str) -> None:
    """The ceilings of the work one control cycle does (samples x steps poses) and of its rate."""
    check_ceiling(NavigationError, what, "controller_frequency", obj.controller_frequency, "rate")
    samples = math.prod(getattr(obj, k) for k in sample_keys)
    check_ceiling(
        NavigationError,
        what,
        f"{' x '.join(sample_keys)} x steps (sim_time / sim_granularity)",
        samples * steps,
        "rollout_poses",
    )


def _ordered(what: str, obj: Any, low: str, high: str) -> None:
    if getattr(obj, low) > getattr(obj, high):
        raise bad(what, low, getattr(obj, low), f"<= {high} ({getattr(obj, high)})")


def _oldest_spelling(values: dict[str, Any]) -> dict[str, Any]:
    """TrajectoryPlannerROS's oldest ``max_rotational_vel`` sets both ends of the rotation range."""
    if "max_rotational_vel" in values:
        values = dict(values)
        vmax = values.pop("max_rotational_vel")
        values.setdefault("max_vel_theta", vmax)
        values.setdefault(
            "min_vel_theta", -vmax if isinstance(vmax, int | float) and not isinstance(vmax, bool) else vmax
        )
    return values


# a sample count <= 0 becomes 1 with a warning, as both ROS 1 planners do
TrajectoryPlannerParams.PARAMS = ParamSpec(
    TP,
    NavigationError,
    ignored=_VIEW_ONLY,
    prepare=_oldest_spelling,
    clamp_at_least={"vx_samples": 1, "vtheta_samples": 1},
    above=dict.fromkeys(
        (
            "acc_lim_x",
            "acc_lim_theta",
            "sim_time",
            "sim_granularity",
            "controller_frequency",
            "max_vel_x",
            "max_vel_theta",
        ),
        0.0,
    ),
    at_least=dict.fromkeys(
        (
            "acc_lim_y",
            "min_in_place_vel_theta",
            "pdist_scale",
            "gdist_scale",
            "occdist_scale",
            "heading_lookahead",
            "oscillation_reset_dist",
            "xy_goal_tolerance",
            "yaw_goal_tolerance",
            "escape_reset_dist",
            "escape_reset_theta",
            "min_vel_x",
        ),
        0.0,
    ),
    aliases={
        "backup_vel": "escape_vel",
        "acc_lim_th": "acc_lim_theta",
        "path_distance_bias": "pdist_scale",
        "goal_distance_bias": "gdist_scale",
        "vth_samples": "vtheta_samples",
    },
)
DWAPlannerParams.PARAMS = ParamSpec(
    DWA,
    NavigationError,
    ignored=_VIEW_ONLY,
    clamp_at_least={"vx_samples": 1, "vy_samples": 1, "vth_samples": 1},
    above=dict.fromkeys(
        (
            "acc_lim_x",
            "acc_lim_theta",
            "sim_time",
            "sim_granularity",
            "angular_sim_granularity",
            "controller_frequency",
            "max_vel_trans",
            "max_vel_x",
        ),
        0.0,
    ),
    at_least=dict.fromkeys(
        (
            "min_vel_trans",
            "min_vel_theta",
            "max_vel_theta",
            "path_distance_bias",
            "goal_distance_bias",
            "occdist_scale",
            "twirling_scale",
            "forward_point_distance",
            "oscillation_reset_dist",
            "xy_goal_tolerance",
            "yaw_goal_tolerance",
            "trans_stopped_vel",
            "theta_stopped_vel",
            "stop_time_buffer",
        ),
        0.0,
    ),
    aliases={
        "max_trans_vel": "max_vel_trans",
        "min_trans_vel": "min_vel_trans",
        "max_rot_vel": "max_vel_theta",
        "min_rot_vel": "min_vel_theta",
        "acc_lim_th": "acc_lim_theta",
        "rot_stopped_vel": "theta_stopped_vel",
        "pdist_scale": "path_distance_bias",
        "gdist_scale": "goal_distance_bias",
        "vtheta_samples": "vth_samples",
        "dwa": "use_dwa",
    },
)
