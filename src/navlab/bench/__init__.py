"""Benchmarks: measured performance figures, one module per benchmark group (``navlab bench NAME --json``,
the verb in :mod:`navlab.cli.bench`, prints them as JSON).

Each benchmark is a function ``run(args) -> dict`` registered in ``BENCHES`` by import path.
``navlab bench all --json`` runs them all (but ``soak``) and adds
``summary``: the headline figures (``nav_rtf``, ``nav_rtf_cpu``, ``sim_rtf``, ``nav_sim_ratio`` = nav_rtf_cpu /
sim_rtf, both per CPU second, ``start_s``, ``slam_peak_rss_mb``, ...). ``navlab bench compare OLD.json
NEW.json`` prints every figure the two share with its ratio new / old.
"""

from __future__ import annotations

from typing import Any

# name -> "module:function"; the function takes the parsed args and returns a JSON-able dict.
BENCHES: dict[str, str] = {
    "mapping": "navlab.bench.experiments:run_mapping_bench",
    "slam": "navlab.bench.mapping:run",
    "slam-office": "navlab.bench.mapping:run_office",
    "slam-gmapping": "navlab.bench.mapping:run_gmapping",
    "startup": "navlab.bench.startup:run",
    "core": "navlab.bench.core:run",
    "soak": "navlab.bench.core:run_soak",
    "amcl": "navlab.bench.localization:run",
    "description": "navlab.bench.description:run",
    "sim": "navlab.bench.sim:run",
    "decompose": "navlab.bench.decompose:run",
    "sensors": "navlab.bench.sensors:run",
    "controller": "navlab.bench.navigation:run_controller",
    "planner": "navlab.bench.navigation:run_planner",
    "nav": "navlab.bench.experiments:run_nav",
    "clutter": "navlab.bench.experiments:run_clutter",
    "odom": "navlab.bench.experiments:run_odom",
    "sweep": "navlab.bench.sweep:run",
    "view": "navlab.bench.view:run",
    "ros": "navlab.bench.ros:run",
}


# summary key -> (bench, key) of ``navlab bench all``
SUMMARY = {
    "nav_rtf": ("nav", "rtf"),
    "nav_rtf_cpu": ("nav", "rtf_cpu"),
    "sim_rtf": ("sim", "rtf"),
    "start_s": ("startup", "sim_start_cpu_s"),
    "help_s": ("startup", "help_cpu_s"),
    "trial_s": ("startup", "trial_cpu_s"),
    "slam_peak_rss_mb": ("slam-gmapping", "peak_rss_mb"),
    "slam_gmapping_cpu_s": ("slam-gmapping", "cpu_s"),
    "slam_gmapping_trans_m": ("slam-gmapping", "relations_trans_m"),
    "slam_gmapping_filter_trans_m": ("slam-gmapping", "filter_relations_trans_m"),
    "slam_graph_rtf": ("slam", "rtf"),
    "mapping_rtf": ("mapping", "rtf"),
}


def _flat(results: dict[str, Any], prefix: str = "") -> dict[str, float]:
    """Numeric figures of a bench JSON (nested for ``all``) as ``bench.key`` -> value."""
    out: dict[str, float] = {}
    for key, value in results.items():
        if isinstance(value, dict):
            out.update(_flat(value, f"{prefix}{key}."))
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            out[prefix + key] = float(value)
    return out


def compare(old: dict[str, Any], new: dict[str, Any]) -> list[tuple[str, float, float, float | None]]:
    """(figure, old, new, new / old) for every numeric figure both results hold, in the new one's order."""
    a, b = _flat(old), _flat(new)
    return [(k, a[k], v, v / a[k] if a[k] else None) for k, v in b.items() if k in a]
