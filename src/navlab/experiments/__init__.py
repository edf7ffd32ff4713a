"""Experiments: scenarios, trials, metrics and reports that reproduce and extend the paper's experiments.

``metrics`` holds the accuracy measures (the SLAM relations metric of Kümmerle et al. 2009 and the
``timestamp x y theta`` pose files it reads and writes).
"""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.experiments.clutter_protocol import JACKAL_MAX_SPEED, run_protocol
    from navlab.experiments.errors import ExperimentError
    from navlab.experiments.localize_run import DEFAULT_ROUTE, plot_result, run_localization
    from navlab.experiments.mapping_run import read_trajectory as read_map_trajectory
    from navlab.experiments.mapping_run import run_mapping
    from navlab.experiments.metrics import (
        free_coverage,
        read_poses,
        read_relations,
        relations_closure,
        relations_error,
        score_map,
        trajectory_error,
        write_poses,
    )
    from navlab.experiments.navigate_run import run_navigation, save_goal_pictures
    from navlab.experiments.odom_run import ROBOTS, ROUTES, run_drift
    from navlab.experiments.plots import Track, plot_run
    from navlab.experiments.report import render_report
    from navlab.experiments.scenario import load_scenario
    from navlab.experiments.session import rounded, start_run
    from navlab.experiments.sweep import parse_params, run_sweep
    from navlab.experiments.trajectory import align_se2, apply_se2, associate, ate, read_trajectory, trajectory_ate
    from navlab.experiments.trials import read_results, run_experiment

_EXPORTS = {
    "align_se2": "navlab.experiments.trajectory",
    "associate": "navlab.experiments.trajectory",
    "DEFAULT_ROUTE": "navlab.experiments.localize_run",
    "read_poses": "navlab.experiments.metrics",
    "read_relations": "navlab.experiments.metrics",
    "relations_error": "navlab.experiments.metrics",
    "write_poses": "navlab.experiments.metrics",
    "ExperimentError": "navlab.experiments.errors",
    "JACKAL_MAX_SPEED": "navlab.experiments.clutter_protocol",
    "ROBOTS": "navlab.experiments.odom_run",
    "ROUTES": "navlab.experiments.odom_run",
    "Track": "navlab.experiments.plots",
    "apply_se2": "navlab.experiments.trajectory",
    "ate": "navlab.experiments.trajectory",
    "free_coverage": "navlab.experiments.metrics",
    "load_scenario": "navlab.experiments.scenario",
    "parse_params": "navlab.experiments.sweep",
    "plot_result": "navlab.experiments.localize_run",
    "plot_run": "navlab.experiments.plots",
    "read_map_trajectory": "navlab.experiments.mapping_run:read_trajectory",
    "read_trajectory": "navlab.experiments.trajectory",
    "relations_closure": "navlab.experiments.metrics",
    "read_results": "navlab.experiments.trials",
    "render_report": "navlab.experiments.report",
    "rounded": "navlab.experiments.session",
    "run_drift": "navlab.experiments.odom_run",
    "run_experiment": "navlab.experiments.trials",
    "run_localization": "navlab.experiments.localize_run",
    "run_mapping": "navlab.experiments.mapping_run",
    "run_navigation": "navlab.experiments.navigate_run",
    "run_protocol": "navlab.experiments.clutter_protocol",
    "run_sweep": "navlab.experiments.sweep",
    "save_goal_pictures": "navlab.experiments.navigate_run",
    "score_map": "navlab.experiments.metrics",
    "start_run": "navlab.experiments.session",
    "trajectory_ate": "navlab.experiments.trajectory",
    "trajectory_error": "navlab.experiments.metrics",
}
__all__ = [
    "DEFAULT_ROUTE",
    "JACKAL_MAX_SPEED",
    "ROBOTS",
    "ROUTES",
    "ExperimentError",
    "Track",
    "align_se2",
    "apply_se2",
    "associate",
    "ate",
    "free_coverage",
    "load_scenario",
    "parse_params",
    "plot_result",
    "plot_run",
    "read_map_trajectory",
    "read_poses",
    "read_relations",
    "read_results",
    "read_trajectory",
    "relations_closure",
    "relations_error",
    "render_report",
    "rounded",
    "run_drift",
    "run_experiment",
    "run_localization",
    "run_mapping",
    "run_navigation",
    "run_protocol",
    "run_sweep",
    "save_goal_pictures",
    "score_map",
    "start_run",
    "trajectory_ate",
    "trajectory_error",
    "write_poses",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
