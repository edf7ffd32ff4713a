"""The parameters of Nav2's MPPI controller (``MppiParams``) and how they are read: Nav2 names and defaults,
critic sections (``CostCritic: {...}`` or dotted ``CostCritic.cost_weight``) read by each critic's own spec.

Split from :mod:`navlab.navigation.controllers.mppi`, which re-exports ``MppiParams``. Units: m, rad, s.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from navlab.core import ParamSpec, check_ceiling, read_params
from navlab.errors import did_you_mean
from navlab.navigation.controllers import mppi_critics as critics
from navlab.navigation.controllers.common import bad
from navlab.navigation.errors import NavigationError

WHAT = "MPPIController"
_IGNORED = frozenset(
    {
        "plugin",
        "visualize",
        "publish_optimal_trajectory",
        "regenerate_noises",
        "reset_period",
        "transform_tolerance",
        "enforce_path_inversion",
        "use_sim_time",
        "TrajectoryVisualizer",
        "open_loop",
        "shift_control_sequence",
    }
)


@dataclass
class MppiParams:
    """nav2_mppi_controller's parameters (Nav2 names and defaults; critic sections in ``critic_params``)."""

    batch_size: int = 1000
    time_steps: int = 56
    model_dt: float = 0.05
    iteration_count: int = 1
    temperature: float = 0.3
    gamma: float = 0.015
    vx_std: float = 0.2
    vy_std: float = 0.2
    wz_std: float = 0.4
    vx_max: float = 0.5
    vx_min: float = -0.35
    vy_max: float = 0.5
    wz_max: float = 1.9
    ax_max: float = 3.0
    ax_min: float = -3.0
    ay_max: float = 3.0
    az_max: float = 3.5
    motion_model: str = "DiffDrive"
    prune_distance: float = 1.7
    retry_attempt_limit: int = 1
    noise_correlation: float = 0.9  # navlab: AR(1) coefficient of the noise over time (0: Nav2's white noise)
    # navlab: RPP's cost-regulated speed limit (its names and defaults; off as MPPI has none)
    use_cost_regulated_linear_velocity_scaling: bool = False
    cost_scaling_dist: float = 0.6  # m from the robot's centre to the obstacle
    cost_scaling_gain: float = 1.0
    inflation_cost_scaling_factor: float = 3.0  # the inflation layer's cost_scaling_factor
    regulated_linear_scaling_min_speed: float = 0.25  # m/s
    # navlab: Nav2's rotation shim (its names and defaults) for a robot standing facing away from its path (off)
    use_rotation_shim: bool = False
    angular_dist_threshold: float = 0.785  # rad
    forward_sampling_distance: float = 0.5  # m
    rotate_to_heading_angular_vel: float = 1.8  # rad/s
    max_angular_accel: float = 3.2  # rad/s²
    simulate_ahead_time: float = 1.0  # s
    rotation_shim_max_speed: float = 0.1  # m/s: the shim turns the robot only when it moves slower
    rotation_shim_backup_dist: float = 0.0  # m: where the turn is blocked, back out straight up to this far (0: never)
    rotation_shim_backup_speed: float = 0.25  # m/s
    controller_frequency: float = 20.0
    xy_goal_tolerance: float = 0.25
    yaw_goal_tolerance: float = 0.25
    stateful: bool = True
    critics: list[str] = field(
        default_factory=lambda: [
            "ConstraintCritic",
            "CostCritic",
            "GoalCritic",
            "GoalAngleCritic",
            "PathAlignCritic",
            "PathFollowCritic",
            "PathAngleCritic",
            "PreferForwardCritic",
        ]
    )
    critic_params: dict[str, Any] = field(default_factory=dict)

    PARAMS: ClassVar[ParamSpec]

    def critic(self, name: str) -> Any:
        """The parameters of critic ``name`` (its defaults if the file set none)."""
        return self.critic_params.get(name) or critics.CRITICS[name]()

    def validate(self) -> None:
        """Raise ``NavigationError`` naming the first bad parameter (what spans fields or needs its own words; the
        ranges are in ``PARAMS``)."""
        if not 0.0 <= self.noise_correlation < 1.0:
            raise bad(WHAT, "noise_correlation", self.noise_correlation, "0 <= value < 1")
        if self.ax_min > 0:
            raise bad(WHAT, "ax_min", self.ax_min, "<= 0 (a deceleration)")
        if not self.vx_max > 0:
            raise bad(WHAT, "vx_max", self.vx_max, "> 0 (a forward speed)")
        if self.vx_min > self.vx_max:
            raise bad(WHAT, "vx_min", self.vx_min, f"<= vx_max ({self.vx_max})")
        check_ceiling(NavigationError, WHAT, "controller_frequency", self.controller_frequency, "rate")
        check_ceiling(
            NavigationError,
            WHAT,
            "batch_size x time_steps x iteration_count",
            self.batch_size * self.time_steps * self.iteration_count,
            "rollout_poses",
        )
        if self.motion_model != "DiffDrive":
            raise bad(WHAT, "motion_model", self.motion_model, "'DiffDrive' (navlab's controllers drive (v, w))")
        for name in self.critics:
            if name not in critics.CRITICS:
                hint = did_you_mean(name, critics.CRITICS, template="did you mean {!r}? ")
                raise bad(WHAT, "critics", name, f"a known critic ({hint}known: {', '.join(critics.CRITICS)})")


