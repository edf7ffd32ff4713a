"""Teleop: teleop_twist_keyboard's keys, teleop_twist_joy's mapping, scripted routes driving the real sim."""

import pytest

from navlab.core import Executor
from navlab.drivers import DriverError, JoyMapping, RouteFollower, TeleopKeyboard, TeleopState, load_route


def test_keyboard_bindings_and_speed_keys():
    s = TeleopState()
    s.key("i")
    assert (s.twist().linear.x, s.twist().angular.z) == (0.5, 0.0)
    s.key("u")
    assert (s.twist().linear.x, s.twist().angular.z) == (0.5, 1.0)
    s.key("q")
    assert s.twist().linear.x == pytest.approx(0.55) and s.twist().angular.z == pytest.approx(1.1)
    s.key("k")
    assert (s.twist().linear.x, s.twist().angular.z) == (0.0, 0.0)


def test_keyboard_node_publishes_pressed_keys():
    ex = Executor()
    node = TeleopKeyboard(ex)
    got = []
    ex.add_listener(lambda topic, m, t: got.append(m.angular.z) if topic == "/cmd_vel" else None)
    node.press("j")
    ex.run(0.3)
    assert got and got[-1] == 1.0


def test_joystick_mapping_needs_the_deadman_button():
    j = JoyMapping()
    assert j.twist([0.0, -1.0], [0]).linear.x == 0.0
    t = j.twist([-0.5, -1.0], [1])
    assert t.linear.x == pytest.approx(0.5) and t.angular.z == pytest.approx(0.25)


def test_route_file_errors(tmp_path):
    f = tmp_path / "r.yaml"
    f.write_text("segments:\n  - {linear: 0.2}\n")
    with pytest.raises(DriverError, match=r"segments\[0\]"):
        load_route(f)
    f.write_text("speed: 1\n")
    with pytest.raises(DriverError, match="segments"):
        load_route(f)


def test_route_follower_drives_the_simulated_robot_to_its_waypoint():
    from navlab.sim import launch_sim

    ex = Executor(seed=0)
    gz = launch_sim(ex, world="room")
    route = RouteFollower(
        ex,
        parameters={
            "segments": [{"linear": 0.0, "angular": 0.5, "duration": 1.0}],
            "waypoints": [[1.0, 0.5]],
            "base_frame": "chassis",
        },
    )
    assert ex.run_until(lambda: route.done, timeout=30.0)
    x, y, _ = gz.sim.base_pose2d()
    assert abs(x - 1.0) < 0.12 and abs(y - 0.5) < 0.12
