"""Ctrl-C (SIGINT) and SIGTERM stop `navlab teleop` at once and give the terminal back, also when it runs as a
background job of a script (SIGINT inherited ignored: Python then installs no handler of its own)."""

from __future__ import annotations

import signal
import termios
from pathlib import Path

import pytest

from cli_terminal import Terminal


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_teleop_stops_on_a_signal_with_sigint_inherited_ignored(tmp_path: Path, sig: int) -> None:
    term = Terminal(["teleop", "--world", "room"], tmp_path, ignore_sigint=True)
    try:
        before = term.lflag()
        term.wait_for("sending linear.x", 120.0)  # driving: keys are read in cbreak mode
        assert not term.lflag() & termios.ICANON
        term.signal(sig)
        code = term.finish(15.0, after=signal.Signals(sig).name)
        assert code == 0, term.stderr
        assert "stopped at" in term.stdout and "Traceback" not in term.stderr
        assert term.lflag() == before  # the terminal's settings are back (line editing, echo)
    finally:
        term.close()