def _critic_sections(values: dict[str, Any]) -> dict[str, Any]:
    """Nav2's critic sections (``CostCritic: {...}`` or dotted ``CostCritic.cost_weight``) read by their own
    specs into ``critic_params``; critic names without their ``mppi::critics::`` prefix."""
    flat: dict[str, Any] = {}
    sections: dict[str, dict[str, Any]] = {}
    names = [f.name for f in fields(MppiParams) if f.name != "critic_params"]
    for key, val in values.items():
        head, dot, tail = str(key).partition(".")
        if head in critics.CRITICS:
            sections.setdefault(head, {}).update({tail: val} if dot else dict(val or {}))
        elif dot or (isinstance(val, Mapping) and head not in _IGNORED):
            raise NavigationError(f"unknown {WHAT} parameter '{key}'{did_you_mean(head, [*names, *critics.CRITICS])}")
        else:
            flat[key] = val
    if isinstance(flat.get("critics"), list | tuple):
        flat["critics"] = [str(c).rsplit("::", 1)[-1] for c in flat["critics"]]
    flat["critic_params"] = {name: read_params(critics.CRITICS[name], sec) for name, sec in sections.items()}
    return flat


MppiParams.PARAMS = ParamSpec(
    WHAT,
    NavigationError,
    ignored=_IGNORED,
    prepare=_critic_sections,
    at_least={
        **dict.fromkeys(("batch_size", "iteration_count", "retry_attempt_limit"), 1),
        "time_steps": 2,
        **dict.fromkeys(("gamma", "xy_goal_tolerance", "yaw_goal_tolerance", "regulated_linear_scaling_min_speed"), 0),
        **dict.fromkeys(
            (
                "angular_dist_threshold",
                "forward_sampling_distance",
                "simulate_ahead_time",
                "rotation_shim_max_speed",
                "rotation_shim_backup_dist",
            ),
            0,
        ),
    },
    above=dict.fromkeys(
        (
            "model_dt",
            "temperature",
            "vx_std",
            "wz_std",
            "wz_max",
            "ax_max",
            "az_max",
            "prune_distance",
            "controller_frequency",
            "cost_scaling_dist",
            "cost_scaling_gain",
            "inflation_cost_scaling_factor",
            "rotate_to_heading_angular_vel",
            "rotation_shim_backup_speed",
            "max_angular_accel",
        ),
        0,
    ),
)
