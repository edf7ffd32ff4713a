"""``navlab topic echo``: rostopic echo's semantics on a running launch, a launch started here, or a recording.

Messages are printed as they arrive, as YAML with ``---`` after each (as rostopic prints them, ``/tf``
included); echo runs until Ctrl-C, the end of the launch or recording, ``-n N`` messages, or ``--duration``
simulated seconds. A silent topic gets rostopic's warning, and a bounded run that saw too few messages ends
with one line saying so (exit 1).
"""

from __future__ import annotations

import json
import math
import queue
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from navlab.core.errors import CoreError

MAX_ITEMS = 12  # longer arrays are shortened to their first 10 items and a count (rostopic's --noarr spirit)


def msg_to_dict(msg: Any) -> Any:
    """A navlab message as plain dicts, lists and numbers, in field order."""
    if hasattr(msg, "__dataclass_fields__"):
        return {k: msg_to_dict(getattr(msg, k)) for k in msg.__dataclass_fields__ if k != "__msgtype__"}
    if isinstance(msg, np.ndarray):
        return msg.tolist()
    if isinstance(msg, list | tuple):
        return [msg_to_dict(m) for m in msg]
    return msg


def format_msg(d: Any, indent: int = 0) -> str:
    """YAML as rostopic echo prints it: nested messages indented, lists of messages as ``-`` items."""
    pad = "  " * indent
    if isinstance(d, dict):
        lines = []
        for k, v in d.items():
            if isinstance(v, dict):
                lines.append(f"{pad}{k}:\n{format_msg(v, indent + 1)}")
            elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
                items = [f"{pad}  -\n{format_msg(x, indent + 2)}" for x in v[:MAX_ITEMS]]
                more = [f"{pad}  # ... ({len(v)} items)"] if len(v) > MAX_ITEMS else []
                lines.append(f"{pad}{k}:\n" + "\n".join(items + more))
            else:
                lines.append(f"{pad}{k}: {_scalar(v)}")
        return "\n".join(lines)
    return pad + _scalar(d)


def _scalar(v: Any) -> str:
    if isinstance(v, list):
        if len(v) > MAX_ITEMS:
            return "[" + ", ".join(_scalar(x) for x in v[:10]) + f", ... ({len(v)} items)]"
        return "[" + ", ".join(_scalar(x) for x in v) + "]"
    if isinstance(v, bool):
        return "True" if v else "False"
    if isinstance(v, float):
        text = f"{v:.6g}"
        return text if any(c in text for c in ".ein") else text + ".0"
    if isinstance(v, str):
        return json.dumps(v)  # rostopic quotes strings
    return str(v)


class Printer:
    """Prints each message with ``---`` after it; ``done`` once ``count`` (0: no limit) were printed."""

    def __init__(self, count: int) -> None:
        self.count, self.printed = count, 0

    def __call__(self, msg: Any) -> None:
        if self.done:
            return
        sys.stdout.write(format_msg(msg_to_dict(msg)) + "\n---\n")
        sys.stdout.flush()
        self.printed += 1

    @property
    def done(self) -> bool:
        return bool(self.count) and self.printed >= self.count


def _short_of(out: Printer, topic: str, what: str) -> int:
    """Exit status at the end of the source: 1, with one line, when fewer than ``--count`` messages came."""
    if out.count and out.printed < out.count:
        print(f"navlab: {what} after {out.printed} of {out.count} messages on {topic}", file=sys.stderr)
        return 1
    if not out.printed:
        print(f"navlab: no message on {topic}: {what}", file=sys.stderr)
        return 1
    return 0


def echo_bag(bag: str, topic: str, out: Printer, duration: float) -> int:
    """Echo ``topic`` from a recording: every message (or the first ``--count``, or ``duration`` s of them)."""
    from navlab.io import bag_topics, read_bag

    if topic not in bag_topics(bag):
        raise CoreError(f"no topic {topic!r} in the recording {bag} (topics: {', '.join(sorted(bag_topics(bag)))})")
    t0 = None
    for _name, t_ns, msg in read_bag(bag, topics=[topic]):
        t0 = t_ns if t0 is None else t0
        if out.done or (t_ns - t0) / 1e9 > duration:
            break
        out(msg)
    return _short_of(out, topic, "the recording ended")


def echo_live(path: Path, topic: str, out: Printer, duration: float) -> int:
    """Echo ``topic`` of a launch running in another shell until Ctrl-C, the launch's end, ``--count`` messages or
    ``duration`` simulated s (the launch's clock, so a silent topic ends too)."""
    from navlab.core.introspect import request, subscribe

    start = float(request(path, "info")["sim_time"])
    inbox: queue.Queue[Any] = queue.Queue()
    stop = threading.Event()

    def pump() -> None:
        while not stop.is_set():
            try:
                for _t, msg in subscribe(path, topic):
                    inbox.put(("msg", msg))
            except CoreError as exc:
                if not str(exc).startswith("no topic"):
                    inbox.put(("error", exc))
                    return
                stop.wait(0.5)  # not published yet: ask again, as rostopic waits for the topic to appear
                continue
            except OSError:  # the launch went away
                pass
            inbox.put(("end", None))
            return

    threading.Thread(target=pump, daemon=True, name="echo-subscribe").start()
    try:
        return _echo_until(path, topic, out, duration, start, inbox)
    finally:
        stop.set()


def _echo_until(path: Path, topic: str, out: Printer, duration: float, start: float, inbox: queue.Queue[Any]) -> int:
    """The loop of :func:`echo_live`: print what arrives, watch the launch's clock for the duration's end."""
    from navlab.core.introspect import request

    warned = False
    while not out.done:
        try:
            kind, item = inbox.get(timeout=0.5)
        except queue.Empty:
            try:
                now = float(request(path, "info", timeout=2.0)["sim_time"])
            except (OSError, CoreError):
                return _short_of(out, topic, "the launch ended")
            if now - start >= duration:
                return _short_of(out, topic, f"{duration:g} simulated s passed")
            if not warned and not out.printed and now - start >= 1.0:
                print(f"WARNING: topic [{topic}] does not appear to be published yet", file=sys.stderr)
                warned = True
            continue
        if kind == "msg":
            out(item)
        elif kind == "error":
            raise item
        else:
            return _short_of(out, topic, "the launch ended")
    return 0


def echo_launch(
    file_and_args: list[str], topic: str, out: Printer, duration: float, seed: int, run_for: Callable[..., Any]
) -> int:
    """Start a launch here and echo ``topic`` as it is published: in real time until Ctrl-C (as roslaunch +
    rostopic echo), or as fast as possible for ``duration`` simulated s; ends early after ``--count``."""
    from navlab.core.launch import start
    from navlab.core.runner import parse_launch_args

    file, *items = file_and_args
    session = start(file, seed=seed, rate=1.0 if math.isinf(duration) else 0.0, launch_args=parse_launch_args(items))
    ex = session.executor
    ex.add_listener(lambda name, msg, _t: out(msg) if name == topic else None)
    run_for(ex, min(duration, 1.0), quiet=True, until=lambda: out.done)
    if not out.done and topic not in ex.topics:
        print(f"WARNING: topic [{topic}] does not appear to be published yet", file=sys.stderr)
    if not out.done and duration > 1.0:
        run_for(ex, duration - 1.0, quiet=True, until=lambda: out.done)
    if not out.printed and topic not in ex.topics:
        raise CoreError(
            f"no topic {topic!r} in this launch after {duration:g} simulated s (topics: {', '.join(sorted(ex.topics))})"
        )
    return _short_of(out, topic, f"{duration:g} simulated s passed") if not out.done else 0
