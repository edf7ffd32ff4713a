"""What a physics step skips for speed changes no motion, bit for bit: MuJoCo's profiling timers, and its spring and
damper passes on a model that has neither."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from sim_helpers import make_mybot, make_room

from navlab.description import load_robot_named
from navlab.sim import Simulation


def _drive(sim: Simulation) -> np.ndarray:
    """Drive a curve for 1 s (500 steps, wheels touching the floor) and return the state."""
    sim.set_wheel_velocity_targets(4.0, 6.0)
    sim.step(500)
    return np.concatenate([sim.data.qpos, sim.data.qvel, sim.data.qacc_warmstart])


def test_mujoco_timers_are_off_in_a_simulation_and_a_users_clock_is_kept() -> None:
    step = int(mujoco.mjtTimer.mjTIMER_STEP)
    ticks: list[int] = []

    def clock() -> float:
        ticks.append(1)
        return float(len(ticks))

    mujoco.set_mjcb_time(clock)  # the user's own timer callback: kept, and its timers count
    try:
        timed = Simulation(make_mybot(), make_room(), seed=0)
        assert mujoco.get_mjcb_time() is clock
        timed_state = _drive(timed)
        assert timed.data.timer[step].number == 500 and ticks
    finally:
        mujoco.set_mjcb_time(None)
    untimed = Simulation(make_mybot(), make_room(), seed=0)
    untimed_state = _drive(untimed)
    assert untimed.data.timer[step].duration == 0.0  # no stage timed (MuJoCo still counts the calls)
    assert np.array_equal(timed_state, untimed_state)  # the same motion, bit for bit


@pytest.mark.parametrize("robot", ["mybot", "jackal"])
def test_spring_and_damper_passes_are_off_without_springs_or_dampers_and_change_nothing(robot: str) -> None:
    bits = int(mujoco.mjtDisableBit.mjDSBL_SPRING) | int(mujoco.mjtDisableBit.mjDSBL_DAMPER)
    model, world = load_robot_named(robot), make_room()
    skipped = Simulation(model, world, seed=0)
    assert skipped.model.opt.disableflags & bits == bits  # no joint stiffness or damping on the shipped robots
    computed = Simulation(model, world, seed=0)
    computed.model.opt.disableflags &= ~bits
    assert np.array_equal(_drive(skipped), _drive(computed))  # the same motion, bit for bit
