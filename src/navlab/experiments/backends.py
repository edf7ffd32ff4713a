"""Where trials run: in this process, in local worker processes, or as Ray tasks.

``run_tasks(fn, items, backend=..., workers=...)`` calls ``fn(item)`` for every item and yields
``(index, result)`` as each finishes (in any order); the caller (the driver) writes the results, so a
results file looks the same whichever backend ran the trials. ``fn`` must be a module-level function
(workers import it by name).

- ``local``: ``workers`` = 1 runs in this process; more start that many ``spawn`` processes, each fed one item at
  a time over its own pipe (no lock shared with the workers, so nothing the driver can block on). A worker starts
  with Ctrl-C held back and then ignores it (a terminal signals the whole job: the driver decides). Closing the
  generator (Ctrl-C in the driver) ends them in bounded time: SIGTERM, which a worker turns into SystemExit (its
  ``finally`` blocks and exit handlers run: no leaked semaphore), sent again every ``RESEND_S``, then SIGKILL for
  any left after ``STOP_GRACE_S``. The exception can land where it cannot propagate: native code calling back
  into Python (a Numba function turns it into ``SystemError(... returned a result with an exception set)``, an
  extension module's import into ``ImportError``) or a finalizer (``__del__``: "Exception ignored"). A worker
  whose item ends after SIGTERM therefore exits whatever the item's outcome, a finalizer's "Exception ignored" is
  not printed, and the driver repeats the signal. Whatever is left, the worker's temporary files go to a folder
  of the driver's, removed once the workers are gone.
- ``ray``: ``ray.init(address=$RAY_ADDRESS)`` when the variable is set (a cluster whose nodes have navlab
  installed), else a local instance with ``workers`` CPUs (default: every core); each item is one Ray task
  of one CPU. Ray is imported only here, only for this backend. An instance started here is shut down at
  the end, in a background thread (``ray-shutdown``: Ray's shutdown waits ~1.3 s for its processes), so the
  caller writes its tables and plots meanwhile; the interpreter waits for that thread before it exits, and the
  next local instance is started only after it has finished (code that calls ``ray.init`` itself right after a
  run calls ``wait_for_shutdown()`` first). One already initialised by the caller is used as it is.
"""

from __future__ import annotations

import contextlib
import logging
import os
import shutil
import signal
import tempfile
import threading
import time
import traceback
from collections.abc import Callable, Generator, Iterator, Sequence
from multiprocessing.connection import Connection, wait
from multiprocessing.process import BaseProcess
from typing import Any, TypeVar, cast

from navlab.experiments.errors import ExperimentError

BACKENDS = ("local", "ray")
SHUTDOWN_THREAD = "ray-shutdown"  # the name of the thread stopping a local Ray instance started here
STOP_GRACE_S = 10.0  # local workers still running this long after the first SIGTERM are killed (SIGKILL)
RESEND_S = 1.0  # SIGTERM again to a local worker still running after this long
T = TypeVar("T")
R = TypeVar("R")


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
    yield from _run_local(fn, items, n)


def _run_local(fn: Callable[[T], R], items: Sequence[T], n: int) -> Iterator[tuple[int, R]]:
    """``fn`` over ``items`` in ``n`` spawned worker processes; every way out (the end, an error, Ctrl-C, the
    generator closed) stops the workers within ``STOP_GRACE_S`` and removes their temporary files."""
    import multiprocessing
    from multiprocessing import resource_tracker

    ctx = multiprocessing.get_context("spawn")
    resource_tracker.ensure_running()  # every spawn needs it; started inside _sigint_held, it would unblock SIGINT
    todo = list(enumerate(items))[::-1]  # popped from the end: in order
    procs: list[BaseProcess] = []
    pipes: list[Connection] = []  # the driver's end of each worker's pipe
    running: dict[Connection, tuple[BaseProcess, int]] = {}  # a busy worker's pipe: the worker, its item
    scratch = tempfile.mkdtemp(prefix="navlab-workers-")
    try:
        for _ in range(n):
            here, there = ctx.Pipe()
            pipes.append(here)
            proc: BaseProcess = ctx.Process(target=_worker, args=(there, fn, scratch), daemon=True)
            procs.append(proc)
            with _sigint_held():  # inherited across exec: the worker ignores Ctrl-C before one can reach it
                proc.start()
            there.close()  # the worker's end is the worker's alone: its death is an EOF here
            _hand_out(here, proc, todo, running)
        while running:
            for conn in cast(list[Connection], wait(list(running))):
                proc, i = running.pop(conn)
                try:
                    ok, value = conn.recv()
                except (EOFError, OSError):
                    proc.join(1.0)
                    raise ExperimentError(
                        f"worker process {proc.pid} ended (exit code {proc.exitcode}) while running item {i}"
                    ) from None
                if not ok:
                    raise value  # the worker's exception, its traceback in a note
                _hand_out(conn, proc, todo, running)
                yield i, value
    finally:
        for conn in pipes:
            conn.close()  # an idle worker reads EOF and ends
        try:
            _stop(procs)
        finally:  # also after a second Ctrl-C
            shutil.rmtree(scratch, ignore_errors=True)


