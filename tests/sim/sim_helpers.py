"""Robots and worlds built in Python (the paper's mybot per its Table I, a walled room) for sim tests.

A plain module (not conftest) so test files import it by a name no other test folder uses."""

from __future__ import annotations

import math

from navlab.description.model import (
    DiffDriveConfig,
    Geometry,
    Inertial,
    Joint,
    LidarConfig,
    Link,
    Origin,
    RobotModel,
    Shape,
)
from navlab.world import ModelSpec, WorldModel


def _cyl_inertial(mass: float, r: float, h: float, axis: str = "z") -> Inertial:
    """Solid cylinder about its centre, its axis along ``axis`` (z: the chassis; y: a wheel on its axle)."""
    side, along = mass * (3 * r * r + h * h) / 12.0, mass * r * r / 2.0
    if axis == "y":
        return Inertial(mass=mass, ixx=side, iyy=along, izz=side)
    return Inertial(mass=mass, ixx=side, iyy=side, izz=along)


def make_mybot(
    *, torque: float = 15.0, caster_mu: float | None = 0.0, odometry_source: str = "encoder", noise: float = 0.01
) -> RobotModel:
    """The paper's robot: cylinder base r 0.2 m, wheels r 0.08 m 0.4 m apart, two caster spheres, a lidar."""
    wheel_rpy = (math.pi / 2, 0.0, 0.0)
    links = {
        "chassis": Link(
            "chassis",
            inertial=_cyl_inertial(10.0, 0.2, 0.05),
            collisions=[
                Shape(Geometry("cylinder", (0.2, 0.05))),
                Shape(Geometry("sphere", (0.04,)), Origin((0.15, 0.0, -0.04))),
                Shape(Geometry("sphere", (0.04,)), Origin((-0.15, 0.0, -0.04))),
            ],
            mu1=caster_mu,
            mu2=caster_mu,
        ),
        "left_wheel": Link(
            "left_wheel",
            inertial=_cyl_inertial(2.0, 0.08, 0.03, axis="y"),
            collisions=[Shape(Geometry("cylinder", (0.08, 0.03)), Origin(rpy=wheel_rpy))],
        ),
        "right_wheel": Link(
            "right_wheel",
            inertial=_cyl_inertial(2.0, 0.08, 0.03, axis="y"),
            collisions=[Shape(Geometry("cylinder", (0.08, 0.03)), Origin(rpy=wheel_rpy))],
        ),
        "laser": Link("laser", collisions=[Shape(Geometry("box", (0.05, 0.05, 0.04)))]),
    }
    joints = [
        Joint("left_wheel_hinge", "continuous", "chassis", "left_wheel", Origin((0.0, 0.2, 0.0)), (0, 1, 0)),
        Joint("right_wheel_hinge", "continuous", "chassis", "right_wheel", Origin((0.0, -0.2, 0.0)), (0, 1, 0)),
        Joint("laser_joint", "fixed", "chassis", "laser", Origin((0.0, 0.0, 0.06))),
    ]
    return RobotModel(
        name="mybot",
        links=links,
        joints=joints,
        root_link="chassis",
        diff_drive=DiffDriveConfig(
            update_rate=30.0,
            wheel_separation=0.4,
            wheel_diameter=0.16,
            max_torque=torque,
            robot_base_frame="chassis",
            odometry_source=odometry_source,  # type: ignore[arg-type]
        ),
        lidars=[
            LidarConfig(
                link="laser",
                update_rate=40.0,
                samples=720,
                range_min=0.2,
                range_max=25.0,
                noise_stddev=noise,
                topic="/mybot/laser/scan",
                frame_id="laser",
            )
        ],
    )


def box_model(name: str, x: float, y: float, size: tuple[float, float, float], *, static: bool = True) -> ModelSpec:
    """A box model resting on the floor at (x, y)."""
    link = Link("link", collisions=[Shape(Geometry("box", size))])
    return ModelSpec(name, pose=(x, y, size[2] / 2, 0.0, 0.0, 0.0), static=static, links=[link])


def make_room(length: float = 10.0, width: float = 8.0, *, models: list[ModelSpec] | None = None) -> WorldModel:
    """A walled room centred on the origin (inner size length × width m, walls 0.2 m thick, 1 m high)."""
    t, h = 0.2, 1.0
    walls = [
        box_model("wall_north", 0.0, width / 2 + t / 2, (length + 2 * t, t, h)),
        box_model("wall_south", 0.0, -width / 2 - t / 2, (length + 2 * t, t, h)),
        box_model("wall_east", length / 2 + t / 2, 0.0, (t, width, h)),
        box_model("wall_west", -length / 2 - t / 2, 0.0, (t, width, h)),
    ]
    return WorldModel("room", models=walls + list(models or []))
