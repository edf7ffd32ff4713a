"""The shipped jackal's wheels grip as the real Jackal's do: its weight rides on the driven wheels and a 2 m/s
start does not spin them, so the wheel odometry stays with the truth (mapless navigation at the Jackal's 2 m/s
marks obstacles where they are)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
from sim_helpers import make_room

from navlab import msgs, resources
from navlab.core import Context, Executor, Node
from navlab.description import load_robot
from navlab.sim import launch_sim


def _start(ex: Executor) -> object:
    return launch_sim(
        ex, world=make_room(12.0, 4.0), robot=load_robot(resources.robot("jackal")), pose=(-4.0, 0.0, 0.0)
    )


def test_jackal_rests_on_its_wheels() -> None:
    ex = Executor(seed=0)
    sim = _start(ex).sim  # type: ignore[attr-defined]
    ex.run(0.5)
    wheels = {mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, f"{s}_wheel_link") for s in ("left", "right")}
    force, on_wheels = np.zeros(6), 0.0
    for i in range(sim.data.ncon):
        c = sim.data.contact[i]
        mujoco.mj_contactForce(sim.model, sim.data, i, force)
        if {int(sim.model.geom_bodyid[c.geom1]), int(sim.model.geom_bodyid[c.geom2])} & wheels:
            on_wheels += force[0]
    weight = float(sim.model.body_mass.sum()) * 9.81
    assert on_wheels > 0.9 * weight  # the casters only keep the chassis from pitching


def test_jackal_starts_at_2_m_s_without_wheel_spin() -> None:
    ex = Executor(seed=0)
    sim = _start(ex).sim  # type: ignore[attr-defined]
    node = Node("driver", context=Context(ex))
    odom: list[tuple[float, float, float]] = []
    node.create_subscription(msgs.Odometry, "odom", lambda m: odom.append(msgs.pose2d(m.pose.pose)))
    pub = node.create_publisher(msgs.Twist, "cmd_vel")
    cmd = [0.0]
    node.create_timer(0.05, lambda: pub.publish(msgs.twist(cmd[0], 0.0)))
    ex.run(0.5)
    x0, o0, worst = sim.base_pose2d("base_link")[0], odom[-1][0], 0.0
    cmd[0] = 2.0  # a step to the Jackal's top speed
    for _ in range(8):
        ex.run(0.25)
        worst = max(worst, abs((odom[-1][0] - o0) - (sim.base_pose2d("base_link")[0] - x0)))
    travelled = sim.base_pose2d("base_link")[0] - x0
    assert travelled > 3.0  # it does reach 2 m/s (at 4 m/s² of wheel acceleration)
    assert worst < 0.1  # was 0.55 m: the wheels spun up at once with the casters carrying 71 % of the weight
    assert math.isclose(sim.base_pose2d("base_link")[1], 0.0, abs_tol=0.02)
