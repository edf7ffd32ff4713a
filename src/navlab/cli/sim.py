"""``navlab sim`` (run the simulator and its plugins) and ``navlab render`` (a picture of a world)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from navlab.cli.options import (
    add_pose_arguments,
    add_resource_path_arguments,
    add_run_options,
    add_set_argument,
    apply_resource_paths,
    out_file,
    parse_sets,
    seconds_or_zero,
    start_pose,
)
from navlab.cli.runs import ros_bridge, stop_signals, viewing

_SPAWN_HELP = (
    "spawn a model, KIND:key=value,... with KIND box|cylinder|sphere|sdf, e.g. 'box:name=crate,x=2,y=1,size=0.5', "
    "'cylinder:x=1,radius=0.2,length=1', 'sdf:file=model.sdf,x=1'; keys name x y z yaw static mass size "
    "sx sy sz radius length file, and t=SECONDS to spawn while running (repeatable)"
)


def _add_common(p: argparse.ArgumentParser) -> None:
    from navlab.resources import shipped

    p.add_argument(
        "--world",
        default="room",
        help=f"shipped world ({', '.join(shipped('world'))}) or a .world file (default: room)",
    )
    p.add_argument(
        "--robot",
        default="mybot",
        help=f"shipped robot ({', '.join(shipped('robot'))}), a .xacro/.urdf file or a "
        "package://pkg/urdf/robot.xacro URI (default: mybot)",
    )
    add_pose_arguments(p)
    add_resource_path_arguments(p)
    p.add_argument("--spawn", action="append", default=[], metavar="SPEC", help=_SPAWN_HELP)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``sim`` and ``render`` verbs."""
    p = sub.add_parser(
        "sim",
        help="run the MuJoCo simulation of a robot in a world with Gazebo's plugins",
        description="Simulate a robot (xacro/URDF with <gazebo> plugin tags) in a Gazebo world: physics, "
        "diff_drive (cmd_vel -> odom + tf), lidar, imu, joint_states and /ground_truth/odom, in "
        "simulated time. Prints a summary; --record leaves a rosbag2 (MCAP) of every topic. As ROS 1's "
        "gazebo_ros_diff_drive, the last cmd_vel holds until a new one arrives; --set cmd_timeout=0.5 adds "
        "navlab's watchdog (stop the wheels 0.5 s after the last command; default 0 = off).",
    )
    _add_common(p)
    p.add_argument(
        "--duration",
        type=seconds_or_zero,
        default=10.0,
        help="simulated seconds to run (default 10; 0: load the world and robot, step nothing)",
    )
    p.add_argument(
        "--timestep",
        type=float,
        default=0.0,
        help="physics step in s, 0.0005-0.002 (default 0.002, or the world's max_step_size if larger)",
    )
    p.add_argument(
        "--cmd-vel",
        default=None,
        metavar="V,W",
        help="publish this constant cmd_vel (m/s, rad/s) at 10 Hz, e.g. 0.3,0.2",
    )
    add_set_argument(p, "gazebo", "ground_truth_rate=100")
    add_run_options(p, seed=0, rate=None, record=True, quiet=True, json=True, view=True, ros=True)
    p.set_defaults(func=_cmd_sim)

    r = sub.add_parser(
        "render",
        help="render a PNG of a robot in its world (MuJoCo offscreen, MUJOCO_GL=egl)",
        description="Render the world with the robot placed at --x/--y/--yaw, from above at an angle like "
        "the paper's Figs. 4 and 5. Spawned models (--spawn) are drawn too.",
    )
    _add_common(r)
    r.add_argument(
        "--out",
        default=".",
        metavar="DIR",
        help="folder for DIR/world.png (default: the current folder; a FILE.png is deprecated but still "
        "works this release)",
    )
    r.add_argument("--width", type=int, default=960, help="image width in pixels (default 960)")
    r.add_argument("--height", type=int, default=720, help="image height in pixels (default 720)")
    r.add_argument("--azimuth", type=float, default=135.0, help="camera azimuth in degrees (default 135)")
    r.add_argument("--elevation", type=float, default=-40.0, help="camera elevation in degrees (default -40)")
    r.add_argument("--distance", type=float, default=None, help="camera distance in m (default: frame the world)")
    r.add_argument("--no-robot", action="store_true", help="render the world alone")
    r.set_defaults(func=_cmd_render)


def _parse_cmd_vel(text: str | None) -> tuple[float, float] | None:
    from navlab.sim import SimError

    if text is None:
        return None
    try:
        v, w = (float(x) for x in text.split(","))
    except ValueError:
        raise SimError(f"--cmd-vel {text!r}: expected two numbers V,W (m/s, rad/s)") from None
    return v, w


