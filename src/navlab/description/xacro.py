"""xacro → URDF text, with ``$(find pkg)`` resolved through a :class:`PackageIndex`.

Uses the xacro processor that ``xacrodoc`` ships. xacro keeps its look-up function and file stack in
module globals; they are swapped in for the duration of one expansion and restored afterwards.
"""

from __future__ import annotations

import contextlib
import io
import xml.parsers.expat
from collections.abc import Iterator, Mapping
from pathlib import Path

import xacro
from xacro import substitution_args

from navlab.description.errors import DescriptionError
from navlab.description.packages import PackageIndex


@contextlib.contextmanager
def _find_through(index: PackageIndex) -> Iterator[None]:
    """Make xacro's ``$(find pkg)`` and ``${find('pkg')}`` use ``index`` while the block runs."""

    def find(pkg: str) -> str:
        return str(index.find(pkg))

    saved_fn = substitution_args._eval_find
    saved_dict = substitution_args._eval_dict.get("find")
    substitution_args._eval_find = find
    substitution_args._eval_dict["find"] = find
    try:
        yield
    finally:
        substitution_args._eval_find = saved_fn
        substitution_args._eval_dict["find"] = saved_dict


def _current_file(default: Path) -> str:
    """The file xacro was reading when it failed (its file stack), else ``default``."""
    stack = [f for f in (xacro.filestack or []) if f]
    return str(stack[-1]) if stack else str(default)


def expand(path: Path, index: PackageIndex, args: Mapping[str, str] | None = None) -> tuple[str, list[str]]:
    """Expand the xacro (or plain URDF) file ``path``; return the URDF text and xacro's warnings.

    ``args`` are ``<xacro:arg>`` values (``name:=value`` on the ROS command line). Errors become a
    DescriptionError naming the file being read and xacro's message.
    """
    path = Path(path)
    if path.is_dir():
        raise DescriptionError(f"{path}: is a directory; expected a .xacro or .urdf file")
    if not path.is_file():
        raise DescriptionError(f"{path}: robot description file not found")
    mappings = {str(k): str(v) for k, v in (args or {}).items()}
    stderr = io.StringIO()
    try:
        with _find_through(index), contextlib.redirect_stderr(stderr):
            doc = xacro.process_file(str(path), mappings=mappings)
            text = doc.toprettyxml(indent="  ")
    except DescriptionError as exc:
        raise DescriptionError(f"{_current_file(path)}: {exc}") from None
    except xml.parsers.expat.ExpatError as exc:
        raise DescriptionError(f"{_current_file(path)}: malformed XML: {exc}") from None
    except xacro.XacroException as exc:
        raise DescriptionError(f"{_current_file(path)}: xacro error: {exc}") from None
    except substitution_args.ArgException as exc:
        raise DescriptionError(
            f"{_current_file(path)}: xacro error: $(arg {exc}) is not set and has no default "
            "(pass it in args / name:=value)"
        ) from None
    except Exception as exc:  # xacro raises NameError, KeyError, ... from evaluated expressions
        raise DescriptionError(
            f"{_current_file(path)}: xacro error: {type(exc).__name__}: {exc}"
        ) from None
    finally:
        xacro.filestack = None
        xacro.all_includes = []  # xacro's module-level include log would grow with every load
    warnings = [
        f"xacro: {line.strip()}"
        for line in stderr.getvalue().splitlines()
        if line.strip() and not line.startswith(("when processing file", "in file", "included from"))
    ]
    return text, warnings
