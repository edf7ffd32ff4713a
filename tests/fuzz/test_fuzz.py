"""The fast fuzz subset (issues 14, 21): 320 malformed inputs over every format, none may end in a traceback, a hang,
a crash, code run by a robot description, an accepted invalid value or an error that names no file.

The full campaign (>= 3,000 cases, a table per format) is ``python -m tests.fuzz`` (``make fuzz``).
"""

from __future__ import annotations

from .runner import BAD, cases, format_table, run_cases, table
from .seeds import FORMATS


def test_fast_fuzz_subset_has_only_clean_errors_and_valid_acceptances() -> None:
    todo = cases(320, seed=0)
    assert {c.fmt for c in todo} == set(FORMATS) and len(todo) >= 300
    results = run_cases(todo, timeout=30.0)  # generous: a real hang never answers; a loaded CI machine is slow
    bad = [
        f"{r.outcome}: {r.case.fmt} {r.case.mutation}: {r.detail[:160]}"
        for r in results
        if r.outcome in (*BAD, "vague")
    ]
    assert not bad, format_table(table(results)) + "\n" + "\n".join(bad[:20])
    assert sum(r.outcome == "clean" for r in results) > 150  # the mutations do break the inputs