def _hand_out(
    conn: Connection, proc: BaseProcess, todo: list[tuple[int, Any]], running: dict[Connection, tuple[BaseProcess, int]]
) -> None:
    """Send the next item to the worker at ``conn`` (none left: close its pipe, it ends)."""
    if not todo:
        conn.close()
        return
    i, item = todo.pop()
    try:
        conn.send((i, item))
    except OSError:  # BrokenPipeError: the worker died
        proc.join(1.0)
        raise ExperimentError(f"worker process {proc.pid} ended (exit code {proc.exitcode}) before item {i}") from None
    running[conn] = (proc, i)


def _stop(procs: list[BaseProcess]) -> None:
    """End the workers: SIGTERM every ``RESEND_S`` while they run, SIGKILL after ``STOP_GRACE_S``."""
    end = time.monotonic() + STOP_GRACE_S
    try:
        while (alive := [p for p in procs if p.is_alive()]) and time.monotonic() < end:
            for p in alive:
                p.terminate()
            resend = min(time.monotonic() + RESEND_S, end)
            while (alive := [p for p in alive if p.is_alive()]) and (left := resend - time.monotonic()) > 0:
                wait([p.sentinel for p in alive], timeout=left)
    finally:  # also on a second Ctrl-C while waiting
        for p in procs:
            if p.is_alive():
                p.kill()
            p.join(5.0)


@contextlib.contextmanager
def _sigint_held() -> Iterator[None]:
    """SIGINT blocked in this thread meanwhile: a child started here inherits the mask (``exec`` keeps it); a
    Ctrl-C that comes meanwhile reaches this process when the mask is restored."""
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def _worker(conn: Connection, fn: Callable[[Any], Any], scratch: str) -> None:
    """A worker process: ``fn`` on each ``(i, item)`` it reads, ``(True, result)`` or ``(False, exception)`` sent
    back; it ends when the driver closes the pipe, or on SIGTERM."""
    terminated = _worker_signals()
    tempfile.tempdir = os.environ["TMPDIR"] = scratch  # the driver removes it, however the worker ends
    try:
        while True:
            try:
                i, item = conn.recv()
            except (EOFError, OSError):  # the driver closed its end (a reset if a reply was left unread)
                return
            try:
                reply = (True, fn(item))
            except Exception as exc:  # SystemExit (SIGTERM) ends the worker
                exc.add_note(f"in worker process {os.getpid()} (item {i}):\n{traceback.format_exc().rstrip()}")
                reply = (False, exc)
            if terminated.is_set():  # SIGTERM came, but native code swallowed its exception or turned it into another
                raise SystemExit(143)
            try:
                conn.send(reply)  # pickled whole before any byte is written
            except OSError:  # the driver has gone
                return
            except Exception as exc:  # an unpicklable result or exception
                conn.send((False, ExperimentError(f"item {i}: its result could not be sent back: {exc!r}")))
    finally:  # on its way out: the interpreter's exit runs undisturbed (the driver kills it past the grace time)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)


def _worker_signals() -> threading.Event:
    """A worker leaves Ctrl-C to the driver (a terminal sends it to every process of the job) and ends on the
    driver's SIGTERM as on an exception, so its ``finally`` blocks and exit handlers still run; the event returned
    is set once that SIGTERM has come."""
    import sys

    def end(_signum: int, _frame: Any) -> None:
        terminated.set()
        raise SystemExit(143)

    terminated = threading.Event()
    default_hook = sys.unraisablehook

    def unraisable(info: Any) -> None:
        if not (terminated.is_set() and info.exc_type is SystemExit):  # raised in a finalizer: the driver signals again
            default_hook(info)

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # discards a Ctrl-C held back since the worker started
    signal.signal(signal.SIGTERM, end)
    sys.unraisablehook = unraisable
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    return terminated


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
