"""Where trials run: in this process, in local worker processes, or as Ray tasks.

``run_tasks(fn, items, backend=..., workers=...)`` calls ``fn(item)`` for every item and yields
``(index, result)`` as each finishes (in any order); the caller (the driver) writes the results, so a
results file looks the same whichever backend ran the trials. ``fn`` must be a module-level function
(workers import it by name).

- ``local``: ``workers`` = 1 runs in this process; more start that many ``spawn`` processes.
- ``ray``: ``ray.init(address=$RAY_ADDRESS)`` when the variable is set (a cluster whose nodes have navlab
  installed), else a local instance with ``workers`` CPUs (default: every core); each item is one Ray task
  of one CPU. Ray is imported only here, only for this backend. An instance started here is shut down at
  the end, in a background thread (``ray-shutdown``: Ray's shutdown waits ~1.3 s for its processes), so the
  caller writes its tables and plots meanwhile; the interpreter waits for that thread before it exits, and the
  next local instance is started only after it has finished (code that calls ``ray.init`` itself right after a
  run calls ``wait_for_shutdown()`` first). One already initialised by the caller is used as it is.
"""

from __future__ import annotations

import functools
import logging
import os
import threading
from collections.abc import Callable, Generator, Iterator, Sequence
from typing import Any, TypeVar

from navlab.experiments.errors import ExperimentError

BACKENDS = ("local", "ray")
SHUTDOWN_THREAD = "ray-shutdown"  # the name of the thread stopping a local Ray instance started here
T = TypeVar("T")
R = TypeVar("R")


def _indexed(fn: Callable[[T], R], job: tuple[int, T]) -> tuple[int, R]:
    return job[0], fn(job[1])


def run_tasks(
    fn: Callable[[T], R], items: Sequence[T], *, backend: str = "local", workers: int | None = None
) -> Generator[tuple[int, R], None, None]:
    """Yield ``(i, fn(items[i]))`` for every item as it finishes; ``workers``: processes (local, default 1) or
    CPUs of a local Ray instance (default: all). Closing the generator stops the workers."""
    if backend not in BACKENDS:
        raise ExperimentError(f"backend: expected one of {', '.join(BACKENDS)}, got {backend!r}")
    if workers is not None and workers < 1:
        raise ExperimentError(f"workers: expected an integer >= 1, got {workers}")
    if not items:
        return
    if backend == "ray":
        yield from _run_ray(fn, items, workers)
        return
    n = min(workers or 1, len(items))
    if n == 1:
        for i, item in enumerate(items):
            yield i, fn(item)
        return
    import multiprocessing

    with multiprocessing.get_context("spawn").Pool(n, initializer=_worker_signals) as pool:
        yield from pool.imap_unordered(functools.partial(_indexed, fn), list(enumerate(items)))


def _worker_signals() -> None:
    """A worker leaves Ctrl-C to the driver (a terminal sends it to every process of the job) and ends on the
    pool's SIGTERM as on an exception, so its ``finally`` blocks (a trial's temporary folder) still run."""
    import signal

    def end(_signum: int, _frame: Any) -> None:
        raise SystemExit(143)

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, end)


def _run_ray(fn: Callable[[T], R], items: Sequence[T], workers: int | None) -> Iterator[tuple[int, R]]:
    ray = _import_ray()
    wait_for_shutdown()
    started = not ray.is_initialized()
    if started:
        init_ray(ray, workers)
    try:
        task = ray.remote(num_cpus=1, max_retries=0)(fn)
        pending = {task.remote(item): i for i, item in enumerate(items)}
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            i = pending.pop(ready[0])
            try:
                result = ray.get(ready[0])
            except ray.exceptions.RayTaskError as exc:  # the trial's own error, with its traceback
                raise ExperimentError(f"item {i} failed on Ray: {exc}") from exc
            except ray.exceptions.RayError as exc:  # a worker or node died
                raise ExperimentError(f"item {i} was lost on Ray ({type(exc).__name__}): {exc}") from exc
            yield i, result
    finally:
        if started:  # not a daemon thread: the interpreter waits for it at exit
            threading.Thread(target=ray.shutdown, name=SHUTDOWN_THREAD, daemon=False).start()


def wait_for_shutdown() -> None:
    """Wait until a local Ray instance started by ``run_tasks`` has stopped (its shutdown runs in the
    background)."""
    for thread in threading.enumerate():
        if thread.name == SHUTDOWN_THREAD:
            thread.join()


def _import_ray() -> Any:
    try:
        import ray
    except ImportError as exc:
        raise ExperimentError(f"--backend ray needs the ray package ({exc}); install it with pip install ray") from exc
    return ray


def init_ray(ray: Any, workers: int | None) -> None:
    """Connect to ``$RAY_ADDRESS`` or start a local instance with ``workers`` CPUs; a clear error otherwise."""
    address = os.environ.get("RAY_ADDRESS") or None
    if address:
        check_reachable(address)
    try:
        if address:
            ray.init(address=address, log_to_driver=False, logging_level=logging.WARNING)
        else:
            ray.init(
                num_cpus=workers or os.cpu_count() or 1,
                include_dashboard=False,
                log_to_driver=False,
                logging_level=logging.WARNING,
            )
    except Exception as exc:  # Ray raises ConnectionError, RuntimeError, ValueError, ... by cause
        where = f"the cluster at RAY_ADDRESS={address!r}" if address else "a local Ray instance"
        hint = (
            "; a cluster with token authentication (which `ray start` turns on when ~/.ray/auth_token exists) "
            "needs RAY_AUTH_MODE=token here too"
            if address and not os.environ.get("RAY_AUTH_MODE")
            else ""
        )
        raise ExperimentError(
            f"--backend ray: could not start or reach {where}: "
            f"{type(exc).__name__}: {str(exc).strip().splitlines()[0] if str(exc).strip() else ''}"
            f"{hint}"
        ) from exc


def check_reachable(address: str, timeout: float = 5.0) -> None:
    """Refuse a ``RAY_ADDRESS`` (``host:port`` or ``ray://host:port``) whose port does not answer within
    ``timeout`` s (``ray.init`` would retry for minutes); ``auto``/``local`` are left to Ray."""
    import socket

    hostport = address.split("://", 1)[-1].rstrip("/")
    if hostport in ("auto", "local"):
        return
    host, sep, port = hostport.rpartition(":")
    if not sep or not port.isdigit():
        raise ExperimentError(f"RAY_ADDRESS={address!r}: expected host:port or ray://host:port (or auto)")
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
            pass
    except OSError as exc:
        raise ExperimentError(
            f"--backend ray: the Ray cluster at RAY_ADDRESS={address!r} is unreachable ({exc}); "
            "start it with `ray start --head` or unset RAY_ADDRESS for a local instance"
        ) from None
