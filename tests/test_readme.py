"""Every command of the README's "What you can run" and experiments blocks, run as written from a temporary
folder outside the checkout (only simulated durations shortened, listed below), in README order; each must exit 0
without a traceback. Commands too long for CI are listed in LONG with the reason and run with NAVLAB_README_LONG=1.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import time
from pathlib import Path

import pytest

from navlab.io import data_dir

README = Path(__file__).resolve().parents[1] / "README.md"

# verb (+ a word that tells the command apart) -> options appended to keep CI short (same meaning, less sim time)
SHORTER = {
    "sim": ["--duration", "2"],
    "map --explore": ["--duration", "20"],
    "map --route": ["--duration", "15"],
    "localize": ["--duration", "3"],
    "navigate --map": ["--timeout", "3"],
    "navigate --mapless": ["--timeout", "3"],
    "slam": ["--max-scans", "120"],  # 25 s of the log: enough for relations to match
    "launch mapping": ["--duration", "3"],
    "launch navigation": ["--duration", "2"],  # without --duration it runs until Ctrl-C, as roslaunch
    "run": ["--duration", "3"],
    "topic": ["--duration", "2"],
    "graph": ["--duration", "1"],
}
# navigate exits 1 when a goal is not reached; with 3 s per goal that is expected, and said in one line
NOT_REACHED = re.compile(r"^navlab: \d+ of \d+ goals not reached \(.*\)$", re.M)
# files of the checkout that are not shipped in the package (an example node, a sample ROS workspace): a reader runs
# these lines from the clone, so here they point into the checkout explicitly; nothing else may be repo-relative
CHECKOUT_FILES = ("examples/", "tests/fixtures/")
LONG = {  # command prefix -> why it is not in CI's run (each takes minutes of simulated trials)
    "experiment": "runs whole scenario trials (minutes each)",
    "bench": "a benchmark: minutes, and figures are not asserted",
    "report": "reports the sweep above, which is in LONG",
}


def readme_commands() -> list[str]:
    """The `navlab ...` lines of the README's bash blocks, comments removed, in order."""
    text = README.read_text()
    blocks = re.findall(r"```bash\n(.*?)```", text, re.S)
    cmds = []
    for block in blocks:
        for line in block.splitlines():
            line = line.split("  #")[0].strip()
            if line.startswith("navlab "):
                cmds.append(line)
    return cmds


def _extra(cmd: str) -> list[str]:
    words = cmd.split()
    for key, extra in SHORTER.items():
        verb, *flag = key.split()
        if words[1] == verb and all(f in words for f in flag):
            return extra
    return []


def _run(cmd: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "NAVLAB_DATA": str(data_dir()), "MPLBACKEND": "Agg"}
    bin_dir = Path(sys.executable).parent
    env["PATH"] = f"{bin_dir}{os.pathsep}{env.get('PATH', '')}"
    words = [str(README.parent / w) if w.startswith(CHECKOUT_FILES) else w for w in cmd.split()]
    line = " ".join(words) + "".join(f" {shlex.quote(w)}" for w in _extra(cmd)) + " --quiet" * ("--quiet" in _help(cmd))
    return subprocess.run(
        ["bash", "-c", line], cwd=cwd, env=env, capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL
    )


def _help(cmd: str) -> str:
    """The verb's --help text (to know whether it takes --quiet)."""
    words = shlex.split(cmd)
    return (
        subprocess.run([sys.executable, "-m", "navlab.cli", words[1], "--help"], capture_output=True, text=True).stdout
        if words[1] not in ("eval",)
        else ""
    )


def test_readme_lists_the_commands_the_test_runs() -> None:
    cmds = readme_commands()
    assert len(cmds) >= 20 and any(c.startswith("navlab check robot mybot") for c in cmds)
    assert not [c for c in cmds if "src/navlab" in c or "../shared" in c or "route.yaml" in c]  # from any folder
    repo_relative = [w for c in cmds for w in c.split() if "/" in w and (README.parent / w).exists()]
    assert all(w.startswith(CHECKOUT_FILES) for w in repo_relative), repo_relative


def test_every_readme_command_from_a_folder_outside_the_checkout(tmp_path_factory: pytest.TempPathFactory) -> None:
    cwd = tmp_path_factory.mktemp("readme")
    assert README.parent not in cwd.parents
    if not (data_dir() / "mit-csail" / "mit-csail.clf").is_file():
        pytest.fail(f"the MIT CSAIL dataset is not at {data_dir()} (set NAVLAB_DATA)")
    long = os.environ.get("NAVLAB_README_LONG") == "1"
    failures, skipped = [], []
    for cmd in readme_commands():
        verb = cmd.split()[1]
        if verb == "teleop" or "--teleop" in cmd:
            continue  # interactive: test_readme_teleop and test_ctrl_c drive them through a terminal
        if verb in LONG and not long and not cmd.startswith("navlab experiment list"):  # list: one second
            skipped.append(f"{cmd}  ({LONG[verb]})")
            continue
        proc = _run(cmd, cwd)
        ok = proc.returncode == 0 or (verb == "navigate" and proc.returncode == 1 and NOT_REACHED.search(proc.stderr))
        if not ok or "Traceback" in proc.stderr:
            failures.append(f"{cmd}\n  exit {proc.returncode}: {proc.stderr.strip()[-600:]}")
    assert not failures, "\n".join(failures)
    if skipped:  # said, not silent: these need NAVLAB_README_LONG=1
        print("not run (NAVLAB_README_LONG=1 runs them):\n  " + "\n  ".join(skipped))


def test_readme_teleop_drives_from_a_terminal(tmp_path: Path) -> None:
    """`navlab teleop` with no launch running starts the sim here; keys come from a terminal (a pty)."""
    import signal

    from cli_terminal import Terminal

    term = Terminal(["teleop", "--world", "room"], tmp_path)
    try:
        term.wait_for("sending linear.x", 120.0)  # its status line: it reads keys now (a loaded machine is slow)
        term.keys(b"i")
        term.wait_for("sending linear.x +0.50", 60.0)
        time.sleep(1.5)
        term.signal(signal.SIGINT)  # Ctrl-C at the terminal
        code = term.finish(30.0, after="Ctrl-C (SIGINT)")
    finally:
        term.close()
    out, err = term.stdout, term.stderr
    assert code == 0, err
    assert "stopped at" in out and "Traceback" not in err
    assert "sending linear.x +0.50 m/s" in err  # it shows what it sends
    moved = re.search(r"stopped at x=(-?[\d.]+)", out)
    assert moved and float(moved.group(1)) > 0.05  # the 'i' key drove it forward
