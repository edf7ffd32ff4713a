"""A tf buffer: time-stamped transforms, static transforms, interpolation and chain lookups.

Each child frame has one parent. A transform ``parent_T_child`` maps points from the child frame
into the parent frame. ``lookup_transform(target, source, t)`` returns ``target_T_source``,
interpolating each dynamic edge linearly in translation and by slerp in rotation.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field
from typing import Any

from navlab.core.errors import TfError
from navlab.geometry import IDENTITY_TF, Tf, compose3, interpolate3, inverse3, yaw_from_quat
from navlab.msgs import Quaternion, Transform, TransformStamped, Vector3, header, ns_from_time

Pose2 = tuple[float, float, float]  # (x m, y m, yaw rad) of a frame's origin in another frame
LOOKUP_CACHE = 64  # lookups remembered (see TfBuffer.lookup)
_DROP_BATCH = 128  # history entries past cache_ns are deleted from an edge's lists this many at a time (cheaper)


def tf_from_msg(tr: Any) -> Tf:
    """Tuple form of a ``geometry_msgs/Transform``."""
    t, r = tr.translation, tr.rotation
    return (t.x, t.y, t.z, r.x, r.y, r.z, r.w)


def yaw_of(tf: Tf) -> float:
    """Yaw (rad) of a transform's rotation."""
    return yaw_from_quat(tf[3:])


@dataclass
class _Edge:
    parent: str
    static: bool
    times: list[int] = field(default_factory=list)
    values: list[Tf] = field(default_factory=list)
    changes: int = 0  # bumped by every transform added: a lookup through the edge is then computed again
    lo: int = 0  # the history is times[lo:], values[lo:]: older entries are dropped from the lists in batches


# a lookup's edges (child frame, edge) from the target and from the source up to their common ancestor, and all of them
_Chain = tuple[list[tuple[str, _Edge]], list[tuple[str, _Edge]], tuple[_Edge, ...]]


