"""One wiring path: every run starts a launch file and adds its drivers and monitors as nodes.

``start_run("mapping", world=..., robot=..., pose=...)`` starts the shipped (or a user's) launch with the
robot's own base frame and scan topic, and returns a ``Run``: the launch session, the simulator node,
the robot's frames, and ``run()``, which advances simulated time with a progress bar (and optional
rosbag2 recording) and reports ``sim_s``, ``wall_s`` and ``rtf`` — the keys every run prints.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from navlab.core import Executor, Node, Session, run_for, start


@dataclass
class Run:
    """A started launch with its simulator: frames of the robot, and a clock-keeping ``run``."""

    session: Session
    gazebo: Any  # navlab.sim.gazebo.GazeboSim
    base_frame: str
    odom_frame: str
    scan_topic: str
    # sim_s, wall_s and this process's CPU time cpu_s (what one free core would take on a busy machine)
    timing: dict[str, float] = field(default_factory=lambda: {"sim_s": 0.0, "wall_s": 0.0, "cpu_s": 0.0})
    bag: Path | None = None  # the last recording made by ``run(record=...)``

    @property
    def executor(self) -> Executor:
        """The run's executor."""
        return self.session.executor

    @property
    def sim(self) -> Any:
        """The MuJoCo simulation (``navlab.sim.Simulation``)."""
        return self.gazebo.sim

    def node(self, name: str) -> Node:
        """A node of the launch by name."""
        return self.session.node(name)

    def add(self, node_class: type[Node], *, remappings: dict[str, str] | None = None, **kwargs: Any) -> Any:
        """Start one more node (a driver or a monitor) on this run's executor, as a launch would."""
        with self.executor.node_context(remappings=remappings):
            node = node_class(self.executor, **kwargs)
        self.session.nodes[node.fully_qualified_name] = node
        return node

    def run(
        self,
        duration: float,
        *,
        until: Callable[[], bool] | None = None,
        record: str | Path | None = None,
        quiet: bool = True,
        desc: str = "sim",
        chunk: float = 0.5,
    ) -> bool:
        """Run ``duration`` simulated s, or until ``until()`` is true (checked at each message); returns
        whether ``until`` ended it. Adds the time to ``timing``."""
        ex = self.executor
        t0, wall0, cpu0 = ex.now_ns, time.perf_counter(), time.process_time()
        bag = run_for(ex, duration, record=record, quiet=quiet, desc=desc, chunk=chunk, until=until)
        self.bag = bag if bag is not None else self.bag
        self.timing["sim_s"] += (ex.now_ns - t0) / 1e9
        self.timing["wall_s"] += time.perf_counter() - wall0
        self.timing["cpu_s"] += time.process_time() - cpu0
        return until is not None and until()

    def figures(self) -> dict[str, float]:
        """``{"sim_s", "wall_s", "rtf", "cpu_s"}`` of everything run so far (``cpu_s``: this process's CPU time)."""
        sim_s, wall_s = self.timing["sim_s"], self.timing["wall_s"]
        return {
            "sim_s": round(sim_s, 2),
            "wall_s": round(wall_s, 2),
            "rtf": round(sim_s / wall_s, 1) if wall_s > 0 else math.inf,
            "cpu_s": round(self.timing["cpu_s"], 2),
        }


def robot_frames(robot: str) -> tuple[str, str, str]:
    """(base frame, odom frame, scan topic) from a robot's plugin tags (shipped name or file)."""
    from navlab.description import load_robot_named

    model = load_robot_named(robot)
    dd = model.diff_drive
    base = dd.robot_base_frame if dd else model.root_link
    odom = dd.odometry_frame if dd else "odom"
    scan = model.lidars[0].topic if model.lidars else "scan"
    return base, odom, scan


def start_run(
    launch: str,
    *,
    world: str = "room",
    robot: str = "mybot",
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
    seed: int = 0,
    rate: float = 0.0,
    overrides: dict[str, dict[str, Any]] | None = None,
    on_start: Callable[[Run], None] | None = None,
    pace: float | None = None,
    **launch_args: Any,
) -> Run:
    """Start ``launch`` (a shipped name or a file with the sim's ``world``/``robot``/``x``/``y``/``yaw``
    arguments, plus ``base_frame``/``scan_topic`` when it declares them) and return the ``Run``.

    ``overrides`` maps node names to parameters applied after the launch file's (``--set``); ``on_start(run)``
    is called once the launch started (``--view`` attaches the viewer there). ``rate``: the pace (0 = as fast as
    possible, 1 = real time; ``pace``, its old name, is deprecated).
    """
    from navlab.core import declared_args
    from navlab.deprecation import renamed

    rate = renamed(rate, pace, old="pace", new="rate", where="start_run")

    base, odom, scan = robot_frames(robot)
    args: dict[str, Any] = {"world": world, "robot": robot, "x": pose[0], "y": pose[1], "yaw": pose[2]}
    declared = {str(a.get("name")) for a in declared_args(launch)}
    for key, value in (("base_frame", base), ("scan_topic", scan)):
        if key in declared:
            args[key] = value
    args.update(launch_args)
    session = start(launch, seed=seed, rate=rate, launch_args=args, overrides=overrides)
    run = Run(session, session.node("gazebo"), base, odom, scan)
    if on_start is not None:
        on_start(run)
    return run


def rounded(figures: dict[str, Any], digits: int = 4) -> dict[str, Any]:
    """Floats rounded for printing (in nested dicts and lists too); non-finite floats become None (valid JSON)."""
    return {key: _round(value, digits) for key, value in figures.items()}


def _round(value: Any, digits: int) -> Any:
    if isinstance(value, dict):
        return rounded(value, digits)
    if isinstance(value, list | tuple):
        return [_round(v, digits) for v in value]
    if isinstance(value, float):
        return round(value, digits) if math.isfinite(value) else None
    return value
