"""The root of navlab's errors; each package derives its own (``DescriptionError``, ``WorldError``, ...).

The CLI prints a ``NavlabError`` as one line (``navlab: error: ...``) instead of a traceback, so
its message must name the file, element or key and say what was expected.
"""

import contextlib
from collections.abc import Iterable, Iterator


class NavlabError(Exception):
    """Base class of every error navlab raises on purpose."""


def closest(key: object, known: Iterable[object], n: int = 1, *, cutoff: float = 0.6) -> list[str]:
    """The ``n`` names of ``known`` closest to ``key`` (difflib, ratio >= ``cutoff``), best first."""
    import difflib  # here: every module imports this one, few need it (start-up time)

    return difflib.get_close_matches(str(key), [str(k) for k in known], n=n, cutoff=cutoff)


def did_you_mean(
    key: object, known: Iterable[object], *, template: str = "; did you mean {!r}?", n: int = 1, cutoff: float = 0.6
) -> str:
    """The one "did you mean" hint of every error message: ``template`` filled with the closest of ``known``
    (the ``n`` closest joined with ", "), or "" when nothing is close."""
    close = closest(key, known, n, cutoff=cutoff)
    return template.format(", ".join(close)) if close else ""


@contextlib.contextmanager
def interrupt_note(note: str) -> Iterator[None]:
    """Ctrl-C inside the block leaves with ``note`` on the KeyboardInterrupt: what it left on disk (the CLI
    prints it after "navlab: interrupted")."""
    try:
        yield
    except KeyboardInterrupt as exc:
        exc.add_note(note)
        raise
