"""Nav2's collision monitor (``nav2_collision_monitor``): the last guard between the controller and the wheels.

Each velocity command (``cmd_vel_in``, m/s and rad/s in the base frame) is checked against the raw laser
points (base frame) and the configured polygons, in order; each polygon has an ``action_type``:

- ``stop``: ``min_points`` or more points inside -> the robot stops;
- ``slowdown``: -> the command scaled by ``slowdown_ratio``;
- ``limit``: -> linear speed capped at ``linear_limit`` (m/s), angular at ``angular_limit`` (rad/s);
- ``approach``: the polygon (the footprint) is moved along the command's arc in ``simulation_time_step`` s
  steps; if it would touch ``min_points`` points within ``time_before_collision`` s, the command is scaled so
  that the contact stays ``time_before_collision`` s away.

The most restrictive result wins (Nav2's rule). Polygons are ``type: polygon`` with ``points`` ([x, y, ...]
flat or [[x, y], ...]) or ``type: circle`` with ``radius``. The algorithm is :class:`CollisionMonitor` (pure);
:class:`CollisionMonitorNode` is the node (``cmd_vel_in`` + ``scan`` -> ``cmd_vel``). When no polygon is
configured, navlab builds Nav2's example set from ``footprint``: ``PolygonStop`` (footprint grown by
``stop_margin`` m), ``PolygonSlow`` (by ``slowdown_margin`` m, ``slowdown_ratio`` 0.3) and
``FootprintApproach`` (``time_before_collision`` 1.2 s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from navlab import msgs
from navlab.core import Executor, Node, TfError
from navlab.navigation.errors import NavigationError
from navlab.navigation.velocity_smoother import as_list

ACTIONS = ("stop", "slowdown", "limit", "approach", "none")


@dataclass
class Polygon:
    """One of the monitor's zones (Nav2's polygon parameters; base frame, m)."""

    name: str
    action_type: str
    points: np.ndarray | None = None  # (N, 2) polygon, or None for a circle
    radius: float = 0.0
    min_points: int = 4
    slowdown_ratio: float = 0.5
    linear_limit: float = 0.5
    angular_limit: float = 0.5
    time_before_collision: float = 2.0
    simulation_time_step: float = 0.1
    enabled: bool = True

    @property
    def reach(self) -> float:
        """How far (m) the zone reaches from the base frame's origin."""
        return self.radius if self.points is None else float(np.hypot(self.points[:, 0], self.points[:, 1]).max())

    def inside(self, pts: np.ndarray) -> np.ndarray:
        """Which of ``pts`` (M, 2; base frame) lie in the zone."""
        if self.points is None:
            return np.hypot(pts[:, 0], pts[:, 1]) <= self.radius
        return in_polygon(pts, self.points)


@dataclass
class Verdict:
    """The command after the monitor: (v, w) and which polygon acted (``""`` when none)."""

    v: float
    w: float
    polygon: str = ""
    action: str = "none"
    extra: dict[str, float] = field(default_factory=dict)


