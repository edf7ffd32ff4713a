"""The ``navlab`` command: one verb per step of the paper's pipeline.

Each verb group registers its verbs from its own module in this package (a ``register(subparsers)``
function); the options they share are declared once in :mod:`navlab.cli.options`. This file only assembles
them and turns ``NavlabError`` into a one-line message.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import re
import sys
from typing import NoReturn

from navlab.cli.options import check_named_inputs
from navlab.errors import NavlabError, did_you_mean

# Modules that define ``register(subparsers: argparse._SubParsersAction) -> None``, one per verb group.
COMMAND_MODULES = (  # in the order of the paper's pipeline, then the ROS-style tools
    "navlab.cli.demo",
    "navlab.cli.sim",
    "navlab.cli.description",
    "navlab.cli.world",
    "navlab.cli.mapping",
    "navlab.cli.evaluation",
    "navlab.cli.localization",
    "navlab.cli.navigation",
    "navlab.cli.experiments",
    "navlab.cli.launch",
    "navlab.cli.ros",
    "navlab.cli.view",
    "navlab.cli.bench",
)


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line, ``navlab: error: launch: argument --duration: ...``, like other errors."""

    def error(self, message: str) -> NoReturn:
        verb = self.prog.removeprefix("navlab").strip()
        wrong = re.match(r"argument (\S+): invalid choice: '([^']*)' \(choose from (.*)\)$", message)
        if wrong:  # a mistyped verb or choice: the closest one, as git does
            choices = re.findall(r"'([^']*)'", wrong.group(3))
            what = "verb" if wrong.group(1) == "VERB" else wrong.group(1)
            hint = did_you_mean(wrong.group(2), choices, cutoff=0.5) or f" (one of: {', '.join(choices)})"
            message = f"unknown {what} {wrong.group(2)!r}{hint}"
        self.exit(2, f"navlab: error: {verb + ': ' if verb else ''}{message} (see `{self.prog} --help`)\n")


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser with every registered verb."""
    parser = _Parser(
        prog="navlab",
        description="The paper's ROS/Gazebo mobile-robot stack in plain Python: simulate the robot in "
        "its world, map it with SLAM, localize with AMCL, and inspect runs with ROS-style tools.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="show the nodes' info-level log lines")
    sub = parser.add_subparsers(dest="command", metavar="VERB", required=True)
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``navlab`` console script; returns the exit code."""
    parser = build_parser()
    args, extra = parser.parse_known_args(argv)
    if extra:  # `navlab launch mapping --duration 60 world:=room`: launch arguments may follow options, as in ROS
        target = next((a for a in ("args", "launch") if isinstance(getattr(args, a, None), list)), None)
        if (
            target is None
            or any(e.startswith("-") for e in extra)
            or (target == "launch" and not all(":=" in e for e in extra))
        ):
            parser.error(f"unrecognized arguments: {' '.join(extra)}")
        getattr(args, target).extend(extra)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(levelname)s %(message)s")
    try:
        check_named_inputs(args)  # a missing world or robot in one line, before MuJoCo and Numba load
        return int(args.func(args) or 0)
    except NavlabError as exc:
        print(f"navlab: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `navlab topic echo /odom | head`: the reader left; stop quietly, as rostopic does
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error when Python flushes
        return 0
    except OSError as exc:  # a file the user named cannot be read or written (permissions, full disk, ...)
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"navlab: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:  # its notes say what the verb left on disk (``errors.interrupt_note``)
        print("; ".join(["navlab: interrupted", *getattr(exc, "__notes__", [])]), file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
