"""Run fuzz cases in a worker process (per-case time limit, memory limit) and classify the outcomes.

The worker (``python -m tests.fuzz.runner --worker``) reads one JSON request per line, runs the
format's entry point in-process and answers one JSON line. The parent writes each case's files to a
fresh folder, waits for the answer at most ``timeout`` seconds, and restarts the worker after a hang
(killed) or a crash (the worker died: memory limit, signal).
"""

from __future__ import annotations

import json
import os
import select
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .mutate import FIFO, LINK_PREFIX, Case, generate
from .seeds import FORMATS, build_seeds

REPO = Path(__file__).resolve().parents[2]
OUTCOMES = ("clean", "accepted", "vague", "accepted-invalid", "traceback", "hang", "crash", "escape", "lost")
BAD = ("accepted-invalid", "traceback", "hang", "crash", "escape", "lost")
MEMORY_LIMIT = 3 << 30  # bytes of address space for the worker


@dataclass
class Result:
    """The outcome of one case and what it said."""

    case: Case
    outcome: str
    detail: str = ""


# --- worker side ------------------------------------------------------------------------------------


def _worker() -> None:
    import logging
    import resource
    import traceback

    logging.disable(logging.CRITICAL)
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    from navlab.errors import NavlabError

    from .targets import TARGETS

    out = sys.stdout
    sys.stdout = sys.stderr  # entry points that print must not corrupt the answer stream
    for line in sys.stdin:
        req = json.loads(line)
        folder = Path(req["dir"])
        os.chdir(folder)
        reply: dict[str, Any]
        try:
            info = TARGETS[req["fmt"]](folder / req["main"])
            reply = {"status": "accepted", "info": info}
        except NavlabError as exc:
            reply = {"status": "error", "message": str(exc)}
        except BaseException as exc:
            tb = traceback.extract_tb(exc.__traceback__)
            where = f"{Path(tb[-1].filename).name}:{tb[-1].lineno}" if tb else "?"
            reply = {"status": "traceback", "message": f"{type(exc).__name__} at {where}: {str(exc)[:300]}"}
        lost = [
            rel
            for rel, text in (req.get("keep") or {}).items()
            if not (folder / rel).is_file() or (folder / rel).read_text() != text
        ]
        if lost:
            reply = {"status": "lost", "message": f"the user's files are gone or changed: {', '.join(lost)}"}
        marker = req.get("marker")
        if marker and any((p / marker).exists() for p in (folder, Path(tempfile.gettempdir()))):
            reply = {"status": "escape", "message": f"the description created {marker}"}
        out.write(json.dumps(reply) + "\n")
        out.flush()


# --- parent side --------------------------------------------------------------------------------------


def _write_case(case: Case, folder: Path) -> None:
    for rel, data in case.files.items():
        p = folder / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        if data == FIFO:
            os.mkfifo(p)
        elif data.startswith(LINK_PREFIX):
            p.symlink_to(data[len(LINK_PREFIX) :].decode())
        else:
            p.write_bytes(data)


class Worker:
    """A worker process that runs cases one at a time."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen[str] | None = None

    def _start(self) -> subprocess.Popen[str]:
        if self.proc is None or self.proc.poll() is not None:
            src = os.environ.get("NAVLAB_FUZZ_SRC", str(REPO / "src"))  # another checkout's src (a before/after table)
            env = {**os.environ, "PYTHONPATH": src + os.pathsep + str(REPO)}
            env.pop("NAVLAB_FUZZ_SURELY_UNSET", None)
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "tests.fuzz.runner", "--worker"],
                cwd=REPO,
                env=env,
                text=True,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
            )
        return self.proc

    def kill(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        self.proc = None

    def run(self, req: dict[str, Any], timeout: float) -> dict[str, Any]:
        proc = self._start()
        assert proc.stdin is not None and proc.stdout is not None
        try:
            proc.stdin.write(json.dumps(req) + "\n")
            proc.stdin.flush()
        except BrokenPipeError:
            self.kill()
            return {"status": "crash", "message": "worker died before the case"}
        ready, _, _ = select.select([proc.stdout], [], [], timeout)
        if not ready:
            self.kill()
            return {"status": "hang", "message": f"no answer within {timeout:g} s"}
        line = proc.stdout.readline()
        if not line:
            code = proc.wait()
            self.proc = None
            return {"status": "crash", "message": f"worker exited with {code}"}
        return dict(json.loads(line))


def classify(case: Case, reply: dict[str, Any], folder: Path) -> Result:
    """The outcome class of one case from the worker's reply."""
    status, message = reply["status"], str(reply.get("message", ""))
    if status in ("traceback", "hang", "crash", "escape", "lost"):
        return Result(case, status, message)
    if status == "error":
        names = {Path(rel).name for rel in case.files} | {folder.name, Path(case.main).name}
        names |= set(case.expect.get("names", []))  # command-line cases: the option or value at fault
        named = any(n and n in message for n in names)
        lines = message.count("\n") + 1
        return Result(case, "clean" if named and lines <= 3 else "vague", message[:300])
    info = reply.get("info") or {}
    skipped_min = case.expect.get("skipped_at_least")
    if skipped_min is not None:
        return Result(
            case, "accepted" if info.get("skipped", 0) >= skipped_min else "accepted-invalid", json.dumps(info)
        )
    return Result(case, "accepted-invalid" if case.invalid else "accepted", "")