class TfBuffer:
    """Stores transforms between frames and answers lookups between any two connected frames.

    ``cache_ns`` bounds the history kept per dynamic edge; ``tolerance_ns`` allows lookups that
    slightly extrapolate past the newest (or before the oldest) transform of an edge.
    """

    def __init__(self, *, cache_ns: int = 10_000_000_000, tolerance_ns: int = 0) -> None:
        self.cache_ns = cache_ns
        self.tolerance_ns = tolerance_ns
        self._edges: dict[str, _Edge] = {}
        self._parents: set[str] = set()
        self._version = 0  # bumped whenever the tree's shape changes (an edge added or re-parented)
        # (target, source) -> (version, the lookup's chain of edges)
        self._chains: dict[tuple[str, str], tuple[int, _Chain]] = {}
        # lookups answered (target, source, t_ns, tolerance) -> [tree version, the edges the answer read, their
        # changes then, the answer, its (x, y, yaw) once asked]: valid until one of those edges changes. Many nodes ask
        # the same question between two transforms of the edges it reads (the costmaps, move_base, amcl, monitors).
        self._lookups: dict[tuple[str, str, int | None, int], list[Any]] = {}

    def frames(self) -> list[str]:
        """Every frame seen, as parent or child."""
        names = set(self._edges)
        names.update(e.parent for e in self._edges.values())
        return sorted(names)

    def parent_of(self, frame: str) -> str | None:
        """Parent frame of ``frame`` (None for a root or unknown frame)."""
        e = self._edges.get(frame)
        return e.parent if e else None

    def set_transform(self, parent: str, child: str, t_ns: int, tf: Tf, *, static: bool = False) -> None:
        """Add ``parent_T_child`` valid at ``t_ns`` (static transforms are valid at every time)."""
        if not parent or not child:
            raise TfError(f"transform needs both frame names, got parent={parent!r} child={child!r}")
        e = self._edges.get(child)
        if e is None or e.parent != parent or e.static != static:
            e = self._edges[child] = _Edge(parent, static)
            self._parents.add(parent)
            self._version += 1
        e.changes += 1
        if static:
            e.times, e.values, e.lo = [t_ns], [tf], 0
            return
        times, values = e.times, e.values
        if times and t_ns < times[-1]:
            i = bisect.bisect_right(times, t_ns, e.lo)
            times.insert(i, t_ns)
            values.insert(i, tf)
        else:
            times.append(t_ns)
            values.append(tf)
        lo = e.lo
        if times[-1] - times[lo] > self.cache_ns:  # keep cache_ns: the entries older than that leave the history
            oldest = times[-1] - self.cache_ns  # bisect_left(times, oldest, lo) by steps: one or two a transform
            while times[lo] < oldest:
                lo += 1
            if lo >= _DROP_BATCH:
                del times[:lo], values[:lo]
                lo = 0
            e.lo = lo

    def add_message(self, msg: Any, *, static: bool = False) -> None:
        """Add every transform of a ``tf2_msgs/TFMessage``."""
        for ts in msg.transforms:
            self.set_transform(
                ts.header.frame_id.lstrip("/"),
                ts.child_frame_id.lstrip("/"),
                ns_from_time(ts.header.stamp),
                tf_from_msg(ts.transform),
                static=static,
            )

    def _edge_at(self, child: str, e: _Edge, t_ns: int | None) -> Tf:
        if e.static:
            return e.values[0]
        times = e.times
        if t_ns is None:
            return e.values[-1]
        if t_ns >= times[-1]:
            if t_ns - times[-1] > self.tolerance_ns:
                raise TfError(
                    f"lookup of {e.parent}->{child} at t={t_ns / 1e9:.3f} s would extrapolate into the future "
                    f"(newest transform at {times[-1] / 1e9:.3f} s)"
                )
            return e.values[-1]
        lo = e.lo
        if t_ns <= times[lo]:
            if times[lo] - t_ns > self.tolerance_ns:
                raise TfError(
                    f"lookup of {e.parent}->{child} at t={t_ns / 1e9:.3f} s would extrapolate into the past "
                    f"(oldest transform at {times[lo] / 1e9:.3f} s)"
                )
            return e.values[lo]
        i = bisect.bisect_right(times, t_ns, lo)
        t0, t1 = times[i - 1], times[i]
        return interpolate3(e.values[i - 1], e.values[i], (t_ns - t0) / (t1 - t0))

    def _ancestors(self, frame: str) -> list[str]:
        """``frame`` and its parents up to the root, by name only (nothing is evaluated)."""
        chain = [frame]
        while frame in self._edges:
            frame = self._edges[frame].parent
            if frame in chain:
                raise TfError(f"tf tree has a loop through frame {frame!r}")
            chain.append(frame)
        return chain

    def _chain(self, target: str, source: str) -> _Chain:
        """The edges (child frame, edge) from ``target`` and from ``source`` up to their common ancestor,
        bottom first, and all those edges; remembered until the tree's shape changes."""
        hit = self._chains.get((target, source))
        if hit is not None and hit[0] == self._version:
            return hit[1]
        for f in (target, source):
            if f not in self._edges and f not in self._parents:
                known = ", ".join(self.frames()) or "none"
                raise TfError(f"frame {f!r} does not exist (known frames: {known})")
        up_s, up_t = self._ancestors(source), self._ancestors(target)
        if up_s[-1] != up_t[-1]:
            raise TfError(f"frames {target!r} and {source!r} are not connected (roots {up_t[-1]!r} and {up_s[-1]!r})")
        in_target = set(up_t)
        common = next(f for f in up_s if f in in_target)
        # Only the edges below the common ancestor are evaluated, so an edge above it (map->odom while
        # looking up odom->base) never limits the lookup time.
        edges_t = [(f, self._edges[f]) for f in up_t[: up_t.index(common)]]
        edges_s = [(f, self._edges[f]) for f in up_s[: up_s.index(common)]]
        chain = (edges_t, edges_s, tuple(e for _, e in (*edges_t, *edges_s)))
        self._chains[(target, source)] = (self._version, chain)
        return chain

    def _compose(self, edges: list[tuple[str, _Edge]], t_ns: int | None) -> Tf:
        """``ancestor_T_frame``: compose a chain of edges (bottom first) up to its top."""
        out: Tf | None = None  # the bottom edge itself, not composed with the identity (the same values, cheaper)
        for child, e in edges:
            tf = self._edge_at(child, e, t_ns)
            out = tf if out is None else compose3(tf, out)
        return IDENTITY_TF if out is None else out

    def lookup(self, target: str, source: str, t_ns: int | None = None) -> Tf:
        """``target_T_source`` at ``t_ns`` (None: the latest time every edge on the path has)."""
        return self._answer(target, source, t_ns)[3]

    def _cached(self, key: tuple[str, str, int | None, int]) -> list[Any] | None:
        """The lookup's cache entry (see ``_lookups``) if it is still valid, else None."""
        hit = self._lookups.get(key)
        if hit is None or hit[0] != self._version:
            return None
        for e, n in zip(hit[1], hit[2], strict=True):
            if e.changes != n:
                return None
        return hit

    def _answer(self, target: str, source: str, t_ns: int | None) -> list[Any]:
        """The lookup's cache entry (see ``_lookups``), computed unless still valid."""
        key = (target, source, t_ns, self.tolerance_ns)
        hit = self._cached(key)
        if hit is not None:
            return hit
        return self._compute(key, self._chain(target.lstrip("/"), source.lstrip("/")), t_ns)

    def _compute(self, key: tuple[str, str, int | None, int], chain: _Chain, t_ns: int | None) -> list[Any]:
        """Work out the lookup ``key`` over ``chain`` (:meth:`_chain`) at ``t_ns`` and remember it."""
        edges_t, edges_s, edges = chain
        out = self._lookup(edges_t, edges_s, t_ns)
        if len(self._lookups) >= LOOKUP_CACHE:  # stamped questions pile up: start again
            self._lookups.clear()
        hit = self._lookups[key] = [self._version, edges, tuple([e.changes for e in edges]), out, None]
        return hit

    def _lookup(self, edges_t: list[tuple[str, _Edge]], edges_s: list[tuple[str, _Edge]], t_ns: int | None) -> Tf:
        """``target_T_source`` from the chain's edges (:meth:`_chain`) at ``t_ns`` (None: the latest common)."""
        if t_ns is None:  # the newest time every dynamic edge between the two frames has (None if all static)
            for _, e in (*edges_s, *edges_t):
                if not e.static:
                    t_ns = e.times[-1] if t_ns is None else min(t_ns, e.times[-1])
        # no identity is composed: a target that is the common ancestor (the usual lookup) takes the source's chain
        down = self._compose(edges_s, t_ns)
        if not edges_t:
            return down
        up = inverse3(self._compose(edges_t, t_ns))
        return compose3(up, down) if edges_s else up

    def can_transform(self, target: str, source: str, t_ns: int | None = None) -> bool:
        """Whether :meth:`lookup` would succeed."""
        try:
            self.lookup(target, source, t_ns)
        except TfError:
            return False
        return True

    def lookup_transform(self, target: str, source: str, t_ns: int | None = None) -> Any:
        """``target_T_source`` as a ``geometry_msgs/TransformStamped`` (frame_id=target, child=source)."""
        tf = self.lookup(target, source, t_ns)
        return TransformStamped(
            header=header(t_ns or 0, target),
            child_frame_id=source,
            transform=Transform(
                translation=Vector3(x=tf[0], y=tf[1], z=tf[2]),
                rotation=Quaternion(x=tf[3], y=tf[4], z=tf[5], w=tf[6]),
            ),
        )

    def lookup_pose2d(self, target: str, source: str, t_ns: int | None = None) -> Pose2:
        """(x, y, yaw) of ``source``'s origin in ``target``."""
        return _pose2d(self._answer(target, source, t_ns))

    def lookup_pose2d_or_latest(self, target: str, source: str, t_ns: int | None) -> Pose2:
        """(x, y, yaw) of ``source`` in ``target`` at ``t_ns``, else at the latest time tf has.

        The pose "at the scan's stamp" of SLAM, AMCL and the costmaps: a message stamped a little ahead
        of the newest odometry still gets a pose. Raises the latest lookup's ``TfError`` if both fail.
        """
        if t_ns is None:
            return self.lookup_pose2d(target, source, None)
        key = (target, source, t_ns, self.tolerance_ns)
        hit = self._cached(key)  # a valid answer at t_ns: every edge had t_ns
        if hit is None:
            # without raising and catching (a scan stamped after the newest odometry is the common case)
            chain = self._chain(target.lstrip("/"), source.lstrip("/"))
            tol = self.tolerance_ns
            for e in chain[2]:
                if not (e.static or e.times[e.lo] - tol <= t_ns <= e.times[-1] + tol):
                    return _pose2d(self._answer(target, source, None))  # lookup_pose2d(target, source, None)
            hit = self._compute(key, chain, t_ns)
        return _pose2d(hit)


def _pose2d(hit: list[Any]) -> Pose2:
    """A lookup's (x, y, yaw), from its cache entry (worked out once)."""
    if hit[4] is None:
        tf = hit[3]
        hit[4] = (tf[0], tf[1], yaw_of(tf))
    return hit[4]
