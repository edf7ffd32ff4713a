"""Local controllers: TrajectoryPlannerROS / DWAPlannerROS (ROS 1) and the Nav2-style MPPI controller.

Hand-made costmaps (uint8 costmap_2d costs), pure kinematic closed loops (no physics): the robot's pose
integrates the commanded (v, w) every 50 ms.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import ndimage

from navlab.grid import COST_INSCRIBED, COST_LETHAL, Grid
from navlab.navigation import NavigationError
from navlab.navigation.controllers import DWAPlannerROS, TrajectoryPlannerROS
from navlab.navigation.controllers import mppi_critics as critics
from navlab.navigation.controllers import synthetic as syn
from navlab.navigation.controllers.common import OscillationFlags, cost_regulated_speeds, crop_plan
from navlab.navigation.controllers.mapgrid import distance_map
from navlab.navigation.controllers.mppi import MPPIController
from navlab.navigation.controllers.trajectory import InPlaceFlags
from navlab.plugins import load_plugin

RES = 0.05
DT = 0.05


def free_map(size: float = 4.0, origin: tuple[float, float, float] = (-2.0, -2.0, 0.0)) -> Grid:
    n = round(size / RES)
    return Grid(np.zeros((n, n), dtype=np.uint8), RES, origin, "odom")


def straight_plan(x0: float = 0.0, x1: float = 5.0, y: float = 0.0) -> np.ndarray:
    n = round((x1 - x0) / RES) + 1
    return np.column_stack([np.linspace(x0, x1, n), np.full(n, y), np.zeros(n)])


def with_disc(grid: Grid, centre: tuple[float, float], radius: float) -> Grid:
    """``grid`` with a round obstacle, inflated as costmap_2d does (robot radius 0.2 m)."""
    h, w = grid.data.shape
    mask = syn.disc_mask((h, w), RES, np.array([centre]), np.array([radius]), grid.origin[:2])
    return Grid(np.maximum(grid.data, syn.inflated(mask, RES)), RES, grid.origin, grid.frame_id)


def step(pose: tuple[float, float, float], cmd: tuple[float, float]) -> tuple[float, float, float]:
    x, y, th = pose
    return x + cmd[0] * math.cos(th) * DT, y + cmd[0] * math.sin(th) * DT, th + cmd[1] * DT


def drive(ctrl, world: Grid, mask: np.ndarray, start, plan: np.ndarray, steps: int = 1200) -> dict:
    """Closed loop on ``world`` with a 4 m rolling window; returns reached, time, clearance, mean speed."""
    ctrl.set_plan(plan)
    pose, vel = (start[0], start[1], start[2]), (0.0, 0.0)
    clearance = ndimage.distance_transform_edt(~mask) * RES
    least, speeds, k = math.inf, [], 0
    for k in range(steps):  # noqa: B007
        if ctrl.is_goal_reached(pose, vel):
            break
        vel = ctrl.compute_velocity(pose, vel, syn.window(world, pose[0], pose[1]))
        pose = step(pose, vel)
        i, j = world.world_to_cell(np.array([pose[:2]]))[0]
        least = min(least, clearance[j, i])
        speeds.append(vel[0])
    return {
        "reached": ctrl.is_goal_reached(pose, vel),
        "time": k * DT,
        "clearance": least,
        "speed": float(np.mean(speeds)),
        "pose": pose,
    }


@pytest.fixture(scope="module")
def clutter_world():
    """An 8 m room with 40 round obstacles (seeded), its costmap and a Dijkstra plan corner to corner."""
    start, goal = (0.8, 0.8), (7.2, 7.2)
    mask = syn.clutter(np.random.default_rng(3), count=40, keep_clear=(start, goal))
    world = Grid(syn.inflated(mask, RES), RES, (0.0, 0.0, 0.0), "odom")
    return world, mask, (*start, math.pi / 4), syn.grid_plan(world, start, goal)


# --- TrajectoryPlannerROS / DWAPlannerROS -----------------------------------------------------------


@pytest.mark.parametrize("cls, vmax", [(DWAPlannerROS, 0.55), (TrajectoryPlannerROS, 0.5)])
def test_straight_path_drives_forward_near_max_vel_x(cls, vmax):
    ctrl = cls()
    ctrl.set_plan(straight_plan())
    vel = (0.0, 0.0)
    for _ in range(20):  # accelerate (the command is fed back as the measured velocity)
        vel = ctrl.compute_velocity((0.0, 0.0, 0.0), vel, free_map())
    assert vel[0] == pytest.approx(vmax, abs=0.03)
    assert abs(vel[1]) < 0.05
    assert ctrl.valid
    lp = ctrl.local_plan
    assert lp.shape[1] == 3 and lp[-1, 0] > 0.4 and np.abs(lp[:, 1]).max() < 0.05


@pytest.mark.parametrize("cls", [DWAPlannerROS, TrajectoryPlannerROS])
def test_obstacle_ahead_is_passed_on_the_planned_detour(cls):
    # ROS's local planners follow the global plan around an obstacle (a plan through it leaves the local goal
    # unreachable: no valid rollout, and move_base replans)
    world = with_disc(free_map(8.0, (-1.0, -4.0, 0.0)), (2.0, 0.0), 0.15)  # 2 m ahead on the straight line
    blocked = world.data >= COST_LETHAL
    plan = syn.grid_plan(world, (0.0, 0.0), (4.0, 0.0))
    assert np.abs(plan[:, 1]).max() > 0.3  # the plan bends around it
    out = drive(cls(), world, blocked, (0.0, 0.0, 0.0), plan, steps=600)
    assert out["reached"]
    assert out["clearance"] >= 0.2 - RES  # the robot (r 0.2 m) never touched it (one cell of slack)


@pytest.mark.parametrize("cls", [DWAPlannerROS, TrajectoryPlannerROS])
def test_chosen_rollout_keeps_off_lethal_and_inscribed_cells(cls):
    world = with_disc(free_map(), (0.7, 0.05), 0.15)
    ctrl = cls()
    ctrl.set_plan(straight_plan())
    ctrl.compute_velocity((0.0, 0.0, 0.0), (0.3, 0.0), world)
    assert ctrl.valid and len(ctrl.local_plan)
    assert (world.value_at(ctrl.local_plan[:, :2], outside=255) < COST_INSCRIBED).all()
    # every sample whose rollout touches such a cell is rejected (cost < 0)
    hits = (
        (world.value_at(ctrl.trajectories[..., :2].reshape(-1, 2), outside=255) >= COST_INSCRIBED)
        .reshape(ctrl.trajectories.shape[:2])
        .any(axis=1)
    )
    assert hits.any()
    assert (ctrl.costs[hits] < 0).all()


def test_dwa_window_respects_acceleration_limits():
    ctrl = DWAPlannerROS({"acc_lim_x": 1.0, "acc_lim_theta": 2.0, "vx_samples": 6, "vth_samples": 11})
    ctrl.set_plan(straight_plan())
    ctrl.compute_velocity((0.0, 0.0, 0.0), (0.3, 0.2), free_map())
    v, w = ctrl.samples[:, 0], ctrl.samples[:, 1]
    period = 1.0 / 20.0
    assert v.min() >= 0.3 - 1.0 * period - 1e-9 and v.max() <= 0.3 + 1.0 * period + 1e-9
    assert w.min() >= 0.2 - 2.0 * period - 1e-9 and w.max() <= 0.2 + 2.0 * period + 1e-9
    assert len(np.unique(v)) == 6 and len(np.unique(w)) >= 10


@pytest.mark.parametrize("dwa, horizon", [(True, 0.05), (False, 1.0)])
def test_trajectory_planner_window_over_sim_period_or_sim_time(dwa, horizon):
    ctrl = TrajectoryPlannerROS({"dwa": dwa, "acc_lim_x": 0.2, "acc_lim_theta": 0.4, "min_vel_x": 0.0})
    ctrl.set_plan(straight_plan())
    ctrl.compute_velocity((0.0, 0.0, 0.0), (0.3, 0.0), free_map())
    forward = ctrl.samples[ctrl.samples[:, 0] > 0]
    assert forward[:, 0].max() == pytest.approx(0.3 + 0.2 * horizon)
    assert forward[:, 0].min() == pytest.approx(0.3 - 0.2 * horizon)
    assert np.abs(forward[:, 1]).max() == pytest.approx(min(1.0, 0.4 * horizon))


@pytest.mark.parametrize("cls", [DWAPlannerROS, TrajectoryPlannerROS])
def test_at_goal_position_stops_then_turns_in_place_to_goal_yaw(cls):
    ctrl = cls()
    plan = straight_plan(-1.0, 0.0)
    plan[-1, 2] = 1.2  # goal yaw
    ctrl.set_plan(plan)
    grid = free_map()
    cmd = ctrl.compute_velocity((0.02, 0.01, 0.0), (0.3, 0.0), grid)  # moving: brake within acc_lim_x
    assert cmd[0] == pytest.approx(0.3 - 2.5 / 20.0) and cmd[1] == 0.0
    pose, vel = (0.02, 0.01, 0.0), (0.0, 0.0)
    for _ in range(200):
        if ctrl.is_goal_reached(pose, vel):
            break
        vel = ctrl.compute_velocity(pose, vel, grid)
        assert vel[0] == 0.0 and vel[1] >= 0.0  # turns left, on the spot
        pose = step(pose, vel)
    assert ctrl.is_goal_reached(pose, (0.0, 0.0))
    assert abs(pose[2] - 1.2) <= ctrl.params.yaw_goal_tolerance
    assert pose[:2] == (0.02, 0.01)
    assert tuple(ctrl.compute_velocity(pose, (0.0, 0.0), grid)) == (0.0, 0.0)


def test_latch_xy_goal_tolerance_keeps_turning_after_drifting_out():
    plan = straight_plan(-1.0, 0.0)
    plan[-1, 2] = math.pi / 2
    for latch, expect_turn_only in ((True, True), (False, False)):
        ctrl = DWAPlannerROS({"latch_xy_goal_tolerance": latch})
        ctrl.set_plan(plan)
        ctrl.compute_velocity((0.05, 0.0, 0.0), (0.0, 0.0), free_map())  # inside xy tolerance: latches
        ctrl.set_plan(plan)  # the same plan again (move_base sends it every cycle) keeps the latch
        v, w = ctrl.compute_velocity((0.15, 0.0, 0.0), (0.0, 0.0), free_map())  # 0.15 m out
        assert (v == 0.0 and w > 0) is expect_turn_only


def test_plan_without_yaw_needs_only_xy_tolerance():
    ctrl = TrajectoryPlannerROS()
    ctrl.set_plan(straight_plan(-1.0, 0.0)[:, :2])
    assert ctrl.is_goal_reached((0.05, 0.0, 2.0), (0.0, 0.0))
    assert not ctrl.is_goal_reached((0.5, 0.0, 0.0), (0.0, 0.0))


def test_dwa_goal_needs_the_robot_stopped():
    ctrl = DWAPlannerROS()
    ctrl.set_plan(straight_plan(-1.0, 0.0))
    assert not ctrl.is_goal_reached((0.0, 0.0, 0.0), (0.3, 0.0))
    assert ctrl.is_goal_reached((0.0, 0.0, 0.0), (0.05, 0.0))


def test_costmap_rotated_origin_gives_the_same_commands():
    world = with_disc(free_map(), (0.8, 0.2), 0.15)
    yaw = 0.6
    c, s = math.cos(yaw), math.sin(yaw)
    rot = Grid(world.data, RES, (c * -2.0 - s * -2.0, s * -2.0 + c * -2.0, yaw), "odom")
    plan = straight_plan()
    plan_r = np.column_stack([c * plan[:, 0] - s * plan[:, 1], s * plan[:, 0] + c * plan[:, 1], plan[:, 2] + yaw])
    for cls in (DWAPlannerROS, TrajectoryPlannerROS):
        a, b = cls(), cls()
        a.set_plan(plan)
        b.set_plan(plan_r)
        cmd_a = a.compute_velocity((0.0, 0.0, 0.0), (0.3, 0.0), world)
        cmd_b = b.compute_velocity((0.0, 0.0, yaw), (0.3, 0.0), rot)
        assert tuple(cmd_a) == pytest.approx(tuple(cmd_b), abs=1e-9)
        lp = b.local_plan
        back = np.column_stack([c * lp[:, 0] + s * lp[:, 1], -s * lp[:, 0] + c * lp[:, 1]])
        assert back == pytest.approx(a.local_plan[:, :2], abs=1e-9)


def test_polygon_footprint_edges_are_checked():
    grid = free_map()
    grid.data[39:41, 36:44] = COST_LETHAL  # a thin wall 0.25 m to the robot's left, parallel to the path
    ctrl = DWAPlannerROS(footprint=[[0.3, 0.3], [0.3, -0.3], [-0.3, -0.3], [-0.3, 0.3]])
    ctrl.set_plan(np.column_stack([np.linspace(0, 2, 41), np.full(41, -0.25), np.zeros(41)]))
    ctrl.compute_velocity((0.0, -0.25, 0.0), (0.2, 0.0), grid)
    assert not ctrl.valid  # every rollout puts the square's left edge on the wall
    circle = DWAPlannerROS()
    circle.set_plan(np.column_stack([np.linspace(0, 2, 41), np.full(41, -0.25), np.zeros(41)]))
    circle.compute_velocity((0.0, -0.25, 0.0), (0.2, 0.0), grid)
    assert circle.valid  # the centre cell is free


@pytest.mark.parametrize("cls", [DWAPlannerROS, TrajectoryPlannerROS])
def test_robot_radius_is_checked_as_costmap_2d_16_gon(cls):
    grid = free_map()
    grid.data[39:41, 36:44] = COST_LETHAL  # a thin wall whose near face is 0.2 m to the robot's left
    plan = np.column_stack([np.linspace(0, 2, 41), np.full(41, -0.25), np.zeros(41)])
    forward = {}
    for radius in (None, 0.15, 0.21):
        ctrl = cls(robot_radius=radius)
        ctrl.set_plan(plan)
        forward[radius] = ctrl.compute_velocity((0.0, -0.25, 0.0), (0.2, 0.0), grid)[0] > 0
    assert cls(robot_radius=0.21).footprint.shape == (16, 2)
    # a point robot, and a 0.15 m one, drive on; a 0.21 m one overlaps the wall: DWA stops, TrajectoryPlanner
    # backs off (its escape)
    assert forward == {None: True, 0.15: True, 0.21: False}


def test_move_base_controller_frequency_sets_sim_period_unless_the_planner_section_does():
    ctrl = TrajectoryPlannerROS({"acc_lim_x": 0.2, "min_vel_x": 0.0}, controller_frequency=10.0)
    ctrl.set_plan(straight_plan())
    ctrl.compute_velocity((0.0, 0.0, 0.0), (0.3, 0.0), free_map())
    assert ctrl.samples[ctrl.samples[:, 0] > 0, 0].max() == pytest.approx(0.3 + 0.2 / 10.0)
    assert DWAPlannerROS({"controller_frequency": 5.0}, controller_frequency=10.0).params.sim_period == 0.2


def test_plan_is_cropped_where_it_leaves_half_the_local_window():
    out_and_back = np.vstack([straight_plan(-3.0, 3.0), straight_plan(-3.0, 3.0, y=0.5)[::-1]])
    crop = crop_plan(out_and_back, 0.0, 0.0, 2.0)
    assert crop[0, 0] == pytest.approx(-2.0) and crop[-1, 0] == pytest.approx(2.05)  # ROS keeps the first beyond
    assert (crop[:, 1] == 0.0).all()  # not the way back, although it passes the window again
    assert len(crop_plan(out_and_back, 0.0, 5.0, 2.0)) == 0


def test_trajectory_planner_keeps_turning_in_place_the_same_way():
    flags = InPlaceFlags(0.05)
    flags.update((0.0, 0.0, 0.0), 0.0, -0.5)
    assert list(flags.allowed(np.array([0.5, -0.5]))) == [True, True]
    flags.update((0.0, 0.0, -0.1), 0.0, -0.5)  # right twice: left turns are no longer tried
    assert list(flags.allowed(np.array([0.5, -0.5]))) == [False, True]
    flags.update((0.06, 0.0, -0.1), 0.2, 0.0)  # driven away from where it turned
    assert list(flags.allowed(np.array([0.5, -0.5]))) == [True, True]


def test_closed_loop_dwa_reaches_goal_in_clutter(clutter_world):
    world, mask, start, plan = clutter_world
    out = drive(DWAPlannerROS(), world, mask, start, plan)
    assert out["reached"], out
    assert out["clearance"] >= 0.2 - RES
    assert out["speed"] > 0.35


def test_mapgrid_distances_go_around_obstacles():
    cost = np.zeros((10, 10), dtype=np.uint8)
    cost[0:8, 5] = COST_INSCRIBED  # a wall with a gap at the top (rows 8, 9)
    d = distance_map(cost, np.array([[0, 0]]))
    assert d[0, 4] == 4  # 4-connected steps
    assert d[0, 5] == cost.size  # an obstacle next to the wave reads the obstacle value
    assert d[0, 6] == 4 + 8 + 1 + 8 + 1  # up to the gap, across, down
    cost[8:, 5] = COST_LETHAL
    assert distance_map(cost, np.array([[0, 0]]))[0, 6] == cost.size + 1  # unreachable


def test_oscillation_flags_forbid_turning_back_until_moved():
    flags = OscillationFlags(0.05)
    flags.update((0.0, 0.0, 0.0), 0.0, 0.5, 0.1)  # turn left in place
    flags.update((0.0, 0.0, 0.1), 0.0, -0.5, 0.1)  # then right: oscillation
    assert list(flags.allowed(np.zeros(2), np.array([0.5, -0.5]))) == [False, True]
    flags.update((0.03, 0.0, 0.1), 0.2, -0.2, 0.1)
    assert not flags.allowed(np.zeros(1), np.array([0.5]))[0]
    flags.update((0.06, 0.0, 0.1), 0.2, -0.2, 0.1)  # moved more than oscillation_reset_dist
    assert flags.allowed(np.zeros(1), np.array([0.5]))[0]


# --- parameters --------------------------------------------------------------------------------------


def test_both_ros1_spellings_are_read():
    assert TrajectoryPlannerROS({"pdist_scale": 0.7}).params.pdist_scale == 0.7
    assert TrajectoryPlannerROS({"path_distance_bias": 0.7, "goal_distance_bias": 0.9}).params.gdist_scale == 0.9
    assert TrajectoryPlannerROS({"backup_vel": -0.2}).params.escape_vel == -0.2
    tp = TrajectoryPlannerROS({"max_rotational_vel": 0.8}).params
    assert (tp.max_vel_theta, tp.min_vel_theta) == (0.8, -0.8)
    dwa = DWAPlannerROS(
        {
            "pdist_scale": 20.0,
            "gdist_scale": 10.0,
            "max_trans_vel": 0.4,
            "min_trans_vel": 0.05,
            "max_rot_vel": 1.5,
            "min_rot_vel": 0.3,
            "acc_lim_th": 2.0,
            "rot_stopped_vel": 0.05,
        }
    ).params
    assert (dwa.path_distance_bias, dwa.goal_distance_bias) == (20.0, 10.0)
    assert (dwa.max_vel_trans, dwa.min_vel_trans, dwa.max_vel_theta, dwa.min_vel_theta) == (0.4, 0.05, 1.5, 0.3)
    assert (dwa.acc_lim_theta, dwa.theta_stopped_vel) == (2.0, 0.05)
    assert DWAPlannerROS({"path_distance_bias": 20.0}).params.path_distance_bias == 20.0


def test_scoring_weights_change_the_choice():
    world = with_disc(free_map(), (1.0, 0.0), 0.1)
    picks = []
    for bias in (0.0, 200.0):  # a strong path bias keeps the robot on the (blocked) line longer
        ctrl = DWAPlannerROS({"path_distance_bias": bias, "vth_samples": 30})
        ctrl.set_plan(straight_plan())
        picks.append(tuple(ctrl.compute_velocity((0.0, 0.0, 0.0), (0.4, 0.0), world)))
    assert picks[0] != picks[1]


@pytest.mark.parametrize(
    "cls, key",
    [
        (DWAPlannerROS, "vx_samples"),
        (DWAPlannerROS, "vy_samples"),
        (DWAPlannerROS, "vth_samples"),
        (TrajectoryPlannerROS, "vx_samples"),
        (TrajectoryPlannerROS, "vtheta_samples"),
    ],
)
def test_sample_counts_below_one_warn_and_become_one_as_in_ros(cls, key, caplog):
    """dwa_local_planner and base_local_planner warn and sample one value (TurtleBot3's files set vy_samples: 0)."""
    with caplog.at_level("WARNING", logger="navlab.navigation"):
        ctrl = cls({key: 0})
    assert getattr(ctrl.params, key) == 1
    (msg,) = [r.getMessage() for r in caplog.records]
    assert f"{key} is 0" in msg and "set to 1" in msg


@pytest.mark.parametrize(
    "cls, params, words",
    [
        (
            DWAPlannerROS,
            {"max_vel_x": 0.5, "max_vel_trans": 0.5, "path_distance_bais": 1.0},
            ["path_distance_bais", "did you mean", "path_distance_bias"],
        ),
        (TrajectoryPlannerROS, {"pdist_scal": 1.0}, ["pdist_scal", "did you mean", "pdist_scale"]),
        (DWAPlannerROS, {"min_vel_x": 0.6}, ["min_vel_x", "got 0.6", "max_vel_x"]),
        (TrajectoryPlannerROS, {"min_vel_theta": 2.0}, ["min_vel_theta", "got 2.0", "max_vel_theta"]),
        (TrajectoryPlannerROS, {"sim_time": 0.0}, ["sim_time", "got 0.0", "> 0"]),
        (TrajectoryPlannerROS, {"escape_vel": 0.1}, ["escape_vel", "got 0.1", "<= 0"]),
        (DWAPlannerROS, {"xy_goal_tolerance": -0.1}, ["xy_goal_tolerance", "got -0.1", ">= 0"]),
        (DWAPlannerROS, {"max_rot_vel": 1.0, "max_vel_theta": 2.0}, ["max_rot_vel", "max_vel_theta", "give one"]),
    ],
)
def test_bad_parameters_get_a_one_line_error(cls, params, words):
    with pytest.raises(NavigationError) as err:
        cls(params)
    msg = str(err.value)
    assert "\n" not in msg
    for word in words:
        assert word in msg


def test_registered_under_ros_names():
    for name, cls in (
        ("base_local_planner/TrajectoryPlannerROS", TrajectoryPlannerROS),
        ("dwa_local_planner/DWAPlannerROS", DWAPlannerROS),
        ("nav2_mppi_controller::MPPIController", MPPIController),
    ):
        assert load_plugin("controller", name) is cls
    assert issubclass(load_plugin("controller", "nav2_dwb_controller/DWBLocalPlanner"), DWAPlannerROS)


# --- MPPI --------------------------------------------------------------------------------------------


def test_mppi_same_seed_same_commands():
    world = with_disc(free_map(), (1.2, 0.1), 0.15)

    def run(seed: int) -> list[tuple[float, float]]:
        ctrl = MPPIController(rng=np.random.default_rng(seed))
        ctrl.set_plan(straight_plan())
        pose, vel, out = (0.0, 0.0, 0.0), (0.0, 0.0), []
        for _ in range(5):
            vel = ctrl.compute_velocity(pose, vel, world)
            pose = step(pose, vel)
            out.append(vel)
        return out

    assert run(7) == run(7)
    assert run(7) != run(8)


def test_mppi_steers_around_an_obstacle_on_the_path():
    world = with_disc(free_map(8.0, (-1.0, -4.0, 0.0)), (1.5, 0.0), 0.2)
    blocked = world.data >= COST_LETHAL
    out = drive(
        MPPIController(rng=np.random.default_rng(0)),
        world,
        blocked,
        (0.0, 0.0, 0.0),
        straight_plan(0.0, 3.5),
        steps=400,
    )
    assert out["reached"], out
    assert out["clearance"] >= 0.2 - RES


@pytest.mark.parametrize("vx_max", [0.5, 0.7])
def test_mppi_reaches_goal_in_clutter_at_speed(clutter_world, vx_max):
    world, mask, start, plan = clutter_world
    out = drive(MPPIController({"vx_max": vx_max}, rng=np.random.default_rng(0)), world, mask, start, plan)
    assert out["reached"], out
    assert out["clearance"] >= 0.2 - RES
    assert out["speed"] > 0.6 * vx_max


def test_mppi_local_plan_is_the_optimal_rollout():
    ctrl = MPPIController(rng=np.random.default_rng(0))
    ctrl.set_plan(straight_plan())
    pose, measured, vel = (0.0, 0.1, 0.2), (0.0, 0.0), (0.0, 0.0)
    for _ in range(10):
        measured, vel = vel, ctrl.compute_velocity(pose, vel, free_map())
    lp = ctrl.local_plan
    assert lp.shape == (ctrl.params.time_steps + 1, 3)
    assert lp[0] == pytest.approx(pose)
    assert lp[-1, 0] > 0.5 and abs(lp[-1, 1]) < 0.1  # ahead, back on the path
    # it is the optimal sequence rolled out: first step at the measured velocity, then the controls
    x, y, th = pose
    assert vel == pytest.approx(tuple(ctrl.sequence[0]))
    v_w = np.vstack([measured, ctrl.sequence[:-1]])
    for k, (v, w) in enumerate(v_w):
        x, y, th = x + v * math.cos(th) * DT, y + v * math.sin(th) * DT, th + w * DT
        assert lp[k + 1] == pytest.approx((x, y, th), abs=1e-9)


def test_mppi_cost_critic_scores_collisions_far_above_clearance():
    t_n = 10
    xs = np.tile(np.linspace(0.1, 1.0, t_n), (3, 1))
    cost = np.zeros((3, t_n), dtype=np.uint8)
    cost[1, 5] = 100  # passes through inflation
    cost[2, 5] = COST_LETHAL  # collides
    batch = critics.Batch(
        xs,
        np.zeros_like(xs),
        np.zeros_like(xs),
        np.full_like(xs, 0.3),
        np.zeros_like(xs),
        cost,
        xs,
        (0.0, 0.0, 0.0),
        np.zeros((0, 2)),
        (5.0, 0.0, None),
        5.0,
        0.05,
        (-0.35, 0.5),
        np.zeros((4, 4), dtype=np.uint8),
        RES,
    )
    out = critics.cost(critics.CostCritic(trajectory_point_step=1), batch)
    assert out[0] == 0.0 < out[1] < 1.0 < 100.0 < out[2]
    near = critics.goal(critics.GoalCritic(), batch)
    assert near is None  # 5 m from the goal: beyond threshold_to_consider


FAST = {"vx_max": 2.0, "vx_std": 0.4, "time_steps": 40}  # the Jackal's clutter settings
REGULATED = {
    **FAST,
    "use_cost_regulated_linear_velocity_scaling": True,
    "cost_scaling_dist": 0.6,
    "inflation_cost_scaling_factor": 10.0,  # syn.inflated's
}


def test_mppi_cost_regulated_speed_is_rpps_law():
    v = cost_regulated_speeds(2.0, 0.6, 1.0, 10.0, 0.2, 0.25)
    assert v[0] == v[255] == 2.0  # free and unknown cells do not slow the robot
    # a cost stands for the distance from the robot's centre to the obstacle that drew it
    d = 0.2 - math.log(100 / 252) / 10.0
    assert v[100] == pytest.approx(2.0 * d / 0.6)
    assert v[COST_LETHAL] == pytest.approx(2.0 * 0.2 / 0.6)  # as close as a centre can be: one inscribed radius
    assert np.all(np.diff(v[1:255]) <= 0)  # the higher the cost, the slower
    assert cost_regulated_speeds(2.0, 0.6, 0.1, 10.0, 0.2, 0.25)[COST_LETHAL] == 0.25  # never under min speed


def test_mppi_cost_regulation_slows_through_a_gap_and_not_on_open_ground():
    def commands(params, world, steps):
        ctrl = MPPIController(params, rng=np.random.default_rng(3))
        ctrl.set_plan(straight_plan(0.0, 6.0))
        pose, vel, out = (0.0, 0.0, 0.0), (0.0, 0.0), []
        for _ in range(steps):
            vel = ctrl.compute_velocity(pose, vel, syn.window(world, pose[0], pose[1]))
            pose = step(pose, vel)
            out.append((pose[0], vel[0]))
        return np.array(out)

    open_ground = free_map(10.0, (-2.0, -5.0, 0.0))
    off = commands(FAST, open_ground, 30)
    assert np.array_equal(commands(REGULATED, open_ground, 30), off)  # no cost, no change
    gap = with_disc(with_disc(open_ground, (2.5, 0.42), 0.075), (2.5, -0.42), 0.075)  # 0.69 m between them
    fast = commands(FAST, gap, 80)
    slow = commands(REGULATED, gap, 80)
    assert fast[:, 0].max() > 3.0 and slow[:, 0].max() > 3.0  # both went through
    in_gap = lambda run: run[np.abs(run[:, 0] - 2.5) < 0.1, 1].max()  # noqa: E731
    assert in_gap(slow) < 0.8 * in_gap(fast)


def test_mppi_parameters():
    p = MPPIController(
        {
            "vx_max": 0.6,
            "CostCritic": {"cost_weight": 2.0},
            "GoalCritic.threshold_to_consider": 1.0,
            "plugin": "nav2_mppi_controller::MPPIController",
        },
        rng=np.random.default_rng(0),
    ).params
    assert p.vx_max == 0.6 and p.critic("CostCritic").cost_weight == 2.0
    assert p.critic("GoalCritic").threshold_to_consider == 1.0
    assert p.critic("PathFollowCritic").offset_from_furthest == 6  # Nav2's default
    for params, words in (
        ({"CostCritc": {"cost_weight": 1.0}}, ["CostCritc", "did you mean", "CostCritic"]),
        ({"batch_sise": 10}, ["batch_sise", "did you mean", "batch_size"]),
        ({"CostCritic": {"cost_wieght": 1.0}}, ["cost_wieght", "did you mean", "cost_weight"]),
        ({"critics": ["CostCritic", "GoalCritc"]}, ["GoalCritc", "did you mean", "GoalCritic"]),
        ({"batch_size": 0}, ["batch_size", "got 0", ">= 1"]),
        ({"vx_min": 1.0}, ["vx_min", "got 1.0", "vx_max"]),
    ):
        with pytest.raises(NavigationError) as err:
            MPPIController(params, rng=np.random.default_rng(0))
        assert "\n" not in str(err.value)
        for word in words:
            assert word in str(err.value)
    with pytest.raises(NavigationError, match="rng"):
        MPPIController()


def test_a_rollouts_first_failure_in_time_decides_its_code() -> None:
    """``generateTrajectory`` checks poses in time order and returns at the first failure: -1 when the footprint
    is blocked (or off the map), -2 when the cell has no path to the goal. The code matters: only a -2 escape
    rollout keeps TrajectoryPlanner out of escape mode."""
    from navlab.navigation.controllers.rollout import rollout_scores

    res, n = 0.1, 5
    grid = np.zeros((n, n), dtype=np.uint8)
    grid[2, 3] = COST_LETHAL  # cell (i=3, j=2)
    path_dist = np.ones((n, n))
    goal_dist = np.ones((n, n))
    goal_dist[2, 1] = n * n  # cell (1, 2): cut off from the goal
    cells = {"no_path": (1, 2), "free": (2, 2), "lethal": (3, 2)}

    def score(*names: str) -> float:
        traj = np.array([[[(cells[k][0] + 0.5) * res, (cells[k][1] + 0.5) * res, 0.0] for k in names]])
        out = np.empty(1)
        zeros = np.zeros(traj.shape[:2])
        rollout_scores(
            grid,
            grid,
            path_dist,
            goal_dist,
            1.0 / res,
            traj,
            zeros,
            zeros,
            np.zeros(0),
            np.zeros(0),
            False,
            False,
            np.array([1.0, 0.6, 0.8, 0.01]),
            float(n * n),
            np.array([-1]),
            out,
        )
        return float(out[0])

    assert score("no_path", "free", "lethal") == -2.0  # no path first (the old kernel said -1: blocked anywhere)
    assert score("lethal", "free", "no_path") == -1.0
    assert score("free", "free") == pytest.approx(0.6 + 0.8)


def test_heading_scoring_scores_one_step_and_the_heading_to_the_visible_plan() -> None:
    """``heading_scoring: true`` (base_local_planner): every rollout has sim_time / sim_granularity steps, path
    and goal distances count at the step at heading_scoring_timestep only, and 0.3 x the angle between the
    heading there and the direction to the last plan point in clear sight is added."""
    ctrl = TrajectoryPlannerROS({"heading_scoring": True, "dwa": False, "vtheta_samples": 9})
    plan = straight_plan(0.0, 1.5)
    ctrl.set_plan(plan)
    ctrl.compute_velocity((0.0, 0.0, 0.5), (0.0, 0.0), free_map())
    assert set(ctrl._steps(ctrl.samples).tolist()) == {40}  # 1.0 s / 0.025 s
    k = ctrl._heading_step(40)
    assert k == 32  # the first step at >= 0.8 s
    spin = np.flatnonzero((ctrl.samples[:, 0] == 0) & (ctrl.costs >= 0))
    assert len(spin) >= 2
    # the in-place turns share their cell (same distances, no obstacle): they differ by 0.3 x the heading error
    # to the plan's last point (1.5, 0) at step k, taken from the rollouts themselves
    poses = ctrl.trajectories[spin, k]
    aim = np.arctan2(0.0 + 0.025 - poses[:, 1], 1.5 + 0.025 - poses[:, 0])  # the point's cell centre
    err = np.abs((poses[:, 2] - aim + np.pi) % (2 * np.pi) - np.pi)
    assert np.allclose(ctrl.costs[spin] - ctrl.costs[spin[0]], 0.3 * (err - err[0]), atol=1e-6)
    # a wall across the plan hides its end: the heading term aims at the last point still in sight
    walled = free_map()
    walled.data[:, round((1.0 + 2.0) / RES)] = COST_LETHAL  # the column of cells at x = 1.0 m
    ctrl2 = TrajectoryPlannerROS({"heading_scoring": True, "dwa": False, "vtheta_samples": 9})
    ctrl2.set_plan(plan)
    ctrl2.compute_velocity((0.0, 0.0, 0.5), (0.0, 0.0), walled)
    from navlab.navigation.controllers.rollout import heading_diffs

    local = ctrl2._frame.points_in(plan[:, :2])
    pose = ctrl2._frame.pose_in((0.0, 0.0, 0.0))
    seen = heading_diffs(walled.data, RES, local, np.array([pose]))[0]
    assert seen == pytest.approx(abs(math.atan2(0.025, 0.975)), abs=1e-9)  # (0.95, 0) is the last one in sight