def cases(n: int, seed: int, formats: tuple[str, ...] = FORMATS) -> list[Case]:
    """``n`` cases spread evenly over ``formats``, drawn from ``numpy.random.default_rng(seed)``."""
    seeds = build_seeds()
    rng = np.random.default_rng(seed)
    return [generate(formats[k % len(formats)], seeds[formats[k % len(formats)]], rng) for k in range(n)]


COMPILE_ALLOWANCE = 4.0  # x timeout for a format's first case (JIT compilation is not a hang)


def run_cases(todo: list[Case], *, timeout: float = 10.0, progress: bool = False) -> list[Result]:
    """Run and classify every case (each in a fresh folder, one worker process reused)."""
    worker = Worker()
    results: list[Result] = []
    seen: set[str] = set()
    root = Path(tempfile.mkdtemp(prefix="navlab-fuzz-"))
    try:
        for k, case in enumerate(todo):
            folder = root / f"case{k:05d}"
            folder.mkdir()
            _write_case(case, folder)
            req = {
                "fmt": case.fmt,
                "dir": str(folder),
                "main": case.main,
                "marker": case.expect.get("marker"),
                "keep": case.expect.get("keep"),
            }
            # a format's first case in a worker may compile its Numba kernels (cold caches in a fresh clone): more time
            first = case.fmt not in seen
            seen.add(case.fmt)
            results.append(classify(case, worker.run(req, timeout * (COMPILE_ALLOWANCE if first else 1.0)), folder))
            shutil.rmtree(folder, ignore_errors=True)
            if progress and (k + 1) % 100 == 0:
                print(f"  {k + 1}/{len(todo)} cases", file=sys.stderr, flush=True)
    finally:
        worker.kill()
        shutil.rmtree(root, ignore_errors=True)
    return results


def table(results: list[Result]) -> dict[str, dict[str, int]]:
    """Counts per format and outcome class."""
    out: dict[str, Counter[str]] = defaultdict(Counter)
    for r in results:
        out[r.case.fmt][r.outcome] += 1
    return {fmt: {o: out[fmt][o] for o in OUTCOMES} for fmt in sorted(out)}


def format_table(counts: dict[str, dict[str, int]]) -> str:
    """The table as Markdown, one row per format plus a total row."""
    head = "| format | cases | " + " | ".join(OUTCOMES) + " |"
    rows = [head, "|" + " --- |" * (len(OUTCOMES) + 2)]
    total = Counter[str]()
    for fmt, c in counts.items():
        total.update(c)
        rows.append(f"| {fmt} | {sum(c.values())} | " + " | ".join(str(c[o]) for o in OUTCOMES) + " |")
    rows.append(f"| total | {sum(total.values())} | " + " | ".join(str(total[o]) for o in OUTCOMES) + " |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    """``python -m tests.fuzz [--cases N] [--seed S] [--timeout T] [--json] [--show K]``."""
    import argparse

    p = argparse.ArgumentParser(prog="python -m tests.fuzz", description="navlab's input fuzz campaign")
    p.add_argument("--cases", type=int, default=3200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--timeout", type=float, default=10.0, help="seconds per case before it counts as a hang")
    p.add_argument("--format", action="append", choices=FORMATS, help="only these formats (repeatable)")
    p.add_argument("--show", type=int, default=5, help="print up to this many examples of each bad class")
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    t0 = time.monotonic()
    results = run_cases(
        cases(args.cases, args.seed, tuple(args.format or FORMATS)), timeout=args.timeout, progress=not args.json
    )
    counts = table(results)
    bad = [r for r in results if r.outcome in BAD or r.outcome == "vague"]
    if args.json:
        print(
            json.dumps(
                {
                    "cases": len(results),
                    "seconds": round(time.monotonic() - t0, 1),
                    "table": counts,
                    "bad": [[r.case.fmt, r.case.mutation, r.outcome, r.detail] for r in bad],
                }
            )
        )
    else:
        print(format_table(counts))
        shown: Counter[str] = Counter()
        for r in bad:
            key = r.outcome
            if shown[key] < args.show:
                shown[key] += 1
                print(f"{r.outcome}: {r.case.fmt} {r.case.mutation}: {r.detail[:200]}")
        print(f"{len(results)} cases in {time.monotonic() - t0:.0f} s")
    return 1 if any(r.outcome in BAD for r in results) else 0


if __name__ == "__main__":
    if sys.argv[1:] == ["--worker"]:
        _worker()
    else:
        sys.exit(main())