def in_polygon(pts: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Which points (M, 2) lie inside the polygon (N, 2) (even-odd ray casting)."""
    x, y = pts[:, 0:1], pts[:, 1:2]
    ax, ay = poly[:, 0], poly[:, 1]
    bx, by = np.roll(ax, -1), np.roll(ay, -1)
    crosses = ((ay > y) != (by > y)) & (x < (bx - ax) * (y - ay) / np.where(by == ay, 1e-12, by - ay) + ax)
    return (crosses.sum(axis=1) % 2) == 1


def grow(footprint: np.ndarray, margin: float) -> np.ndarray:
    """A convex footprint (N, 2) grown outwards by ``margin`` m (each vertex pushed along its corner bisector)."""
    poly = np.asarray(footprint, dtype=np.float64)
    centre = poly.mean(axis=0)
    out = []
    n = len(poly)
    for k in range(n):
        a, b, c = poly[k - 1], poly[k], poly[(k + 1) % n]
        n1 = _outward(a, b, centre)
        n2 = _outward(b, c, centre)
        bis = n1 + n2
        cos_half = max(float(np.dot(bis / np.linalg.norm(bis), n1)), 1e-3)
        out.append(b + bis / np.linalg.norm(bis) * margin / cos_half)
    return np.array(out)


def _outward(a: np.ndarray, b: np.ndarray, centre: np.ndarray) -> np.ndarray:
    d = b - a
    nrm = np.array([d[1], -d[0]]) / max(float(np.hypot(*d)), 1e-12)
    return nrm if float(np.dot(nrm, (a + b) / 2 - centre)) >= 0 else -nrm


def parse_polygons(params: dict[str, Any], footprint: np.ndarray | None) -> list[Polygon]:
    """The ``polygons`` list and each polygon's namespace (Nav2's layout), or the defaults from ``footprint``."""
    names = params.get("polygons")
    if not names:
        if footprint is None:
            raise NavigationError("collision_monitor: no polygons configured and no footprint to build them from")
        fp = np.asarray(footprint, dtype=np.float64)
        return [
            Polygon("PolygonStop", "stop", grow(fp, float(params.get("stop_margin", 0.05))), min_points=4),
            Polygon(
                "PolygonSlow",
                "slowdown",
                grow(fp, float(params.get("slowdown_margin", 0.3))),
                min_points=4,
                slowdown_ratio=float(params.get("slowdown_ratio", 0.3)),
            ),
            Polygon(
                "FootprintApproach",
                "approach",
                fp,
                min_points=4,
                time_before_collision=float(params.get("time_before_collision", 1.2)),
            ),
        ]
    out = []
    for name in names:
        spec = dict(params.get(str(name)) or {})
        action = str(spec.pop("action_type", ""))
        if action not in ACTIONS:
            raise NavigationError(
                f"collision_monitor polygon {name}: action_type expected one of {', '.join(ACTIONS)}, got {action!r}"
            )
        kind = str(spec.pop("type", "polygon"))
        pts = None
        if kind == "polygon":
            raw = np.asarray(spec.pop("points", spec.pop("footprint", footprint)), dtype=np.float64)
            pts = raw.reshape(-1, 2) if raw.size % 2 == 0 and raw.size >= 6 else None
            if pts is None:
                raise NavigationError(
                    f"collision_monitor polygon {name}: points expected [x1, y1, x2, y2, x3, y3, "
                    f"...] (>= 3 points), got {raw.tolist()!r}"
                )
        elif kind != "circle":
            raise NavigationError(f"collision_monitor polygon {name}: type expected polygon or circle, got {kind!r}")
        keys = {f for f in Polygon.__dataclass_fields__ if f not in ("name", "action_type", "points")}
        known = {k: spec[k] for k in spec if k in keys}
        if "max_points" in spec and "min_points" not in spec:  # Humble's name: the most points that are still ok
            known["min_points"] = int(spec["max_points"]) + 1
        defaults = Polygon(str(name), action)
        try:
            out.append(Polygon(str(name), action, pts, **{k: type(getattr(defaults, k))(v) for k, v in known.items()}))
        except (TypeError, ValueError) as exc:
            raise NavigationError(f"collision_monitor polygon {name}: {exc}") from None
    return out


class CollisionMonitor:
    """Nav2's collision monitor algorithm over ``polygons`` (see the module docstring)."""

    def __init__(self, polygons: list[Polygon]) -> None:
        self.polygons = [p for p in polygons if p.enabled]
        # each zone's (reach m, approach s): the reach at speed v is reach + |v| approach (see _reach), derived once;
        # when the first zone is fixed (not approach), the fixed zones' largest reach is one constant (a NaN speed
        # cannot lead the max, so the order of the rest does not matter)
        self._reaches = [
            (p.reach, p.time_before_collision if p.action_type == "approach" else None) for p in self.polygons
        ]
        fixed = [(r + 0.0) + 1e-9 for r, t in self._reaches if t is None]
        self._fixed = max(fixed) if self._reaches and self._reaches[0][1] is None else None
        self._moving = [(r, t) for r, t in self._reaches if t is not None]

    def check(self, v: float, w: float, points: np.ndarray) -> Verdict:
        """The command (v m/s, w rad/s) allowed with the obstacle ``points`` (M, 2; base frame, m)."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        best = Verdict(v, w)
        if len(pts) == 0:
            return best
        dist = np.hypot(pts[:, 0], pts[:, 1])
        for poly in self.polygons:
            near = pts[dist <= self._reach(poly, v)]
            if len(near) < poly.min_points:
                continue
            if poly.action_type == "approach":
                cand = self._approach(poly, v, w, near)
            elif int(poly.inside(near).sum()) >= poly.min_points:
                if poly.action_type == "stop":
                    cand = Verdict(0.0, 0.0, poly.name, "stop")
                elif poly.action_type == "slowdown":
                    cand = Verdict(v * poly.slowdown_ratio, w * poly.slowdown_ratio, poly.name, "slowdown")
                elif poly.action_type == "limit":
                    cand = Verdict(
                        math.copysign(min(abs(v), poly.linear_limit), v),
                        math.copysign(min(abs(w), poly.angular_limit), w),
                        poly.name,
                        "limit",
                    )
                else:
                    continue
            else:
                continue
            if abs(cand.v) < abs(best.v) - 1e-12 or (cand.action == "stop" and best.action != "stop"):
                best = cand
        return best

    @staticmethod
    def _reach(poly: Polygon, v: float) -> float:
        """How far (m) from the origin a point can count for ``poly`` at speed ``v`` (m/s): an approach zone moved
        along the arc stays within |v| ``time_before_collision`` of here."""
        return poly.reach + (abs(v) * poly.time_before_collision if poly.action_type == "approach" else 0.0) + 1e-9

    def reach(self, v: float) -> float:
        """How far (m) from the origin any point can change the command at speed ``v`` (m/s)."""
        # the same sums as _reach, from the constants of __init__
        av, best = abs(v), self._fixed
        if best is None:  # max(..., default=0.0) over every zone, as a loop (no generator a command)
            for r, t in self._reaches:
                x = (r + (av * t if t is not None else 0.0)) + 1e-9
                if best is None or x > best:
                    best = x
            return 0.0 if best is None else best
        for r, t in self._moving:
            if (x := (r + av * t) + 1e-9) > best:
                best = x
        return best

    def _approach(self, poly: Polygon, v: float, w: float, pts: np.ndarray) -> Verdict:
        """Scale (v, w) so the polygon moved along the arc touches the points no sooner than
        ``time_before_collision`` s."""
        if len(pts) == 0 or (abs(v) < 1e-9 and abs(w) < 1e-9):
            return Verdict(v, w)
        t = 0.0
        dt = poly.simulation_time_step
        while t < poly.time_before_collision - 1e-9:
            t += dt
            # the points as seen from the robot after t s on the arc (the inverse motion applied to the points)
            th = w * t
            if abs(w) > 1e-9:
                x, y = v / w * math.sin(th), v / w * (1 - math.cos(th))
            else:
                x, y = v * t, 0.0
            c, s = math.cos(th), math.sin(th)
            d = pts - (x, y)
            moved = np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]])
            if int(poly.inside(moved).sum()) >= poly.min_points:
                ratio = max(0.0, (t - dt) / poly.time_before_collision)
                return Verdict(v * ratio, w * ratio, poly.name, "approach", {"collision_in_s": t})
        return Verdict(v, w)


class CollisionMonitorNode(Node):
    """``nav2_collision_monitor``'s node: ``cmd_vel_in`` (Twist) checked against ``scan`` -> ``cmd_vel``.

    Parameters: ``base_frame_id`` (the robot's base frame), ``footprint`` (for the default polygons),
    ``polygons`` and their namespaces, ``source_timeout`` (s: an older scan counts as no data and stops the
    robot, Nav2's behaviour)."""

    def __init__(
        self,
        executor: Executor,
        *,
        name: str = "collision_monitor",
        parameters: dict[str, Any] | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(executor, name=name, parameters=parameters, namespace=namespace)
        self.base_frame = str(self.declare_parameter("base_frame_id", "base_link"))
        self.source_timeout = float(self.declare_parameter("source_timeout", 2.0))
        footprint = as_list(self.declare_parameter("footprint", []))
        raw: dict[str, Any] = {"polygons": self.declare_parameter("polygons", [])}
        for key, default in (
            ("stop_margin", 0.05),
            ("slowdown_margin", 0.3),
            ("slowdown_ratio", 0.3),
            ("time_before_collision", 1.2),
        ):
            raw[key] = self.declare_parameter(key, default)
        for poly in raw["polygons"] or []:
            self.accept_parameters(str(poly))
            raw[str(poly)] = self.get_parameters_by_prefix(str(poly))
        fp = np.asarray(footprint, dtype=np.float64).reshape(-1, 2) if footprint else None
        self.monitor = CollisionMonitor(parse_polygons(raw, fp))
        self.check_parameters()
        self.last_scan: Any = None  # the last scan and the laser's pose (x, y, yaw) in the base frame
        self.laser = (0.0, 0.0, 0.0)
        self.scan_ns: int | None = None
        self._scan_frame: str | None = None  # the frame_id the laser pose was looked up for
        self._laser_off = 0.0  # the laser's distance (m) from the base frame's origin
        self._closest: Any = None  # the last scan's closest range (m, the ranges' dtype), found when first needed
        self._last: Verdict | None = None  # the last verdict, or None after a pass-through of _last_in
        self._last_in: Any = None
        self.actions: dict[str, int] = {}  # how many commands each polygon changed
        self.pub = self.create_publisher(msgs.Twist, "cmd_vel", 1)
        self.create_subscription(msgs.LaserScan, "scan", self._on_scan, 1)
        self.create_subscription(msgs.Twist, "cmd_vel_in", self._on_cmd, 1)

    def _on_scan(self, msg: Any) -> None:
        """Keep the scan; its pose is looked up only when its frame changes (the laser is fixed on the robot)."""
        if msg.header.frame_id != self._scan_frame and not self._look_up_laser(msg.header.frame_id):
            return
        self.last_scan, self.scan_ns, self._closest = msg, self.executor.now_ns, None

    def _look_up_laser(self, frame_id: str) -> bool:
        """The laser's pose for scans in ``frame_id``; False (the scan dropped) while tf lacks it."""
        try:
            self.laser = self.sensor_pose(self.base_frame, str(frame_id).lstrip("/"))
        except TfError:
            return False
        self._scan_frame, self._laser_off = frame_id, math.hypot(self.laser[0], self.laser[1])
        return True

    def points(self, within: float = math.inf) -> np.ndarray:
        """The last scan's returns (M, 2; base frame, m), those that may lie within ``within`` m of the origin
        (turned into points only when a command needs them: most are farther than any zone reaches)."""
        msg, (x, y, yaw) = self.last_scan, self.laser
        if msg is None or not self._any_within(within):  # nothing close (the usual case): no points to make
            return np.zeros((0, 2))
        r = np.asarray(msg.ranges)
        far, top = within + self._laser_off, float(msg.range_max)  # NaN and inf fail both tests
        k = np.flatnonzero((r >= float(msg.range_min)) & ((r <= far) if far < top else (r < top)))
        rk = r[k].astype(np.float64)
        a = float(msg.angle_min) + float(msg.angle_increment) * k
        lx, ly = rk * np.cos(a), rk * np.sin(a)
        c, s = math.cos(yaw), math.sin(yaw)
        return np.column_stack([x + c * lx - s * ly, y + s * lx + c * ly])

    def _any_within(self, within: float) -> bool:
        """Whether the last scan may have a return within ``within`` m of the base frame's origin (its closest
        range, found once a scan, against ``within`` + the laser's offset; NaN ranges never count)."""
        closest = self._closest
        if closest is None:
            r = np.asarray(self.last_scan.ranges)
            closest = self._closest = np.fmin.reduce(r) if len(r) else math.inf
        return not closest > within + self._laser_off

    @property
    def last(self) -> Verdict | None:
        """The verdict on the last command (None before the first)."""
        if self._last is None and self._last_in is not None:
            return Verdict(float(self._last_in.linear.x), float(self._last_in.angular.z))
        return self._last

    def _on_cmd(self, msg: Any) -> None:
        lin, ang = msg.linear, msg.angular
        v, w = float(lin.x), float(ang.z)
        if self.scan_ns is None or not (self.executor.now_ns - self.scan_ns) / 1e9 <= self.source_timeout:
            verdict = Verdict(0.0, 0.0, "(no scan)", "stop")
        elif self._any_within(within := self.monitor.reach(v)):
            verdict = self.monitor.check(v, w, self.points(within))
        else:  # no return any zone can reach: the command passes unchanged (the message itself when it is planar;
            # subscribers never change a message they receive), nothing allocated
            self._last, self._last_in = None, msg
            planar = v is lin.x and w is ang.z and not (lin.y or lin.z or ang.x or ang.y)
            self.pub.publish(msg if planar else msgs.twist(v, w))
            return
        if verdict.polygon:
            self.actions[verdict.polygon] = self.actions.get(verdict.polygon, 0) + 1
        self._last, self._last_in = verdict, None
        self.pub.publish(msgs.twist(verdict.v, verdict.w))
