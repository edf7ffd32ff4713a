"""Nodes of a ROS 1 launch file that navlab does not implement, started as processes as roslaunch does.

The command line and environment are roslaunch's (``roslaunch --args NODE`` prints the same):
``[launch-prefix] EXECUTABLE ARGS from:=to ... __name:=NAME __log:=LOGFILE`` with ``ROS_MASTER_URI``,
``ROS_NAMESPACE`` (when the node is in a namespace other than ``/``) and the ``<env>`` values set,
in ``ROS_HOME`` (default ``~/.ros``). ``respawn`` restarts a process that exits (after
``respawn_delay`` s); ``required`` stops the launch when it exits. Only started when the ROS bridge
is on: without a master such a node could not talk to anything.
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from navlab.core.errors import LaunchError
from navlab.core.roslaunch import FIND_PACKAGE, RosNode, call

DEFAULT_MASTER_URI = "http://localhost:11311"


def find_executable(pkg: str, typ: str, where: str) -> Path:
    """The executable ``typ`` of package ``pkg``: a file of that name with the execute bit inside the
    package folder (as catkin's source-space look-up), else one on ``PATH`` (Debian's ROS binaries)."""
    try:
        root: Path | None = Path(call(FIND_PACKAGE, pkg))
    except Exception:
        root = None
    if root is not None:
        for cand in sorted(root.rglob(typ)):
            if cand.is_file() and os.access(cand, os.X_OK) and not any(p.startswith(".") for p in cand.parts):
                return cand
    on_path = shutil.which(typ)
    if on_path:
        return Path(on_path)
    where_pkg = f"in package {pkg} ({root})" if root else f"(package {pkg!r} not found)"
    raise LaunchError(
        f"{where}: cannot launch node of type [{pkg}/{typ}]: no executable {typ!r} {where_pkg} nor on PATH"
    )


def ros_home() -> Path:
    """``ROS_HOME`` (default ``~/.ros``), where roslaunch runs nodes and writes their logs."""
    return Path(os.environ.get("ROS_HOME") or Path.home() / ".ros")


def node_command(node: RosNode, exe: Path, master_uri: str, log_file: Path) -> tuple[list[str], dict[str, str]]:
    """The argv and environment roslaunch gives ``node``."""
    argv = [*shlex.split(node.launch_prefix), str(exe), *shlex.split(node.args)]
    argv += [f"{src}:={dst}" for src, dst in node.remaps]
    argv += [f"__name:={node.name}", f"__log:={log_file}"]
    env = dict(os.environ)
    env.pop("ROS_NAMESPACE", None)
    env["ROS_MASTER_URI"] = master_uri
    ns = node.namespace.rstrip("/")
    if ns:
        env["ROS_NAMESPACE"] = ns
    env.update(node.env)
    return argv, env


@dataclass
class _Running:
    node: RosNode
    argv: list[str]
    env: dict[str, str]
    proc: subprocess.Popen[bytes]
    restarts: int = 0


@dataclass
class ProcessGroup:
    """The processes of one launch; :meth:`stop` ends them (SIGINT, then SIGTERM, then SIGKILL)."""

    master_uri: str = field(default_factory=lambda: os.environ.get("ROS_MASTER_URI") or DEFAULT_MASTER_URI)
    on_required_exit: Callable[[str], None] | None = None
    running: list[_Running] = field(default_factory=list)
    _stopping: threading.Event = field(default_factory=threading.Event)
    _lock: threading.Lock = field(default_factory=threading.Lock)

    def start(self, node: RosNode) -> None:
        """Start ``node`` as roslaunch would (its executable found in its package)."""
        exe = find_executable(node.pkg, node.type, node.where)
        home = ros_home()
        log_dir = home / "log"
        log_dir.mkdir(parents=True, exist_ok=True)
        log_file = log_dir / f"{node.fqn.strip('/').replace('/', '-')}-1.log"
        argv, env = node_command(node, exe, self.master_uri, log_file)
        run = _Running(node, argv, env, self._spawn(node, argv, env, log_file))
        with self._lock:
            self.running.append(run)
        threading.Thread(target=self._watch, args=(run, log_file), daemon=True, name=f"navlab-proc-{node.name}").start()

    def _spawn(self, node: RosNode, argv: list[str], env: dict[str, str], log_file: Path) -> subprocess.Popen[bytes]:
        cwd = Path(node.cwd) if node.cwd and node.cwd != "node" else ros_home()
        if node.cwd == "node":
            cwd = Path(argv[len(shlex.split(node.launch_prefix))]).parent
        out = None if node.output == "screen" else open(log_file.with_suffix(".out"), "ab")  # noqa: SIM115
        try:
            return subprocess.Popen(argv, env=env, cwd=cwd, stdout=out, stderr=out, stdin=subprocess.DEVNULL)
        except OSError as exc:
            raise LaunchError(f"{node.where}: cannot start {argv[0]}: {exc}") from None
        finally:
            if out is not None:
                out.close()

    def _watch(self, run: _Running, log_file: Path) -> None:
        while True:
            code = run.proc.wait()
            if self._stopping.is_set():
                return
            if run.node.required:
                if self.on_required_exit is not None:
                    self.on_required_exit(f"required process [{run.node.fqn}] has died (exit code {code})")
                return
            if not run.node.respawn or self._stopping.wait(max(run.node.respawn_delay, 0.0)):
                return
            run.restarts += 1
            run.proc = self._spawn(run.node, run.argv, run.env, log_file)

    def stop(self, timeout: float = 5.0) -> None:
        """End every process: SIGINT (as roslaunch), then SIGTERM, then SIGKILL."""
        self._stopping.set()
        with self._lock:
            runs = list(self.running)
        for run in runs:
            if run.proc.poll() is None:
                run.proc.send_signal(2)
        for run in runs:
            for action in (None, run.proc.terminate, run.proc.kill):
                if action is not None:
                    action()
                try:
                    run.proc.wait(timeout / 2)
                    break
                except subprocess.TimeoutExpired:
                    continue
