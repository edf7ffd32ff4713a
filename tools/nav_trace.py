"""Record or compare a bit-level trace of ``navlab bench nav``'s run, to show a speed-up changes no result.

    python tools/nav_trace.py record OUT.json [--seed N] [--controller trajectory|dwa|mppi] [--robot mybot_depth]
    python tools/nav_trace.py compare OLD.json NEW.json

The trace holds every cmd_vel (hex floats), every transform tf received (stamp, child, x, y, rotation z),
every amcl_pose, a hash of every global plan, of both costmaps after each update and of the controller's local
plan each cycle, the true path and the monitor's samples (clearance, localization error, plan tracking) at 10 Hz,
and each goal's figures.
Record with the old code (e.g. ``PYTHONPATH=/tmp/old/src``, a ``git archive`` of the base; this tool from the new
tree), then with the new, and compare: ``compare`` names the first difference of each part and exits 1 if there is
one.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from typing import Any

import numpy as np


def _digest(data: bytes) -> str:
    return hashlib.sha1(data).hexdigest()[:16]


def record(out: str, seed: int, controller: str | None, robot: str = "mybot") -> None:
    """Run bench nav's goals with hooks on the executor, the costmaps and move_base; write the trace to ``out``."""
    from navlab.bench.experiments import NAV_GOALS
    from navlab.core.executor import Executor
    from navlab.core.tf import TfBuffer
    from navlab.experiments.navigate_monitor import NavMonitor
    from navlab.experiments.navigate_run import run_navigation
    from navlab.navigation.costmap_ros import Costmap2DROS
    from navlab.navigation.move_base import MoveBase

    rec: dict[str, Any] = {k: [] for k in ("cmd", "tf", "amcl", "plan", "costmap", "local", "monitor")}
    publish, update, make_plan = Executor.publish, Costmap2DROS.update, MoveBase.make_plan
    set_transform = TfBuffer.set_transform
    sample = NavMonitor._sample

    def on_publish(self: Any, topic: Any, msg: Any, *, latch_key: int | None = None) -> None:
        t, name = self.now_ns, topic.name
        if name.endswith("cmd_vel"):
            rec["cmd"].append((t, name, msg.linear.x.hex(), msg.angular.z.hex()))
        elif name.endswith("amcl_pose"):
            p = msg.pose.pose
            rec["amcl"].append((t, *(v.hex() for v in (p.position.x, p.position.y, p.orientation.z, p.orientation.w))))
        publish(self, topic, msg, latch_key=latch_key)

    def on_set_transform(self: Any, parent: str, child: str, t_ns: int, tf: Any, *, static: bool = False) -> None:
        # what tf receives: from a /tf message or straight to the buffer (Node.send_transform_tuples)
        if not static:
            rec["tf"].append((t_ns, child, float(tf[0]).hex(), float(tf[1]).hex(), float(tf[5]).hex()))
        set_transform(self, parent, child, t_ns, tf, static=static)

    def on_update(self: Any, *a: Any, **k: Any) -> Any:
        out = update(self, *a, **k)
        g = None if out is None else self.costmap  # as a reader sees it after the update (a deferred write done now)
        if g is not None:
            rec["costmap"].append(
                (self.node.executor.now_ns, self.name, _digest(g.data.tobytes() + repr(g.origin).encode()))
            )
        return out

    def on_make_plan(self: Any, start: Any, goal: Any) -> Any:
        p = make_plan(self, start, goal)
        rec["plan"].append((self.executor.now_ns, None if p is None else _digest(np.ascontiguousarray(p).tobytes())))
        return p

    def on_sample(self: Any) -> None:
        sample(self)
        last = (self.clearance[-1], self.tracking[-1], self.localization_error[-1] if self.localization_error else 0.0)
        rec["monitor"].append((self.executor.now_ns, *(float(v).hex() for v in last)))

    def on_start(run: Any) -> None:
        ctl = run.node("move_base").controller
        compute = ctl.compute_velocity

        def on_compute(*a: Any, **k: Any) -> Any:
            res = compute(*a, **k)
            lp = np.ascontiguousarray(res.local_plan, dtype=np.float64)
            rec["local"].append((run.executor.now_ns, bool(res.valid), _digest(lp.tobytes())))
            return res

        ctl.compute_velocity = on_compute

    Executor.publish, Costmap2DROS.update, MoveBase.make_plan = on_publish, on_update, on_make_plan  # type: ignore[method-assign]
    NavMonitor._sample = on_sample  # type: ignore[method-assign]
    TfBuffer.set_transform = on_set_transform  # type: ignore[method-assign]
    r = run_navigation(
        list(NAV_GOALS),
        world="room_obstacles",
        robot=robot,
        goal_timeout=90,
        seed=seed,
        controller=controller,
        on_start=on_start,
    )
    rec["path"] = [[float(v).hex() for v in row] for row in r.path]
    rec["summary"] = {k: r.summary[k] for k in ("sim_s", "goals_succeeded", "collisions")}
    rec["goals"] = [{k: v.hex() if isinstance(v, float) else v for k, v in g.items()} for g in r.goals]
    with open(out, "w") as f:
        json.dump(rec, f)
    print(out, {k: len(v) for k, v in rec.items()})


def compare(old: str, new: str) -> bool:
    """Print each part as identical or its first difference; True if everything is identical."""
    with open(old) as f, open(new) as g:
        a, b = json.load(f), json.load(g)
    same = True
    for key in sorted(set(a) | set(b)):
        x, y = a.get(key), b.get(key)
        if x == y:
            print(f"{key}: identical ({len(x)})")
            continue
        same = False
        if isinstance(x, list) and isinstance(y, list):
            k = next((i for i, (p, q) in enumerate(zip(x, y, strict=False)) if p != q), min(len(x), len(y)))
            print(f"{key}: first difference at {k} ({len(x)} vs {len(y)} entries)")
        else:
            print(f"{key}: {x} vs {y}")
    print("IDENTICAL" if same else "DIFFERENT")
    return same


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="verb", required=True)
    r = sub.add_parser("record")
    r.add_argument("out")
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--controller", default=None)
    r.add_argument("--robot", default="mybot")
    c = sub.add_parser("compare")
    c.add_argument("old")
    c.add_argument("new")
    args = ap.parse_args()
    if args.verb == "record":
        record(args.out, args.seed, args.controller, args.robot)
    else:
        sys.exit(0 if compare(args.old, args.new) else 1)


if __name__ == "__main__":
    main()
