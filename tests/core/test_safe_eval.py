"""The safe expression evaluator (issue 21): what xacro documents works; every known sandbox-escape family and
every unbounded computation is refused in one line, before it runs."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import pytest

from navlab.core.safe_eval import MATH_NAMES, ExpressionError, UnsafeExpressionError, safe_eval
from navlab.errors import NavlabError

FUNCTIONS = {
    **MATH_NAMES,
    "abs": abs,
    "min": min,
    "max": max,
    "int": int,
    "float": float,
    "str": str,
    "len": len,
    "round": round,
    "bool": bool,
    "list": list,
    "dict": dict,
    "range": range,
    "map": map,
    "sum": sum,
    "sorted": sorted,
}


class _Namespace(dict):  # a xacro-style namespace: dotted access to keys
    pass


NAMES: dict[str, Any] = {
    "r": 0.5,
    "n": 3,
    "side": "left",
    "dims": _Namespace(radius=0.25, wheels=[1, 2]),
    "math": _Namespace(MATH_NAMES),
    "table": {"a": 1},
}


@pytest.mark.parametrize(
    ("expr", "expected"),
    [
        ("2*r + 1", 2.0),
        ("n ** 2 // 2 % 3", 1),
        ("-r if n > 2 else r", -0.5),
        ("1 < n <= 3 and not False", True),
        ("math.pi / 2", math.pi / 2),
        ("radians(180)", math.pi),
        ("sqrt(abs(-16))", 4.0),
        ("dims.radius * 4", 1.0),
        ("dims['wheels'][-1]", 2),
        ("[1, 2, 3][1:]", [2, 3]),
        ("{'k': n}['k']", 3),
        ("(1, 2) + (3,)", (1, 2, 3)),
        ("side.upper() + '_wheel'", "LEFT_wheel"),
        ("'%s_%d' % (side, n)", "left_3"),
        ("f'{r:.2f}'", "0.50"),
        ("max(list(range(n)))", 2),
        ("table.get('a', 0)", 1),
        ("round(2.567, 2)", 2.57),
        ("len(side) in [4, 5]", True),
        ("'x' * 3", "xxx"),
        ("2 ** 10", 1024),
        ("str(n) == '3'", True),
    ],
)
def test_what_xacro_documents_evaluates(expr: str, expected: Any) -> None:
    assert safe_eval(expr, NAMES, functions=FUNCTIONS) == expected


ISSUE_ESCAPE = "[*(g := (g.gi_frame.f_back.f_back.f_globals['os'].system('touch /tmp/x') for _ in [1]))]"


@pytest.mark.parametrize(
    ("expr", "words"),
    [
        (ISSUE_ESCAPE, "assignment expression"),
        ("().__class__.__bases__[0].__subclasses__()", "'__subclasses__'"),  # dunder walks
        ("side.__class__", "'__class__'"),
        ("__import__('os')", "'__import__'"),
        ("(x for x in [1]).gi_frame", "generator expression"),  # frames, generators, code objects
        ("max.__code__", "'__code__'"),
        ("dims.radius.real", "'.real'"),
        ("'{0.__class__}'.format(n)", "'.format'"),  # format-string attribute access
        ("'{0.__class__}'.format_map(table)", "'.format_map'"),
        ("[y for y in range(3)]", "comprehension"),  # comprehension scopes
        ("{k: 1 for k in 'ab'}", "comprehension"),
        ("(lambda: 1)()", "lambda"),
        ("(z := 3)", "assignment expression"),
        ("9 ** 9 ** 9", "power"),
        ("2 ** 100_000", "power"),
        ("1 << 10 ** 6", "shift"),  # huge numbers
        ("'x' * 10 ** 9", "repeating a str"),
        ("[0] * 10 ** 8", "repeating a list"),  # huge strings and lists
        ("range(10 ** 9)", "range"),
        ("list(map(range, [10 ** 9]))", "range"),
        ("factorial(10 ** 6)", "factorial"),
        ("'%999999999d' % 1", "format width"),
        ("f'{n:>99999999}'", "format width"),
        ("round(1, -10 ** 9)", "round"),
        ("[" * 150 + "]" * 150, "nesting"),
        ("-" * 300 + "1", "nesting"),
        ("1+" * 6000 + "1", "characters"),
        ("getattr(n, 'real')", "name 'getattr' is not defined"),
        ("open('/etc/passwd')", "not defined"),
        ("str.join", "of a value of type type"),
        ("sum([[1]] * 3, [])", "sum()"),
        ("sorted([3], key=type)", "'type'"),
    ],
)
def test_escapes_and_unbounded_work_are_refused_in_one_line(expr: str, words: str) -> None:
    start = time.perf_counter()
    with pytest.raises(ExpressionError) as info:
        safe_eval(expr, NAMES, functions=FUNCTIONS)
    assert time.perf_counter() - start < 2.0  # refused before the work is done
    message = str(info.value)
    assert "\n" not in message and message.startswith("expression '") and words in message
    assert isinstance(info.value, NavlabError)


def test_refusals_are_unsafe_errors_and_failures_are_plain_expression_errors() -> None:
    with pytest.raises(UnsafeExpressionError):
        safe_eval("side.__class__", NAMES)
    with pytest.raises(ExpressionError, match="ZeroDivisionError") as info:
        safe_eval("1 / 0", NAMES)
    assert not isinstance(info.value, UnsafeExpressionError)
    with pytest.raises(UnsafeExpressionError, match="calling 'f'"):
        safe_eval("f(side)", {**NAMES, "f": len})  # a callable in the names but not in the functions


def test_no_code_runs_from_the_issue_escape(tmp_path: Path) -> None:
    marker = tmp_path / "escaped"
    with pytest.raises(UnsafeExpressionError):
        safe_eval(ISSUE_ESCAPE.replace("/tmp/x", str(marker)), NAMES, functions=FUNCTIONS)
    assert not marker.exists()
