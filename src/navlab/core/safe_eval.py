"""A safe evaluator for the expressions in data files (xacro ``${...}``/``$(eval ...)``, launch ``$(eval ...)``).

An AST-walking interpreter, never Python's ``eval``: it can do only what xacro documents — literals
(numbers, strings, booleans, ``None``), arithmetic, comparisons, ``and``/``or``/``not``, conditional
expressions, names from a property table, calls of allowed functions, list/tuple/set/dict literals,
indexing and slicing, ``%`` formatting and f-strings with bounded widths. Attribute access is limited to
key look-up on mapping wrappers (``math.pi``, a xacro namespace's ``ns.prop``, a YAML dict's
``dims.radius``) and a short allow-list of pure methods of ``str``/``list``/``tuple``/``dict`` (never
``format``). Everything else — names or attributes with ``__``, lambdas, comprehensions, ``:=``, calls of
anything not allowed — raises :class:`UnsafeExpressionError` in one line.

Work and memory are bounded: the expression's length and nesting, integer sizes (powers, shifts,
products), the length of strings and sequences an operation would build (``'x' * 10**9`` is refused
before it is built), ``range`` lengths and the arguments of ``math.factorial``/``comb``/``perm``.
"""

from __future__ import annotations

import ast
import math
import operator
import re
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from navlab.core.errors import CoreError

MAX_EXPRESSION_CHARS = 10_000  # characters in one expression
MAX_DEPTH = 100  # nesting of the expression's syntax tree
MAX_NODES = 5_000  # syntax-tree nodes in one expression
MAX_INT_BITS = 8_192  # the largest integer an operation may produce (~2,466 decimal digits)
MAX_ITEMS = 1_000_000  # characters of a string / items (recursively) of a sequence an operation may produce
MAX_FORMAT_WIDTH = 1_000  # field widths and precisions in % formatting and f-strings
MAX_FACTORIAL = 1_000  # argument of math.factorial / comb / perm

#: the ``math`` module's public names, as xacro exposes them (``math.pi``, ``sin(x)``)
MATH_NAMES: Mapping[str, Any] = {k: v for k, v in vars(math).items() if not k.startswith("_")}


class ExpressionError(CoreError):
    """An expression in a data file cannot be evaluated (unknown name, division by zero, wrong types)."""


class UnsafeExpressionError(ExpressionError):
    """An expression uses something a data file may not (reflection, code, unbounded work); one line."""


_BINOPS: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv,
    ast.Mod: operator.mod,
    ast.Pow: operator.pow,
    ast.LShift: operator.lshift,
    ast.RShift: operator.rshift,
    ast.BitAnd: operator.and_,
    ast.BitOr: operator.or_,
    ast.BitXor: operator.xor,
}
_UNARY: dict[type, Callable[[Any], Any]] = {
    ast.UAdd: operator.pos,
    ast.USub: operator.neg,
    ast.Not: operator.not_,
    ast.Invert: operator.invert,
}
_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq,
    ast.NotEq: operator.ne,
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
    ast.Is: operator.is_,
    ast.IsNot: operator.is_not,
    ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b,
}
#: pure methods an expression may call on values of these types (``format`` is not one: it reaches attributes)
_METHODS: dict[type, frozenset[str]] = {
    str: frozenset(
        {
            "lower",
            "upper",
            "strip",
            "lstrip",
            "rstrip",
            "split",
            "rsplit",
            "splitlines",
            "startswith",
            "endswith",
            "find",
            "rfind",
            "index",
            "rindex",
            "count",
            "isdigit",
            "isalpha",
            "isalnum",
            "isspace",
            "islower",
            "isupper",
            "isnumeric",
            "title",
            "capitalize",
            "swapcase",
            "casefold",
            "replace",
            "join",
            "partition",
            "rpartition",
            "removeprefix",
            "removesuffix",
        }
    ),
    list: frozenset({"index", "count"}),
    tuple: frozenset({"index", "count"}),
    dict: frozenset({"get", "keys", "values", "items"}),
}
#: node types refused, with the words the error uses
_REFUSED: dict[type, str] = {
    ast.Lambda: "a lambda",
    ast.NamedExpr: "an assignment expression (:=)",
    ast.ListComp: "a comprehension",
    ast.SetComp: "a comprehension",
    ast.DictComp: "a comprehension",
    ast.GeneratorExp: "a generator expression",
    ast.Await: "await",
    ast.Yield: "yield",
    ast.YieldFrom: "yield",
    ast.MatMult: "the @ operator",
}
_PERCENT_FIELD = re.compile(r"%(?:\([^)]*\))?[-#0 +]*(\*|\d*)(?:\.(\*|\d*))?")
_SPEC_NUMBER = re.compile(r"\d+")


