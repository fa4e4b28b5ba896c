"""Atomic replacement of the files the library writes into result folders (a report or a
figure interrupted half-way left half a file)."""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

__all__ = ["write_atomic", "write_text_atomic"]


def write_atomic(path: str | os.PathLike, write: Callable[[Path], object]) -> Path:
    """Call ``write(tmp)`` with a temporary path next to ``path`` (same suffix, so writers that
    choose the format by suffix still do), flush it to disk and rename it over ``path``:
    readers see the old file or the new one, never a part. The temporary is removed when
    anything fails. A file that is there keeps its permissions; a device, FIFO or directory at
    ``path`` is refused (OSError), never replaced."""
    path = Path(path)
    target = Path(os.path.realpath(path))
    if target.exists() and not target.is_file():  # a rename would replace a device or FIFO
        raise OSError(errno.EINVAL, "not a regular file, not replaced", str(path))
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.stem}.",
                               suffix=f".part{target.suffix}")
    os.close(fd)
    try:
        write(Path(tmp))
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        try:
            mode = os.stat(target).st_mode & 0o7777
        except OSError:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(tmp, mode)
        os.replace(tmp, target)
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
    return path


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    """:func:`write_atomic` of a UTF-8 text."""
    data = text.encode()
    return write_atomic(path, lambda tmp: tmp.write_bytes(data))
