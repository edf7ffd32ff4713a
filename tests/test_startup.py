"""Start-up: every verb's --help and argument errors come before MuJoCo, Numba or Ray are imported (and --help and
unknown options before numpy: the <= 0.3 s of ``navlab VERB --help``)."""

from __future__ import annotations

import json
import subprocess
import sys

_PROBE = r"""
import contextlib, io, json, sys
from navlab.cli import build_parser, main
verbs = sorted(build_parser()._subparsers._group_actions[0].choices)
cases = [[v, "--help"] for v in verbs] + [[v, "--no-such-option"] for v in verbs]
cases += [["sim", "--duration", "x"], None, ["slam", "--log", "no-such.clf", "--out", "out"]]
codes = {}
for argv in cases:
    if argv is None:  # the parser's own cases are done: what they loaded
        light = "numpy" not in sys.modules
        continue
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        try:
            code = main(argv)
        except SystemExit as exc:
            code = exc.code
    codes[" ".join(argv)] = code
heavy = [m for m in ("mujoco", "numba", "ray") if m in sys.modules]
print(json.dumps({"verbs": verbs, "codes": codes, "heavy": heavy, "light": light}))
"""


def test_help_and_argument_errors_import_no_mujoco_numba_or_ray(tmp_path):
    out = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, cwd=tmp_path, check=True)
    got = json.loads(out.stdout)
    assert len(got["verbs"]) >= 10
    assert got["heavy"] == [], got["heavy"]
    assert got["light"], "--help or an unknown option imported numpy"
    for argv, code in got["codes"].items():
        assert code == (0 if argv.endswith("--help") else 2), (argv, code)


def test_sim_with_duration_zero_loads_everything_and_steps_nothing(tmp_path):
    """``navlab sim --duration 0``: the shortest run (the start-up figure of ``navlab bench startup``)."""
    out = subprocess.run(
        [sys.executable, "-m", "navlab.cli", "sim", "--duration", "0", "--json"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        check=True,
    )
    got = json.loads(out.stdout)
    assert got["sim_s"] == 0.0 and got["world"] == "room" and got["robot"]
    assert got["true_pose"] == got["start_pose"]