def _short(expr: str) -> str:
    one = " ".join(expr.split())
    return one if len(one) <= 120 else one[:117] + "..."


class _BoundMethod:
    """An allowed method of a value; callable, with no attributes of its own to walk."""

    __slots__ = ("_fn", "name")

    def __init__(self, fn: Callable[..., Any], name: str) -> None:
        self._fn = fn
        self.name = name

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self._fn(*args, **kwargs)

    def __repr__(self) -> str:
        return f"<method {self.name}>"


class _Evaluator:
    def __init__(self, expr: str, names: Mapping[str, Any], functions: Mapping[str, Callable[..., Any]]) -> None:
        self.expr = expr
        self.names = names
        self.functions = functions
        self.allowed = {id(f) for f in functions.values()}
        self._keep = list(functions.values())  # the ids above stay valid while this evaluator lives
        self.wrapped: dict[int, Callable[..., Any]] = {}  # allowed builtins that size work -> bounded versions
        for fn, guard in (
            (range, self._guard_range),
            (math.factorial, self._guard_factorial),
            (math.comb, self._guard_factorial),
            (math.perm, self._guard_factorial),
            (round, self._guard_round),
            (sum, self._guard_sum),
            (math.prod, self._guard_prod),
        ):
            if id(fn) in self.allowed:
                self.wrapped[id(fn)] = self._bounded(fn, guard)
        self.allowed |= {id(f) for f in self.wrapped.values()}

    def _bounded(
        self,
        fn: Callable[..., Any],
        guard: Callable[[tuple[Any, ...], dict[str, Any]], None],
    ) -> Callable[..., Any]:
        def bounded(*args: Any, **kwargs: Any) -> Any:
            guard(args, kwargs)
            return fn(*args, **kwargs)

        return bounded

    def value(self, value: Any) -> Any:
        """``value`` as an expression sees it: a builtin that sizes work is replaced by its bounded version."""
        return self.wrapped.get(id(value), value) if callable(value) else value

    # --- errors -------------------------------------------------------------------------------------------
    def unsafe(self, what: str) -> UnsafeExpressionError:
        return UnsafeExpressionError(
            f"expression '{_short(self.expr)}': {what} is not allowed (an expression in a data file is not code)"
        )

    def error(self, what: str) -> ExpressionError:
        return ExpressionError(f"expression '{_short(self.expr)}': {what}")

    # --- bounds -------------------------------------------------------------------------------------------
    def items(self, value: Any, budget: int = MAX_ITEMS) -> int:
        """Characters and items in ``value`` (recursively), counted up to just over ``budget``."""
        if isinstance(value, (str, bytes)):
            return len(value)
        if isinstance(value, Mapping):
            value = [*value.keys(), *dict.values(value)] if isinstance(value, dict) else list(value.keys())
        if isinstance(value, (list, tuple, set, frozenset)):
            total = len(value)
            for item in value:
                if total > budget:
                    break
                if isinstance(item, (str, bytes, list, tuple, set, frozenset, dict)):
                    total += self.items(item, budget - total)
            return total
        return 1

    def check_size(self, value: Any) -> Any:
        if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > MAX_INT_BITS:
            raise self.unsafe(f"an integer of more than {MAX_INT_BITS} bits")
        if isinstance(value, (str, bytes, list, tuple, set, frozenset, dict)) and self.items(value) > MAX_ITEMS:
            raise self.unsafe(f"a value of more than {MAX_ITEMS:,} characters/items")
        if isinstance(value, range) and len(value) > MAX_ITEMS:
            raise self.unsafe(f"a range of more than {MAX_ITEMS:,} items")
        return value

    def guard_binop(self, op: type, a: Any, b: Any) -> None:
        ints = isinstance(a, int) and isinstance(b, int)
        if op is ast.Pow and ints and b > 0 and abs(a) > 1 and abs(a).bit_length() * b > MAX_INT_BITS:
            raise self.unsafe(f"the power {a} ** {b} (more than {MAX_INT_BITS} bits)")
        if op is ast.LShift and ints and a != 0 and a.bit_length() + b > MAX_INT_BITS:
            raise self.unsafe(f"the shift {a} << {b} (more than {MAX_INT_BITS} bits)")
        if op is ast.Mult:
            if ints and a.bit_length() + b.bit_length() > MAX_INT_BITS:
                raise self.unsafe(f"a product of more than {MAX_INT_BITS} bits")
            seq, n = (a, b) if isinstance(b, int) else (b, a)
            if (
                isinstance(n, int)
                and isinstance(seq, (str, bytes, list, tuple))
                and n > 0
                and self.items(seq) * n > MAX_ITEMS
            ):
                raise self.unsafe(
                    f"repeating a {type(seq).__name__} of {self.items(seq):,} items {n:,} times "
                    f"(more than {MAX_ITEMS:,})"
                )
        if (
            op is ast.Add
            and isinstance(a, (str, bytes, list, tuple))
            and isinstance(b, (str, bytes, list, tuple))
            and self.items(a) + self.items(b) > MAX_ITEMS
        ):
            raise self.unsafe(f"a value of more than {MAX_ITEMS:,} characters/items")
        if op is ast.Mod and isinstance(a, str):
            for width, precision in _PERCENT_FIELD.findall(a):
                for number in (width, precision):
                    if number == "*" or (number and int(number) > MAX_FORMAT_WIDTH):
                        raise self.unsafe(f"a % format width/precision {number!r} (at most {MAX_FORMAT_WIDTH})")

    def _guard_range(self, args: tuple[Any, ...], kwargs: dict[str, Any]) -> None:
        if all(isinstance(a, int) for a in args) and 1 <= len(args) <= 3 and len(range(*args)) > MAX_ITEMS:
            raise self.unsafe(f"a range of more than {MAX_ITEMS:,} items")

    def _guard_factorial(self, args: tuple[Any, ...], kwargs: dict[str, Any]) -> None:
        if any(isinstance(a, int) and a > MAX_FACTORIAL for a in args):
            raise self.unsafe(f"a factorial/comb/perm argument above {MAX_FACTORIAL}")

    def _guard_round(self, args: tuple[Any, ...], kwargs: dict[str, Any]) -> None:
        digits = args[1] if len(args) > 1 else kwargs.get("ndigits")
        if isinstance(digits, int) and abs(digits) > MAX_FORMAT_WIDTH:
            raise self.unsafe(f"round() to {digits} digits (at most {MAX_FORMAT_WIDTH})")

    def _guard_sum(self, args: tuple[Any, ...], kwargs: dict[str, Any]) -> None:
        if len(args) > 1 and not isinstance(args[1], (int, float)):
            raise self.unsafe("sum() of anything but numbers")

    def _guard_prod(self, args: tuple[Any, ...], kwargs: dict[str, Any]) -> None:
        if (
            args
            and isinstance(args[0], (list, tuple))
            and sum(abs(int(v)).bit_length() for v in args[0] if isinstance(v, int)) > MAX_INT_BITS
        ):
            raise self.unsafe(f"a product of more than {MAX_INT_BITS} bits")

    # --- evaluation -----------------------------------------------------------------------------------------
    def run(self, tree: ast.Expression) -> Any:
        return self.check_size(self.eval(tree.body))

    def eval(self, node: ast.AST) -> Any:
        method = getattr(self, "eval_" + type(node).__name__, None)
        if method is None:
            raise self.unsafe(_REFUSED.get(type(node), f"Python syntax '{type(node).__name__}'"))
        return method(node)

    def eval_Constant(self, node: ast.Constant) -> Any:
        if node.value is Ellipsis or isinstance(node.value, complex):
            raise self.unsafe(f"the constant {node.value!r}")
        return node.value

    def eval_Name(self, node: ast.Name) -> Any:
        name = node.id
        if name.startswith("__"):
            raise self.unsafe(f"the name {name!r}")
        if name in self.names:
            return self.value(self.names[name])
        if name in self.functions:
            return self.value(self.functions[name])
        raise self.error(f"name {name!r} is not defined")

    def eval_Attribute(self, node: ast.Attribute) -> Any:
        attr = node.attr
        if attr.startswith("_"):
            raise self.unsafe(f"the attribute {attr!r}")
        value = self.eval(node.value)
        for kind, methods in _METHODS.items():
            if isinstance(value, kind) and attr in methods:
                return self.bind(value, attr)
        if isinstance(value, Mapping) and type(value) is not dict:  # namespaces and YAML dicts: dotted keys
            try:
                return self.value(value[attr])
            except (KeyError, AttributeError, NameError):
                raise self.error(f"{attr!r} is not a key of this namespace/dictionary") from None
        raise self.unsafe(f"the attribute '.{attr}' of a value of type {type(value).__name__}")

    def bind(self, value: Any, attr: str) -> _BoundMethod:
        fn = getattr(value, attr)
        if attr == "replace":

            def replace(old: str, new: str, count: int = -1) -> str:
                n = value.count(old) if count < 0 else min(count, value.count(old))
                if len(value) + n * (len(new) - len(old)) > MAX_ITEMS:
                    raise self.unsafe(f"a value of more than {MAX_ITEMS:,} characters")
                return value.replace(old, new, count)

            return _BoundMethod(replace, "str.replace")
        if attr == "join":

            def join(items: Iterable[Any]) -> str:
                parts = list(items)
                if sum(len(p) if isinstance(p, str) else 0 for p in parts) + len(value) * len(parts) > MAX_ITEMS:
                    raise self.unsafe(f"a value of more than {MAX_ITEMS:,} characters")
                return fn(parts)

            return _BoundMethod(join, "str.join")
        return _BoundMethod(fn, f"{type(value).__name__}.{attr}")

    def eval_BinOp(self, node: ast.BinOp) -> Any:
        op = type(node.op)
        if op not in _BINOPS:
            raise self.unsafe(_REFUSED.get(op, f"the operator {op.__name__}"))
        a, b = self.eval(node.left), self.eval(node.right)
        self.guard_binop(op, a, b)
        return self.check_size(_BINOPS[op](a, b))

    def eval_UnaryOp(self, node: ast.UnaryOp) -> Any:
        return _UNARY[type(node.op)](self.eval(node.operand))

    def eval_BoolOp(self, node: ast.BoolOp) -> Any:
        value: Any = None
        for operand in node.values:
            value = self.eval(operand)
            if bool(value) == isinstance(node.op, ast.Or):  # `and` stops at a false value, `or` at a true one
                return value
        return value

    def eval_Compare(self, node: ast.Compare) -> Any:
        left = self.eval(node.left)
        for op, right_node in zip(node.ops, node.comparators, strict=True):
            right = self.eval(right_node)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    def eval_IfExp(self, node: ast.IfExp) -> Any:
        return self.eval(node.body) if self.eval(node.test) else self.eval(node.orelse)

    def elements(self, nodes: list[ast.expr]) -> list[Any]:
        out: list[Any] = []
        for n in nodes:
            if isinstance(n, ast.Starred):
                value = self.eval(n.value)
                if isinstance(value, range) or self.items(value) <= MAX_ITEMS:
                    out.extend(self.check_size(value) if isinstance(value, range) else value)
                else:
                    raise self.unsafe(f"unpacking more than {MAX_ITEMS:,} items")
            else:
                out.append(self.eval(n))
        return self.check_size(out)

    def eval_List(self, node: ast.List) -> Any:
        return self.elements(node.elts)

    def eval_Tuple(self, node: ast.Tuple) -> Any:
        return tuple(self.elements(node.elts))

    def eval_Set(self, node: ast.Set) -> Any:
        return set(self.elements(node.elts))

    def eval_Dict(self, node: ast.Dict) -> Any:
        out: dict[Any, Any] = {}
        for key, value in zip(node.keys, node.values, strict=True):
            if key is None:
                merged = self.eval(value)
                if not isinstance(merged, Mapping):
                    raise self.error(f"** needs a mapping, not a {type(merged).__name__}")
                out.update(merged)
            else:
                out[self.eval(key)] = self.eval(value)
        return self.check_size(out)

    def eval_Subscript(self, node: ast.Subscript) -> Any:
        return self.check_size(self.value(self.eval(node.value)[self.eval(node.slice)]))

    def eval_Slice(self, node: ast.Slice) -> Any:
        return slice(*(None if n is None else self.eval(n) for n in (node.lower, node.upper, node.step)))

    def eval_JoinedStr(self, node: ast.JoinedStr) -> Any:
        parts = [str(self.eval(v)) if isinstance(v, ast.Constant) else self.eval(v) for v in node.values]
        return self.check_size("".join(parts))

    def eval_FormattedValue(self, node: ast.FormattedValue) -> Any:
        value = self.eval(node.value)
        spec = self.eval(node.format_spec) if node.format_spec is not None else ""
        if any(int(n) > MAX_FORMAT_WIDTH for n in _SPEC_NUMBER.findall(spec)):
            raise self.unsafe(f"the format width/precision in {spec!r} (at most {MAX_FORMAT_WIDTH})")
        self.check_size(value)
        if node.conversion == ord("r"):
            value = repr(value)
        elif node.conversion in (ord("s"), ord("a")):
            value = str(value) if node.conversion == ord("s") else ascii(value)
        if not isinstance(value, (str, int, float, bool, type(None))):
            value = str(value)
        return format(value, spec)

    def eval_Call(self, node: ast.Call) -> Any:
        fn = self.eval(node.func)
        if not (isinstance(fn, _BoundMethod) or id(fn) in self.allowed):
            name = ast.unparse(node.func)
            raise self.unsafe(f"calling {name!r} (not an allowed function)")
        args = self.elements(node.args)
        kwargs: dict[str, Any] = {}
        for kw in node.keywords:
            if kw.arg is None:
                raise self.unsafe("** in a call")
            kwargs[kw.arg] = self.eval(kw.value)
        for arg in (*args, *kwargs.values()):
            if callable(arg) and not (isinstance(arg, _BoundMethod) or id(arg) in self.allowed):
                raise self.unsafe(f"passing {type(arg).__name__} {arg!r} to a function")
        return self.check_size(fn(*args, **kwargs))


