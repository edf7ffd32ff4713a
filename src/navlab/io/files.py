"""Atomic file writing (everything navlab writes goes to a temporary name and is renamed into place) and
checked reading (regular files only, bounded size, strict UTF-8 with the line of a bad byte).

The temporary file sits beside the target (same filesystem, so the rename is atomic) and gets the
permissions a plain ``open(path, "w")`` would give (0666 less the umask; ``mkstemp`` alone gives 0600).
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from navlab.io.errors import IoError

MAX_TEXT_BYTES = 64 << 20  # the largest text input navlab reads in one piece (64 MiB)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path: str | os.PathLike[str], *, suffix: str = ".tmp") -> Iterator[Path]:
    """A temporary path beside ``path`` to write to; renamed onto ``path`` when the block succeeds.

    On an exception the temporary file is removed and ``path`` is left as it was. ``suffix`` matters
    for writers that pick the format from the file name (matplotlib, ``np.savez``).
    """
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=p.parent, prefix=f".{p.name}.", suffix=suffix)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, p)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    write_bytes_atomic(path, text.encode())


def save_figure_atomic(fig: Any, path: str | os.PathLike[str], **savefig_kwargs: Any) -> None:
    """Save a matplotlib figure to ``path`` atomically (format from the suffix)."""
    with atomic_path(path, suffix=Path(path).suffix) as tmp:
        fig.savefig(tmp, **savefig_kwargs)


def machine_memory_bytes() -> int:
    """The memory this process may use in bytes (the figure memory ceilings are computed from): the machine's
    physical memory, or the process's address-space limit (``ulimit -v``) if that is lower."""
    import resource

    try:
        physical = int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        physical = 8 << 30
    soft, _hard = resource.getrlimit(resource.RLIMIT_AS)
    return min(physical, soft) if soft != resource.RLIM_INFINITY and soft > 0 else physical


def _kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISFIFO, "a named pipe"),
        (stat.S_ISCHR, "a device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "not a regular file"


def check_regular_file(path: str | os.PathLike[str], *, what: str) -> None:
    """Refuse ``path`` unless it is a regular file (named pipes, devices, sockets and folders are refused
    without being opened: a FIFO would block the reader, a device never end). Raises ``IoError``."""
    try:
        st = os.stat(path)
    except OSError as exc:
        raise IoError(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    if not stat.S_ISREG(st.st_mode):
        raise IoError(f"{path}: is {_kind(st.st_mode)}; expected a {what} (a regular file)")


def read_bytes_checked(path: str | os.PathLike[str], *, what: str, max_bytes: int = MAX_TEXT_BYTES) -> bytes:
    """The bytes of the regular file ``path`` (a ``what``, named in errors), at most ``max_bytes`` of them.

    Named pipes, devices and directories are refused before anything is read (a FIFO would block, a
    device never end); so is a file larger than ``max_bytes``. Raises ``IoError`` naming the path.
    """
    p = Path(path)
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as exc:
        raise IoError(f"{p}: cannot read the {what} ({exc.strerror or exc})") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise IoError(f"{p}: is {_kind(st.st_mode)}; expected a {what} (a regular file)")
    with os.fdopen(fd, "rb") as fh:
        if st.st_size > max_bytes:
            raise IoError(f"{p}: {st.st_size} bytes; a {what} may have at most {max_bytes}")
        try:
            data = fh.read(min(st.st_size, max_bytes) + 1)  # not max_bytes: read() allocates what it is asked
        except OSError as exc:
            raise IoError(f"{p}: cannot read the {what} ({exc.strerror or exc})") from None
    if len(data) > max_bytes:
        raise IoError(f"{p}: more than {max_bytes} bytes; a {what} may have at most {max_bytes}")
    return data


def decode_text(data: bytes, path: str | os.PathLike[str], *, what: str) -> str:
    """``data`` as UTF-8 text (a leading byte-order mark dropped); a bad byte raises ``IoError`` naming its line."""
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise IoError(
            f"{path}:{line}: byte 0x{data[exc.start]:02x} is not UTF-8 text; expected a {what} "
            "in UTF-8 (is it a binary file?)"
        ) from None


def read_text_checked(path: str | os.PathLike[str], *, what: str, max_bytes: int = MAX_TEXT_BYTES) -> str:
    """:func:`read_bytes_checked` then :func:`decode_text`: the UTF-8 text of a regular file of bounded size."""
    return decode_text(read_bytes_checked(path, what=what, max_bytes=max_bytes), path, what=what)