def _cmd_sim(args: argparse.Namespace) -> int:
    from navlab import msgs
    from navlab.core import Node
    from navlab.experiments import start_run
    from navlab.sim import parse_spawn_spec

    apply_resource_paths(args)
    cmd_vel = _parse_cmd_vel(args.cmd_vel)
    spawns = [parse_spawn_spec(s, default_name=f"spawned_{i}") for i, s in enumerate(args.spawn)]
    run = start_run(
        "sim",
        world=args.world,
        robot=args.robot,
        pose=start_pose(args),
        seed=args.seed,
        rate=args.rate if args.rate is not None else (1.0 if args.ros else 0.0),  # ROS peers: real time
        timestep=args.timestep,
        overrides={"gazebo": parse_sets(args.set)},
    )
    ex, gazebo = run.executor, run.gazebo
    helper = Node(ex, name="sim_cli")
    for model, t in spawns:
        if t <= 0:
            gazebo.spawn(model)
        else:
            _one_shot(helper, t, lambda model=model: gazebo.spawn(model))
    counts: dict[str, int] = {}
    last: dict[str, Any] = {}

    def listen(topic: str, msg: Any, _t: int) -> None:
        counts[topic] = counts.get(topic, 0) + 1
        last[topic] = msg

    ex.add_listener(listen)
    if cmd_vel is not None:
        pub = helper.create_publisher(msgs.Twist, "cmd_vel", 10)
        helper.create_timer(0.1, lambda: pub.publish(msgs.twist(*cmd_vel)))
        pub.publish(msgs.twist(*cmd_vel))
    start = gazebo.sim.base_pose2d()
    # Ctrl-C (or SIGTERM, also as a background job) ends the run as --duration would: the summary, the recording
    with stop_signals() as stop, viewing(args, ex), ros_bridge(args.ros, ex, ex.nodes):
        stop.graceful(ex, "stopping the simulation (Ctrl-C again: quit at once)")
        run.run(args.duration, record=args.record, quiet=args.quiet, desc="sim")
    bag = run.bag
    end = gazebo.sim.base_pose2d()
    summary: dict[str, Any] = {
        "world": gazebo.sim.world.name,
        "robot": gazebo.sim.robot.name if gazebo.sim.robot else None,
        **run.figures(),
        "timestep_s": gazebo.sim.timestep,
        "start_pose": [round(v, 4) for v in start],
        "true_pose": [round(v, 4) for v in end],
        "distance_m": round(math.dist(start[:2], end[:2]), 4),
        "models": gazebo.sim.model_names(),
        "messages": dict(sorted(counts.items())),
        "record": str(bag) if bag else None,
    }
    odom = last.get("/odom")
    if odom is not None:
        summary["odom_pose"] = [round(v, 4) for v in msgs.pose2d(odom.pose.pose)]
    if args.json:
        print(json.dumps(summary))
    else:
        for key, value in summary.items():
            print(f"{key}: {value}")
    return 0


def _one_shot(node: Any, t: float, fn: Any) -> None:
    """Call ``fn`` once at simulated time ``t`` (s)."""
    holder: dict[str, Any] = {}

    def fire() -> None:
        holder["timer"].cancel()
        fn()

    holder["timer"] = node.create_timer(t, fire)


def _cmd_render(args: argparse.Namespace) -> int:
    from navlab.description import load_robot_named
    from navlab.sim import Simulation, check_start_pose, parse_spawn_spec, render_image, save_png
    from navlab.world import load_world

    apply_resource_paths(args)
    world = load_world(args.world)
    robot = None if args.no_robot else load_robot_named(args.robot)
    if robot is not None:
        check_start_pose(robot, world, (args.x, args.y, args.yaw))
    sim = Simulation(robot, world, robot_pose=(args.x, args.y, args.yaw), visuals=True)
    for i, spec in enumerate(args.spawn):
        sim.spawn(parse_spawn_spec(spec, default_name=f"spawned_{i}")[0])
    sim.advance_to(200_000_000)  # let the robot and dynamic models settle for 0.2 s
    image = render_image(
        sim,
        width=args.width,
        height=args.height,
        azimuth=args.azimuth,
        elevation=args.elevation,
        distance=args.distance,
    )
    path = save_png(image, out_file(args.out, "world.png", old_suffixes=(".png",)))
    print(f"wrote {path} ({args.width}x{args.height})", file=sys.stderr)
    return 0