def _check_tree(evaluator: _Evaluator, tree: ast.AST) -> None:
    """Refuse deep or large trees before anything is evaluated (iteratively: no recursion on hostile input)."""
    count = 0
    stack: list[tuple[ast.AST, int]] = [(tree, 0)]
    while stack:
        node, depth = stack.pop()
        count += 1
        if depth > MAX_DEPTH:
            raise evaluator.unsafe(f"nesting deeper than {MAX_DEPTH} levels")
        if count > MAX_NODES:
            raise evaluator.unsafe(f"more than {MAX_NODES:,} syntax elements")
        if type(node) in _REFUSED:
            raise evaluator.unsafe(_REFUSED[type(node)])
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))


def safe_eval(expr: str, names: Mapping[str, Any], *, functions: Mapping[str, Callable[..., Any]] | None = None) -> Any:
    """Evaluate ``expr`` over ``names`` (a property table: read with ``in`` and ``[]``, so lazy tables work).

    ``functions`` are the only callables an expression may call (looked up after ``names``; a name in
    ``names`` bound to one of them is callable too). Raises :class:`UnsafeExpressionError` for what an
    expression may not do and :class:`ExpressionError` when evaluation fails; both one line.
    """
    evaluator = _Evaluator(str(expr), names, functions or {})
    text = evaluator.expr.strip()
    if len(text) > MAX_EXPRESSION_CHARS:
        raise evaluator.unsafe(f"an expression of {len(text):,} characters (at most {MAX_EXPRESSION_CHARS:,})")
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise evaluator.error(f"invalid syntax ({exc.msg})") from None
    except (MemoryError, RecursionError, ValueError):
        raise evaluator.unsafe("an expression this deeply nested") from None
    _check_tree(evaluator, tree)
    try:
        return evaluator.run(tree)
    except ExpressionError:
        raise
    except RecursionError:
        raise evaluator.unsafe("recursion this deep") from None
    except (ArithmeticError, TypeError, ValueError, LookupError, AttributeError, NameError) as exc:
        raise evaluator.error(f"{type(exc).__name__}: {exc}") from None
