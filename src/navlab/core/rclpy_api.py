"""rclpy's module-level API over navlab's runtime: ``init``, ``shutdown``, ``ok``, ``spin``, ``spin_once``,
``create_node`` and a :class:`Context` that finds the executor nodes join.

``navlab.init()`` is ``rclpy.init()``: it makes the default context, whose executor runs in simulated
time; ``navlab.init(launch="sim", world="room")`` also starts a launch in it, so ``Node("driver")`` joins
the simulation. ``spin(node)`` runs simulated time until ``shutdown()`` (or, in ``navlab run``, for
``--duration`` seconds). The default context lives in a :class:`contextvars.ContextVar` (one per
thread of control), as rclpy keeps one per process.
"""

from __future__ import annotations

import contextvars
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from navlab.core.errors import CoreError
from navlab.core.executor import Executor


@dataclass
class Context:
    """What ``rclpy.init`` sets up: here, the executor (and the launch session, if one was started)."""

    executor: Executor = field(default_factory=Executor)
    session: Any = None  # navlab.core.launch.Session when init() started a launch
    duration: float | None = None  # simulated seconds spin() runs (None: until shutdown)
    prepared: bool = False  # made by `navlab run` before the user's file: its rclpy.init() takes this one
    _ok: bool = True

    def ok(self) -> bool:
        """False after :meth:`shutdown`."""
        return self._ok

    def shutdown(self) -> None:
        """Stop the executor and end the launch's processes."""
        self._ok = False
        self.executor.stop()
        if self.session is not None:
            self.session.shutdown()


_DEFAULT: contextvars.ContextVar[Context | None] = contextvars.ContextVar("navlab_default_context", default=None)


def init(
    args: Sequence[str] | None = None,
    *,
    context: Context | None = None,
    launch: Any = None,
    seed: int = 0,
    rate: float = 0.0,
    duration: float | None = None,
    pace: float | None = None,
    **launch_args: Any,
) -> Context:
    """``rclpy.init()``: make (or take) the default context. ``launch``: a launch to start in it (shipped
    name or file(s)), with ``launch_args``; ``args`` are ``name:=value`` items as on a command line. ``rate``:
    the pace (0 = as fast as possible, 1 = real time; ``pace``, its old name, is deprecated)."""
    from navlab.deprecation import renamed

    rate = renamed(rate, pace, old="pace", new="rate", where="navlab.init")
    current = _DEFAULT.get()
    if context is None and launch is None and current is not None and current.prepared:
        current.prepared = False  # `navlab run FILE`: the file's rclpy.init() joins the launch started for it
        return current
    if context is None:
        if launch is not None:
            from navlab.core.launch import start
            from navlab.core.runner import parse_launch_args

            items = parse_launch_args([a for a in args or [] if ":=" in a])
            session = start(launch, seed=seed, rate=rate, launch_args={**items, **launch_args})
            context = Context(session.executor, session, duration)
        else:
            context = Context(Executor(seed=seed, rate=rate), None, duration)
    _DEFAULT.set(context)
    return context


def get_default_context() -> Context:
    """The context ``init()`` made; CoreError if ``init()`` was not called."""
    context = _DEFAULT.get()
    if context is None:
        raise CoreError("call navlab.init() (rclpy.init()) before creating a node")
    return context


def context_executor(context: Context | None) -> Executor:
    """The executor a new ``Node("name")`` joins: ``context``'s, else the default context's."""
    return (context or get_default_context()).executor


def ok(*, context: Context | None = None) -> bool:
    """``rclpy.ok()``: whether the context is still up."""
    ctx = context or _DEFAULT.get()
    return ctx is not None and ctx.ok()


def shutdown(*, context: Context | None = None) -> None:
    """``rclpy.shutdown()``: stop the context's executor and launch."""
    ctx = context or _DEFAULT.get()
    if ctx is not None:
        ctx.shutdown()
        if ctx is _DEFAULT.get():
            _DEFAULT.set(None)


def spin(node: Any, executor: Any = None) -> None:
    """``rclpy.spin(node)``: run simulated time until shutdown (or the context's ``duration``)."""
    import math

    ctx = _DEFAULT.get()
    duration = ctx.duration if ctx is not None and ctx.duration is not None else math.inf
    ex = node.executor
    step = 0.5
    done = 0.0
    while not ex.stopped and done < duration and (ctx is None or ctx.ok()):
        dt = min(step, duration - done)
        ex.run(dt)
        done += dt


def spin_once(node: Any, *, executor: Any = None, timeout_sec: float | None = None) -> None:
    """``rclpy.spin_once(node, timeout_sec=...)``: run simulated time for ``timeout_sec`` (default: until the
    next scheduled event)."""
    ex = node.executor
    if timeout_sec is None:
        ex.run_until(lambda: True, timeout=1.0)
    else:
        ex.run(float(timeout_sec))


def create_node(node_name: str, **kwargs: Any) -> Any:
    """``rclpy.create_node(name, ...)``: a plain :class:`navlab.core.Node`."""
    from navlab.core.node import Node

    return Node(node_name, **kwargs)
