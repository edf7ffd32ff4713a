"""A `navlab` verb run with a terminal (a pty) as its stdin, for the interactive verbs' tests: every wait is
bounded, and on a timeout the process group is killed and the test fails saying what it waited for."""

from __future__ import annotations

import contextlib
import os
import pty
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import NoReturn

import pytest

# `sh -c 'trap "" INT; ...'` as a shell does for a background job: SIGINT ignored, inherited across exec
IGNORING_SIGINT = (
    "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_IGN); "
    "os.execv(sys.executable, [sys.executable, '-m', 'navlab.cli', *sys.argv[1:]])"
)


class Terminal:
    """``navlab ARGV`` in its own process group, stdin a pty; stdout and stderr collected as they come."""

    def __init__(self, argv: list[str], cwd: Path, *, ignore_sigint: bool = False) -> None:
        self.master, self.slave = pty.openpty()
        cmd = [sys.executable, "-c", IGNORING_SIGINT] if ignore_sigint else [sys.executable, "-m", "navlab.cli"]
        self.proc = subprocess.Popen(
            [*cmd, *argv],
            stdin=self.slave,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            cwd=cwd,
            env={**os.environ, "TMPDIR": str(cwd)},  # no other launch's socket: teleop starts its own sim
            start_new_session=True,  # its own group: signals go to it (as a terminal's do), never to pytest
        )
        self.out: list[bytes] = []
        self.err: list[bytes] = []
        self.readers = [
            threading.Thread(target=lambda fd=fd, b=b: b.extend(iter(lambda: os.read(fd, 4096), b"")), daemon=True)
            for fd, b in ((self.proc.stdout.fileno(), self.out), (self.proc.stderr.fileno(), self.err))  # type: ignore[union-attr]
        ]
        for r in self.readers:
            r.start()

    @property
    def stdout(self) -> str:
        return b"".join(self.out).decode(errors="replace")

    @property
    def stderr(self) -> str:
        return b"".join(self.err).decode(errors="replace")

    def _fail(self, what: str) -> NoReturn:
        self.close()
        pytest.fail(f"{what}\n--- stdout:\n{self.stdout[-1500:]}\n--- stderr:\n{self.stderr[-1500:]}")

    def wait_for(self, text: str, seconds: float, *, stream: str = "stderr") -> None:
        """Wait until ``stream`` (stderr or stdout) shows ``text`` (a loaded machine starts slowly); fail if it
        does not in time."""
        deadline = time.monotonic() + seconds
        while text not in getattr(self, stream):
            if self.proc.poll() is not None:
                self._fail(f"navlab exited ({self.proc.returncode}) before showing {text!r} on {stream}")
            if time.monotonic() > deadline:
                self._fail(f"navlab did not show {text!r} on {stream} within {seconds:.0f} s")
            time.sleep(0.1)

    def keys(self, data: bytes) -> None:
        os.write(self.master, data)

    def signal(self, sig: int) -> None:
        """Send ``sig`` to the process group, as a terminal sends Ctrl-C to its foreground job."""
        os.killpg(self.proc.pid, sig)

    def finish(self, seconds: float, after: str) -> int:
        """Its exit code, once it has exited and its output is read; fail if it runs ``seconds`` more."""
        try:
            code = self.proc.wait(timeout=seconds)
        except subprocess.TimeoutExpired:
            self._fail(f"navlab was still running {seconds:.0f} s after {after}")
        for r in self.readers:
            r.join(timeout=10)
        return code

    def lflag(self) -> int:
        """The terminal's local modes now (ICANON, ECHO: what cbreak mode turns off)."""
        import termios

        return termios.tcgetattr(self.slave)[3]

    def close(self) -> None:
        """Kill the process group if it still runs; close the terminal."""
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait(timeout=30)
        for fd in (self.master, self.slave):
            with contextlib.suppress(OSError):
                os.close(fd)
