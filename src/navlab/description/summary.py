"""Plain-data summary of a robot, for ``navlab check robot`` (text or ``--json``); a world's is
``navlab.world.summary``."""

from __future__ import annotations

from dataclasses import asdict
from typing import Any

from navlab.description.model import RobotModel, Shape


def shape_summary(s: Shape) -> dict[str, Any]:
    """Kind, pose (xyz m, rpy rad) and size or mesh file of a collision shape."""
    g = s.geometry
    out: dict[str, Any] = {"kind": g.kind, "xyz": list(s.origin.xyz), "rpy": list(s.origin.rpy)}
    if g.kind == "mesh":
        out.update(mesh=str(g.mesh_path), scale=list(g.mesh_scale))
        if g.mesh_source and g.mesh_source != g.mesh_path:
            out["source"] = str(g.mesh_source)
        if g.convex is not None:
            out["convex"] = g.convex
    else:
        out["size"] = list(g.size)
    return out


def robot_summary(robot: RobotModel) -> dict[str, Any]:
    """Links (mass, shapes), joints, plugins, sensors and warnings of a robot."""
    links = {}
    for name, link in robot.links.items():
        links[name] = {
            "mass": link.inertial.mass if link.inertial else None,
            "collisions": [shape_summary(s) for s in link.collisions],
            "visuals": len(link.visuals),
            **({"mu1": link.mu1, "mu2": link.mu2} if link.mu1 is not None else {}),
        }
    return {
        "kind": "robot",
        "name": robot.name,
        "source": str(robot.source) if robot.source else None,
        "root_link": robot.root_link,
        "total_mass": sum(link.inertial.mass for link in robot.links.values() if link.inertial),
        "links": links,
        "joints": [
            {
                "name": j.name,
                "type": j.type,
                "parent": j.parent,
                "child": j.child,
                "xyz": [round(v, 9) for v in j.origin.xyz],
                "rpy": [round(v, 9) for v in j.origin.rpy],
                "axis": [round(v, 9) for v in j.axis],
            }
            for j in robot.joints
        ],
        "diff_drive": asdict(robot.diff_drive) if robot.diff_drive else None,
        "ros_control": asdict(robot.ros_control) if robot.ros_control else None,
        "lidars": [{**asdict(lidar), "origin": asdict(lidar.origin)} for lidar in robot.lidars],
        "imus": [{**asdict(imu), "origin": asdict(imu.origin)} for imu in robot.imus],
        "sensors": [{"sensor": type(c).__name__, **asdict(c)} for c in robot.sensors.all()],
        "warnings": list(robot.warnings),
    }


def format_robot(s: dict[str, Any]) -> str:
    """Human-readable text of :func:`robot_summary`."""
    lines = [
        f"robot {s['name']}  ({s['source']})",
        f"  root link {s['root_link']}, total mass {s['total_mass']:.3f} kg",
        f"  links ({len(s['links'])}):",
    ]
    for name, link in s["links"].items():
        mass = "no inertial" if link["mass"] is None else f"{link['mass']:g} kg"
        shapes = ", ".join(f"{c['kind']} {c.get('size', c.get('scale'))}" for c in link["collisions"]) or "-"
        fr = f", mu1 {link['mu1']:g}" if "mu1" in link else ""
        lines.append(f"    {name:<22} {mass:<12} collision: {shapes}{fr}")
    lines.append(f"  joints ({len(s['joints'])}):")
    for j in s["joints"]:
        lines.append(
            f"    {j['name']:<22} {j['type']:<10} {j['parent']} -> {j['child']}  xyz {j['xyz']} axis {j['axis']}"
        )
    dd = s["diff_drive"]
    if dd:
        left = "+".join([dd["left_joint"], *dd["extra_left_joints"]])
        right = "+".join([dd["right_joint"], *dd["extra_right_joints"]])
        lines.append(
            f"  diff drive ({dd['drive']}): joints {left}/{right}, separation "
            f"{dd['wheel_separation']} m, diameter {dd['wheel_diameter']} m, torque {dd['max_torque']} N m, "
            f"{dd['update_rate']} Hz, {dd['command_topic']} -> {dd['odometry_topic']} "
            f"({dd['odometry_frame']} -> {dd['robot_base_frame']}, source {dd['odometry_source']})"
        )
    elif s.get("ros_control"):
        lines.append(
            f"  diff drive: from the ros_control YAML (gazebo_ros_control, namespace {s['ros_control']['namespace']})"
        )
    else:
        lines.append("  diff drive: none")
    for lidar in s["lidars"]:
        lines.append(
            f"  lidar {lidar['name']} on {lidar['link']}: {lidar['samples']} samples "
            f"{lidar['min_angle']:.4g}..{lidar['max_angle']:.4g} rad, {lidar['range_min']}-"
            f"{lidar['range_max']} m, noise {lidar['noise_stddev']} m, {lidar['update_rate']} Hz -> "
            f"{lidar['topic']} [{lidar['frame_id']}]"
        )
    for imu in s["imus"]:
        lines.append(
            f"  imu {imu['name']} on {imu['link']}: {imu['update_rate']} Hz -> {imu['topic']} [{imu['frame_id']}]"
        )
    for c in s.get("sensors", []):
        lines.append(f"  {sensor_line(c)}")
    lines += [f"  warning: {w}" for w in s["warnings"]]
    lines.append("  OK" if not s["warnings"] else f"  OK with {len(s['warnings'])} warning(s)")
    return "\n".join(lines)


def sensor_line(c: dict[str, Any]) -> str:
    """One line for a camera, depth camera, 3D lidar, range sensor or bumper of :func:`robot_summary`."""
    sensor, at = c["sensor"], f"{c['name']} on {c['link']}"
    if sensor == "CameraConfig":
        cam = c["camera"]
        what = (
            f"{cam['width']} x {cam['height']}, hfov {cam['horizontal_fov']:.4g} rad, clip {cam['near']}-"
            f"{cam['far']} m, {c['update_rate']} Hz"
        )
        if c["kind"] == "depth":
            return f"depth camera {at}: {what} -> {c['depth_image_topic']}, {c['point_cloud_topic']} [{c['frame_id']}]"
        return f"camera {at}: {what} -> {c['image_topic']} [{c['frame_id']}]"
    if sensor == "Lidar3dConfig":
        return (
            f"3D lidar {at}: {c['rings']} rings {c['vertical_min_angle']:.4g}..{c['vertical_max_angle']:.4g} rad x "
            f"{c['samples']} samples, {c['range_min']}-{c['range_max']} m, {c['update_rate']} Hz -> {c['topic']} "
            f"[{c['frame_id']}]"
        )
    if sensor == "RangeConfig":
        return (
            f"range ({c['radiation']}) {at}: fov {c['fov']} rad, {c['range_min']}-{c['range_max']} m, "
            f"{c['update_rate']} Hz -> {c['topic']} [{c['frame_id']}]"
        )
    return f"bumper {at}: collision {c['collision']}, {c['update_rate']} Hz -> {c['topic']} [{c['frame_id']}]"
